"""The f4n in the JSBSim harness: the twelfth session's untouched aircraft (docs/jsbsim.md, "The f4n"),
a tuning aircraft since its final evaluation was read (the thirteenth session's untouched one is the
rascal, the fourteenth's the sgs126, ``test_jsbsim_sgs126.py``, where the summaries-label test moved).

JSBSim's stock F-4N Phantom II (``F4N.xml``, Aeromatic v0.9 / David Culp, 2007), flown with its own
flight control as the wheel ships it: direct surfaces (``systems/FCS-pitch.xml``, ``FCS-roll.xml``)
and a yaw damper (``systems/FCS-yaw.xml``) that the harness cannot switch off, kept in the loop as the
b747's was. It is loaded as the derived model ``F4N_fcs`` (``benchmarks/jsbsim_harness/derived.py``):
the stock XML with an empty ``<flight_control>`` added, where ``effects.py`` puts its elevator delay.
Its own checks are here, on the XML and JSBSim's own properties, no flight: the derived XML is the
stock one plus that empty element (hash in the spec, so in the fingerprint) and JSBSim computes the
same forces and moments with it; the yaw damper moves the rudder the aerodynamics read (so the logged
rudder includes it) and nothing else stands between the commands and the surfaces; it is statically
stable about the CG. The checks it
shares with the other aircraft (names, rigid body, sign map, gear, .tlog, hidden effects, airspeed
bias, the evaluation's flights in the envelope, ``--fly-only``; slow but the names') are in
``test_jsbsim_roster.py``. No pipeline fit, GP, diagnosis or scoring ran on the f4n before its final
evaluation (twelfth session).
"""

import dataclasses
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from static_checks import assert_pitch_derivatives, ic_state


def _state(alpha_deg=4.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0, spec=None):
    """:func:`static_checks.ic_state` for the f4n (or ``spec``)."""
    return ic_state(spec or aircraft("f4n"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_derived_model_is_the_stock_f4n_with_an_empty_flight_control():
    """``F4N_fcs`` (hash in the spec's notes, so in the f4n's fingerprint; the installed copy is it) is
    the wheel's F4N.xml with one element added, an empty ``<flight_control>`` just before
    ``<aerodynamics>``; every other element equal. In JSBSim, at alpha 4 deg, sideslip 4 deg, a yaw
    rate of 0.02 rad/s and commands (0.3, -0.4, 0.2), 50 frames on: every force, moment and surface
    equals the stock model's exactly."""
    from benchmarks.jsbsim_harness.derived import derived_sha, derived_xml
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    spec = aircraft("f4n")
    xml = derived_xml("F4N_fcs")
    assert spec.model == "F4N_fcs" and f"XML sha256 {derived_sha('F4N_fcs')}" in spec.notes
    assert (stock_model_dir(spec) / "F4N_fcs.xml").read_bytes() == xml
    derived = list(ET.fromstring(xml))
    stock = list(ET.parse(stock_model_dir(spec).parent / "F4N" / "F4N.xml").getroot())
    i = [c.tag for c in derived].index("flight_control")
    assert len(derived[i]) == 0 and derived[i + 1].tag == "aerodynamics"
    canon = lambda e: ET.tostring(e, encoding="unicode").replace(" ", "").replace("\n", "")   # noqa: E731
    assert [canon(c) for c in derived[:i] + derived[i + 1:]] == [canon(c) for c in stock]

    def run(sp):
        fdm = _state(beta_deg=4.0, cmds=(0.3, -0.4, 0.2), r_rad_s=0.02, spec=sp)
        for _ in range(50):
            fdm.run()
        return fdm

    a, b = run(spec), run(dataclasses.replace(spec, model="F4N"))
    for k in ("forces/fbx-aero-lbs", "forces/fby-aero-lbs", "forces/fbz-aero-lbs", "moments/l-aero-lbsft",
              "moments/m-aero-lbsft", "moments/n-aero-lbsft", "fcs/elevator-pos-rad", "fcs/rudder-pos-rad"):
        assert a[k] == b[k], k
        assert abs(a[k]) > 0.01, k


def test_the_f4n_flies_its_own_surfaces_and_yaw_damper():
    """The F4N's FCS maps the commands straight to the surfaces the aerodynamics read (elevator
    -0.35..+0.30 rad, zero-centred; left aileron +-0.35 rad; rudder +-0.25 rad), and adds its yaw
    damper, 2 x ``velocities/r-aero-rad_sec`` in normalised rudder, clipped to +-0.1 (at most 0.025
    rad of rudder), to the rudder: the harness's own yaw damper is off (k_r = 0), and the rudder
    property the harness logs (and the aerodynamics' Cndr and Cldr read) includes the model's."""
    spec = aircraft("f4n")
    assert spec.gains[5] == 0.0
    fdm = _state(cmds=(0.3, -0.4, 0.2))
    assert fdm["fcs/elevator-pos-rad"] == pytest.approx(0.3 * 0.30, rel=1e-9)
    assert fdm["fcs/left-aileron-pos-rad"] == pytest.approx(-0.4 * 0.35, rel=1e-9)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.2 * 0.25, rel=1e-9)
    assert _state(cmds=(-0.3, 0.0, 0.0))["fcs/elevator-pos-rad"] == pytest.approx(-0.3 * 0.35, rel=1e-9)
    for r, cmd in ((0.02, 0.0), (0.02, 0.2), (0.2, 0.0)):
        fdm = _state(r_rad_s=r, cmds=(0.0, 0.0, cmd))
        damper = fdm["fcs/yaw-damper-final"]
        assert damper == pytest.approx(float(np.clip(2 * fdm["velocities/r-aero-rad_sec"], -0.1, 0.1)), rel=0.02)
        assert abs(damper) > 0.03
        assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.25 * (cmd + damper), rel=1e-9)


def test_the_f4n_is_statically_stable_about_its_cg():
    """JSBSim's pitching moment about the CG at fixed surfaces (``run_ic``, the harness's initial
    condition, sideslip 0) falls with alpha: Cm_alpha -0.23 per rad between 0 and 4 deg and between 4
    and 8 deg (its Cmalpha -0.3, the CG and the aerodynamic reference point 4 in apart vertically);
    Cm per rad of elevator about -0.54 (its Cmde, -0.70 + 0.25 Mach, at the initial Mach 0.61)."""
    per_rad = approx(-0.23, abs=0.01)
    assert_pitch_derivatives(aircraft("f4n"), ((0.0, 4.0, per_rad), (4.0, 8.0, per_rad)),
                             ((-0.5, approx(-0.54, abs=0.02)),), alpha_e=4.0, travel=(0.35, 0.35), term=None)
