"""The c684 in the JSBSim harness: the seventeenth session's untouched aircraft, used since the eighteenth
(docs/jsbsim.md, "The c684").

The model is FlightGear's JSBSim Caudron C.684 Super Rafale (``C684.xml`` of FGMEMBERS/C684 at commit 05ad4b2c,
GPL-2.0-or-later; Guillaume Chauvat 2008, hand-made tables), a 1930s French racing two-seater, checked in under
``data/jsbsim_models/c684/`` and flown as the derived model ``C684_glide`` (``derived.py``): its engine,
propeller and engine system removed, its fuel tanks kept as mass, its gear's 2008 ``FIXED`` flags written 0 for
JSBSim 1.3.3. It is flown at 125 kt (``ic/vc-kts``) and 6000 ft.

The checks here use the XML and JSBSim's own properties (the harness's initial condition, ``run_ic``, no
turbulence: a mechanism check); none of them flies the harness:

- the checked-in file is the one the README names, and the derivation makes only its three edits;
- the FCS maps the commands straight to the surfaces the aerodynamics read, with unequal ends (elevator
  -0.35 / +0.30 rad, ailerons 20 / 15 deg mirrored, rudder +-20 deg) and no damper; no engine, no external force;
- it is statically stable about the CG, and its elevator, aileron and rudder act as its XML says.

The summaries' label test moved to ``test_jsbsim_ultrastick.py`` in the eighteenth session (the ultrastick is
untouched; the c684 is a tuning aircraft).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign
map, .tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``.
All of them but the names are slow.

No pipeline fit, GP, diagnosis or scoring ran on the c684 before the seventeenth session's final evaluation.
"""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import checked_in_model
from static_checks import assert_aero_is_the_only_force, assert_pitch_derivatives, ic_state, lateral_coefficients

SRC = "data/jsbsim_models/c684/C684.xml"
SRC_SHA256 = "fb02bd7d563c8877ebcaaffe81e17ab62efd456ec65027436349e696765e826d"
DEG = np.pi / 180.0


