"""The iar80 in the JSBSim harness: the sixteenth session's untouched aircraft, a tuning aircraft since its final
evaluation was read (docs/jsbsim.md, "The iar80").

The model is FlightGear's JSBSim IAR-80 (``IAR80-Jsb.xml`` of FGMEMBERS/IAR-80-JSB at commit 6d011335,
GPL-2.0-or-later; Aeromatic v0.95, 2015), a single-seat piston fighter, checked in under
``data/jsbsim_models/iar80/`` and flown as the derived model ``IAR80_glide`` (``derived.py``): its engine and
propeller removed, its fuel tanks kept as mass. It is flown at 10000 ft, where MIL-F-8785C light turbulence
moves the air.

The checks here use the XML and JSBSim's own properties; none of them flies the harness:

- the checked-in file is the one the README names, and the derivation removes the engine alone;
- the FCS maps the commands straight to the surfaces the aerodynamics read (every surface +-0.35 rad, the right
  aileron the same sign as the left), with no damper; no engine, no external force;
- it is statically stable about the CG, and its elevator, aileron and rudder act as its XML says.

The summaries' label test moved to ``test_jsbsim_c684.py`` in the seventeenth session (the c684 is untouched).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign
map, gear (its ``Drag_gear`` reads 0 once the harness has retracted it), .tlog, hidden effects, airspeed bias, the
evaluation's flights in the envelope and ``--fly-only``. All of them but the names are slow.

No pipeline fit, GP, diagnosis or scoring runs in these tests.
"""

import xml.etree.ElementTree as ET

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import checked_in_model
from static_checks import assert_aero_is_the_only_force, assert_aileron_maps_back, assert_lateral_derivatives, \
    assert_pitch_derivatives, ic_state, surface_state

SRC = "data/jsbsim_models/iar80/IAR80-Jsb.xml"
SRC_SHA256 = "ce95df946a1a617e340005fbe28a7b02dc65877bf5d622f92224c165b517b207"


def _state(alpha_deg=2.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0):
    """:func:`static_checks.ic_state` for the iar80 (150 kt at 10000 ft)."""
    return ic_state(aircraft("iar80"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_derivation_removes_only_the_engine():
    """The checked-in XML is the README's (20021 bytes, its SHA-256). ``IAR80_glide`` is that XML with its one
    ``<engine>`` (the IAR-K14-1000A radial, its two fuel feeds and the ``Prop`` thruster) removed from
    ``<propulsion>``; the two fuel tanks and every other element are equal (metrics, mass balance, ground
    reactions, flight control, aerodynamics, external reactions). The spec's notes carry the derived XML's hash."""
    src, der, spec = checked_in_model("iar80", "IAR80_glide", SRC, 20021, SRC_SHA256)
    canon = lambda e: ET.tostring(e, encoding="unicode").split()       # noqa: E731  (layout aside)
    assert [c.tag for c in src] == [c.tag for c in der]
    for tag in ("metrics", "mass_balance", "ground_reactions", "flight_control", "aerodynamics", "external_reactions"):
        assert canon(src.find(tag)) == canon(der.find(tag)), tag
    engines = src.find("propulsion").findall("engine")
    assert [e.get("file") for e in engines] == ["IAR-K14-1000A"] and engines[0].find("thruster").get("file") == "Prop"
    assert der.find("propulsion").findall("engine") == []
    assert list(map(canon, der.find("propulsion"))) == [canon(t) for t in src.find("propulsion").findall("tank")]


def test_the_iar80_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps the commands straight to the surfaces (``aerosurface_scale``, no damper): elevator, left
    and right aileron and rudder all +-0.35 rad x the command; the right aileron moves as the left (the file's
    Aeromatic FCS; only the left is read by the aerodynamics), so the harness reads the left alone
    (``aileron_props``) with delta_a = -left. No engine; after 50 frames every non-gravity force and moment
    is aerodynamic. A yaw rate does not move the rudder (no yaw damper), so the harness's own damper flies it."""
    spec = aircraft("iar80")
    assert spec.gains[5] == 0.4 and spec.gear_up and spec.aileron_props == ("fcs/left-aileron-pos-rad", None)
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 0.35), "fcs/left-aileron-pos-rad": (1, 0.35),
                               "fcs/right-aileron-pos-rad": (1, 0.35), "fcs/rudder-pos-rad": (2, 0.35)},
                        up=0.35, alpha_deg=2.0, r_rad_s=0.2)
    assert fdm.get_propulsion().get_num_engines() == 0
    assert_aileron_maps_back(spec, 2.0)
    assert_aero_is_the_only_force(fdm, 3000.0, external_zero=True)


def test_the_iar80_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic``, the harness's initial condition; the
    aerodynamic reference point is 8.7 in above the CG).

    - **Pitch:** without its ``Pitch_alphadot`` term, Cm falls with alpha: -0.48 per rad between -4 and 0 deg,
      -0.55 between 0 and 4 deg (``Pitch_alpha`` -0.5, and the lift and drag acting 8.7 in above the CG: its lift
      table has a break at alpha 0); no Cm0 of its own, Cm 0.008 at alpha 0 (the arm).
    - **Elevator:** Cm per rad of elevator (-1 + 0.375 Mach, Mach 0.316 here: -0.88) -0.897 trailing edge up and
      -0.865 down (``Drag_elevator`` reads the elevator's magnitude and acts through the arm).
    - **Roll and yaw:** per rad of left aileron Cl +0.18 (``Roll_aileron``; the project's Cl_delta_a -0.18) and
      Cn -0.003 (``Yaw_aileron``; Cn_delta_a +0.003, adverse); per rad of rudder Cl 0.01, Cn -0.1; Cl_beta -0.1216
      (``Roll_beta`` -0.1 and ``Side_beta`` -1 acting 8.7 in above the CG), Cn_beta 0.12. Cl and Cn at rest are 0.
    """
    spec = aircraft("iar80")
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.479, abs=0.01)), (0.0, 4.0, approx(-0.548, abs=0.01))),
                             ((-0.5, approx(-0.897, abs=0.005)), (0.5, approx(-0.865, abs=0.005))),
                             cm_at={0.0: approx(0.0077, abs=0.002)}, alpha_e=2.0, travel=(0.35, 0.35),
                             term="aero/moment/Pitch_alphadot")
    assert_lateral_derivatives(spec, (approx(0.18, rel=1e-6), approx(-0.003, rel=1e-6)),
                               (approx(-0.1, rel=1e-6), approx(0.01, rel=1e-6)),
                               {2.0: (approx(-0.1216, abs=5e-4), approx(0.12, rel=1e-6))},
                               alpha_deg=2.0, rest=1e-12, aileron_cmds=(0.4,), rudder_cmds=(0.4,))
