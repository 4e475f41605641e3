"""The rascal in the JSBSim harness: the thirteenth session's untouched aircraft, a tuning aircraft since its
final evaluation (docs/jsbsim.md, "The rascal").

The model is ArduPilot's SITL Rascal 110 (``Rascal110-JSBSim.xml``, based on FlightGear's Rascal110). It
is the first model from outside the jsbsim wheel: the XML is checked in under
``data/jsbsim_models/rascal/`` (GPL-3.0; provenance in its README.md). The harness flies it as the
derived model ``Rascal110_glide`` (``benchmarks/jsbsim_harness/derived.py``), the XML with its engine
and propeller removed.

The checks here use the XML and JSBSim's own properties; none of them flies:

- the checked-in file is the one the README names (its SHA-256);
- the derived XML is that file without its ``<engine>``, and its hash is in the spec (so in the
  fingerprint);
- JSBSim then has no propulsion, and every non-gravity force is aerodynamic;
- the FCS maps the commands straight to the surfaces the aerodynamics read, with no damper;
- it is statically stable about the CG, and its aileron yaws it the way its ``Cnda`` says.

The summaries' label test moved to ``test_jsbsim_sgs126.py`` (the fourteenth session's untouched aircraft).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign
map, .tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``.
All of them but the names are slow.

No pipeline fit, GP, diagnosis or scoring runs here.
"""

import hashlib
import xml.etree.ElementTree as ET

import pytest

from benchmarks.jsbsim_harness import aircraft
from benchmarks.jsbsim_harness.logfile import _REPO
from pytest import approx
from static_checks import assert_pitch_derivatives, check_direct_fcs, ic_state, lateral_coefficients

SOURCE = _REPO / "data" / "jsbsim_models" / "rascal" / "Rascal110-JSBSim.xml"
SOURCE_SHA256 = "d5b9e7435e3a04d7f8c4d3e37b6ecb9ca4865f98e17d38a50177e5a86d41dd20"   # README.md's


def _state(alpha_deg=4.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0):
    """:func:`static_checks.ic_state` for the rascal."""
    return ic_state(aircraft("rascal"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_derived_model_is_ardupilots_rascal_without_its_engine():
    """The checked-in XML is the file the README names (SHA-256). ``Rascal110_glide`` (hash in the
    spec's notes, so in the rascal's fingerprint; the installed copy is it) is that XML with the
    ``<engine>`` element (engine and 18x8 propeller) removed: its propulsion holds the 1.5-lb fuel tank
    alone, and every other element is equal."""
    from benchmarks.jsbsim_harness.derived import REPO_DERIVED, derived_sha, derived_xml
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    assert hashlib.sha256(SOURCE.read_bytes()).hexdigest() == SOURCE_SHA256
    spec = aircraft("rascal")
    xml = derived_xml("Rascal110_glide")
    assert spec.model == "Rascal110_glide" and _REPO / REPO_DERIVED[spec.model][0] == SOURCE
    assert f"XML sha256 {derived_sha('Rascal110_glide')}" in spec.notes
    assert (stock_model_dir(spec) / "Rascal110_glide.xml").read_bytes() == xml
    derived, source = ET.fromstring(xml), ET.parse(SOURCE).getroot()
    assert [c.tag for c in derived] == [c.tag for c in source]
    assert source.find("propulsion/engine") is not None and derived.find("propulsion/engine") is None
    assert [t.tag for t in derived.find("propulsion")] == ["tank"]
    canon = lambda e: ET.tostring(e, encoding="unicode").replace(" ", "").replace("\n", "")   # noqa: E731
    for a, b in zip(derived, source):
        if a.tag == "propulsion":
            assert canon(a.find("tank")) == canon(b.find("tank"))
        else:
            assert canon(a) == canon(b), a.tag


def test_the_rascal_flies_its_own_surfaces_and_no_propulsion():
    """No engine, so every non-gravity force and moment is aerodynamic, 50 frames on. The FCS maps the
    commands straight to the surfaces the aerodynamics read:

    - elevator -0.35..+0.30 rad, zero-centred;
    - left aileron +-0.35 rad, the right its mirror;
    - rudder +-0.35 rad.

    A yaw rate does not move the rudder (no yaw damper), so the harness's own damper flies it (k_r 0.4)."""
    spec = aircraft("rascal")
    assert spec.gains[5] == 0.4
    check_direct_fcs(spec, min_lift_lbs=5.0)


def test_the_rascal_is_statically_stable_and_yaws_adversely():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic``, the harness's initial condition).

    - **Pitch:** without its ``Cmadot`` term, Cm falls with alpha: -0.79 per rad between 0 and 4 deg,
      -0.65 between 4 and 8 deg. ``run_ic`` gives this light aircraft an alpha-dot, which the term reads.
      The stiffness is its Cmalpha -0.5, plus the lift acting 1.0 in aft of the CG, less the axial force
      acting 3.4 in below it.
    - **Elevator:** Cm per rad of elevator -0.53: Cmde -0.5 + 0.1125 Mach (-0.493 at Mach 0.063), plus
      CLde's lift acting aft of the CG (-0.015) and CDde's drag (0.03 per unit of
      ``fcs/elevator-pos-norm``, i.e. 0.1 per rad) acting below it (-0.025).
    - **Yaw:** Cn per rad of left aileron -0.030 (its Cnda: adverse yaw, Cn_delta_a +0.03 in the
      project's sign). Cn at rest is its Cndi, +0.0007.
    """
    assert_pitch_derivatives(aircraft("rascal"), ((0.0, 4.0, approx(-0.79, abs=0.02)),
                                                  (4.0, 8.0, approx(-0.65, abs=0.02))),
                             ((-0.5, approx(-0.53, abs=0.01)),), alpha_e=4.0, travel=(0.35, 0.30))

    (_, n0, a0, _), (_, n1, a1, _) = (lateral_coefficients(_state(alpha_deg=2.0, cmds=(0.0, c, 0.0)))
                                      for c in (0.0, 0.4))
    assert (n1 - n0) / (a1 - a0) == pytest.approx(-0.03, rel=1e-6) and n0 == pytest.approx(0.0007, rel=1e-6)