def _state(alpha_deg=2.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0):
    """:func:`static_checks.ic_state` for the c684 (125 kt at 6000 ft)."""
    return ic_state(aircraft("c684"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_derivation_removes_the_engine_and_its_system_and_fixes_the_gear_flags():
    """The checked-in XML is the README's (28423 bytes, its SHA-256). ``C684_glide`` is that XML with its one
    ``<engine>`` (``6Pfi``, two feeds, the ``ratier_variable`` thruster) removed from ``<propulsion>``, its one
    ``<system file="engine"/>`` removed and the three wheels' ``<retractable>FIXED</retractable>`` written ``0``;
    the fuel tanks and every other element are equal (metrics, mass balance, flight control, aerodynamics; the
    ground reactions but the three flags). The spec's notes carry the derived XML's hash."""
    src, der, spec = checked_in_model("c684", "C684_glide", SRC, 28423, SRC_SHA256)
    canon = lambda e: "".join(ET.tostring(e, encoding="unicode").split())   # noqa: E731  (layout aside: ET.indent)
    assert [c.tag for c in src if c.tag != "system"] == [c.tag for c in der]
    assert [s.get("file") for s in src.findall("system")] == ["engine"] and der.findall("system") == []
    for tag in ("metrics", "mass_balance", "flight_control", "aerodynamics"):
        assert canon(src.find(tag)) == canon(der.find(tag)), tag
    assert [f.text.strip() for f in src.iter("retractable")] == ["FIXED"] * 3
    assert [f.text.strip() for f in der.iter("retractable")] == ["0"] * 3
    gr = ET.fromstring(ET.tostring(src.find("ground_reactions")))
    for f in gr.iter("retractable"):
        f.text = "0"
    assert canon(gr) == canon(der.find("ground_reactions"))
    engines = src.find("propulsion").findall("engine")
    assert [e.get("file") for e in engines] == ["6Pfi"] and engines[0].find("thruster").get("file") == "ratier_variable"
    assert der.find("propulsion").findall("engine") == []
    assert list(map(canon, der.find("propulsion"))) == [canon(t) for t in src.find("propulsion").findall("tank")]


def test_the_c684_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps the commands straight to the surfaces (``aerosurface_scale``, no damper) with unequal ends:
    elevator +0.30 rad trailing edge down, -0.35 up; left aileron 15 deg x a positive command, 20 deg x a
    negative one, the right its mirror (the aerodynamics read the left alone, so the harness reads the left,
    ``aileron_props``, delta_a = -left); rudder +-20 deg (0.01745 x 20 rad). ``cmd_per_rad`` is the larger end of
    each axis, so a command moves the surface by the spec's factor on one side and 0.86 (elevator) / 0.75
    (aileron) of it on the other. No engine; after 50 frames every non-gravity force and moment is
    aerodynamic. A yaw rate does not move the rudder (no yaw damper)."""
    from benchmarks.jsbsim_harness.flight import _deflections

    spec = aircraft("c684")
    assert spec.gains[5] == 0.4 and not spec.gear_up and spec.aileron_props == ("fcs/left-aileron-pos-rad", None)
    fdm = _state(beta_deg=4.0, cmds=(0.3, -0.4, 0.2), r_rad_s=0.2)
    assert fdm.get_propulsion().get_num_engines() == 0
    assert fdm["fcs/elevator-pos-rad"] == pytest.approx(0.3 * 0.30, rel=1e-9)
    assert fdm["fcs/left-aileron-pos-rad"] == pytest.approx(-0.4 * 20 * 0.01745, rel=1e-9)
    assert fdm["fcs/right-aileron-pos-rad"] == pytest.approx(0.4 * 20 * 0.01745, rel=1e-9)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.2 * 20 * 0.01745, rel=1e-9)
    other = _state(cmds=(-0.3, 0.4, -0.2))
    assert other["fcs/elevator-pos-rad"] == pytest.approx(-0.3 * 0.35, rel=1e-9)
    assert other["fcs/left-aileron-pos-rad"] == pytest.approx(0.4 * 15 * 0.01745, rel=1e-9)
    assert other["fcs/rudder-pos-rad"] == pytest.approx(-0.2 * 20 * 0.01745, rel=1e-9)
    da = np.radians(5.0)      # trailing edge down on the right: left aileron up, the 20-deg side
    cmd = da * spec.aileron_sign * spec.cmd_per_rad[1]
    assert _deflections(_state(cmds=(0.0, cmd, 0.0)), spec)[1] == pytest.approx(da, rel=1e-9)
    assert_aero_is_the_only_force(fdm, 1000.0, external_zero=True)


def test_the_c684_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 76.7 m/s
    TAS, Mach 0.23). The aerodynamic reference point is 0.287 m ahead of the loaded CG (the crew and the tanks sit
    aft of it) and 0.15 m below.

    - **Pitch:** without its ``Cmadot`` term, Cm falls with alpha: -0.86 per rad between -4 and 0 deg, -0.81
      between 0 and 4 deg (``Cmalpha`` -2.3 on alpha + 0.043 rad incidence, less the lift acting ahead of the CG;
      the CL table's slope changes at 0); Cm -0.011 at alpha 0.
    - **Elevator:** Cm per rad of elevator (``Cmde`` -1.3) -1.234 trailing edge up and -1.272 down (``CLde`` and
      ``CDde``, the drag of the elevator's magnitude, act through the arm).
    - **Roll and yaw:** a constant ``Clo`` -0.0011; per rad of left aileron Cl +0.1185 at alpha 2 deg (the
      ``Clda`` table in alpha: 0.12 at 0; the project's Cl_delta_a -0.1185) and Cn -0.008 x CL (``Cnda`` reads the
      lift: -0.0046 at CL 0.578; Cn_delta_a +0.0046, adverse), the same per rad either side; per rad of rudder
      Cl 0, Cn -0.065; Cl_beta -0.055 at alpha 0, -0.059 at 2 deg, -0.067 at 6 deg (the ``Clb`` table in alpha,
      -0.08 at 0, and the side force ``CYb`` -1 acting 0.15 m below the CG), Cn_beta 0.141 (``Cnb`` 0.18 less
      the side force ahead of the CG).
    """
    spec = aircraft("c684")
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.863, abs=0.01)), (0.0, 4.0, approx(-0.807, abs=0.01))),
                             ((-0.5, approx(-1.234, abs=0.005)), (0.5, approx(-1.272, abs=0.005))),
                             cm_at={0.0: approx(-0.0113, abs=0.002)}, alpha_e=2.0, travel=(0.35, 0.30))

    def lat(cmds=(0.0, 0.0, 0.0), beta=0.0, alpha=2.0):
        fdm = _state(alpha_deg=alpha, beta_deg=beta, cmds=cmds)
        return lateral_coefficients(fdm) + (np.sqrt(fdm["aero/cl-squared"]),)

    l0, n0, _, _, cl = lat()
    assert l0 == pytest.approx(-0.0011, rel=1e-6) and abs(n0) < 1e-12
    for c in (0.4, -0.4):
        l1, n1, a1, _, _ = lat((0.0, c, 0.0))
        assert (l1 - l0) / a1 == pytest.approx(0.12 - 0.01 * 2.0 / 13.0, rel=1e-6)
        assert (n1 - n0) / a1 == pytest.approx(-0.008 * cl, rel=1e-6) and cl == pytest.approx(0.578, abs=0.002)
    l2, n2, _, r2, _ = lat((0.0, 0.0, 0.4))
    assert abs(l2 - l0) < 1e-12 and (n2 - n0) / r2 == pytest.approx(-0.065, rel=1e-6)
    for a, clb in ((0.0, -0.0550), (2.0, -0.0590), (6.0, -0.0667)):
        lb, nb, _, _, _ = lat(alpha=a)
        l3, n3, _, _, _ = lat(beta=4.0, alpha=a)
        assert (l3 - lb) / np.radians(4.0) == pytest.approx(clb, abs=5e-4), a
        assert (n3 - nb) / np.radians(4.0) == pytest.approx(0.141, abs=2e-3), a

