"""The fokker50 in the JSBSim harness: the twenty-seventh session's untouched aircraft, a tuning aircraft since the
twenty-eighth (docs/jsbsim.md, "The fokker50").

The model is JSBSim's Fokker 50 (the jsbsim 1.3.3 wheel's ``aircraft/fokker50/fokker50.xml``, Erik Hofman 2002,
LGPL-2.1 with JSBSim), the twin-turboprop regional airliner, 31900 lb as the harness flies it and 95.15 ft (29.0 m)
of span, with its own derivatives (not Aeromatic's set): Cm_alpha -1.876, Cm_q -20.13, Cm_alphadot -5.75,
CL_q 5.22, CL_alphadot 1.49, four side-force terms (CY_beta -0.416, CY_p a table in Reynolds number, CY_r 0.362,
CY_delta_r 0.253), Cl_beta and Cl_r tables in alpha and Reynolds number, Cl_p -0.514, Cn_beta 0.181, Cn_p a table in
Reynolds number, Cn_r -0.174, Cn_delta_r -0.110, Cn_delta_a -0.008 per rad of the left aileron. The file is checked in
under ``data/jsbsim_models/fokker50/`` and flown as the derived model ``Fokker50_glide`` (``derived.py``): the
engines and propellers removed with the channels that read them (the engine control reads FlightGear's throttle, so
JSBSim alone could not initialise it), the three propwash terms (products with the propellers' thrust coefficients:
0 without propellers) and the yaw damper removed.

The checks here use the file and JSBSim's own properties (the harness's initial condition, ``run_ic``, no turbulence:
a mechanism check); none of them flies the harness:

- the checked-in file is the one the README names, and the derivation makes only its five edits; every aerodynamic
  function of the derived model equals the stock wheel model's (which initialises in JSBSim alone once FlightGear's
  two throttle properties exist) but the induced drag, which reads the total lift the removed propwash term enters,
  and where the propwash tables are 0 the forces and moments are the stock model's bit for bit;
- the FCS maps the commands straight to the surfaces (elevator -20.1 / +17.2 deg, ailerons +-20.1 deg, rudder
  +-20.1 deg, no yaw damper); no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its XML says.

That the summaries label it bare, as every tuning aircraft, is checked in ``test_jsbsim_navion.py``.

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, gear,
.tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the
names are slow.

No pipeline fit, GP, diagnosis or scoring ran on the fokker50 before its final evaluation (twenty-seventh session); it
is a tuning aircraft since.
"""

import dataclasses
import xml.etree.ElementTree as ET

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_kept_but_engines, bare_xml, checked_in_model, same_xml
from static_checks import assert_deflections_map_back, assert_lateral_derivatives, assert_pitch_derivatives, \
    check_direct_fcs, ic_state

SRC = "data/jsbsim_models/fokker50/fokker50.xml"
SRC_SHA256 = "dd6507d48e51e27423c89af29a036ae7e8c797add03df115bdbc2e4132932a89"
WASH = ("aero/force/Lift_propwash", "aero/moment/Roll_differential_propwash", "aero/moment/Pitch_propwash")
OWN_STATE = ("aero/coefficient/CDi", "aero/force/Lift_alpha_rate", "aero/coefficient/Cmadot")


def _state(alpha_deg=0.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0)):
    """:func:`static_checks.ic_state` for the fokker50 (180 kt at 10000 ft; it glides near alpha -1 deg)."""
    return ic_state(aircraft("fokker50"), alpha_deg, beta_deg, cmds)


def _stock_state(alpha_deg, beta_deg, cmds):
    """The wheel's stock ``fokker50`` at the same initial condition as :func:`_state` (FlightGear's
    ``/controls/engines/engine[n]/throttle``, which its engine control reads and nothing writes, created at 0 before
    ``run_ic``; its engines present, stopped, their propellers windmilling)."""
    return ic_state(dataclasses.replace(aircraft("fokker50"), model="fokker50"), alpha_deg, beta_deg, cmds,
                    props=("/controls/engines/engine/throttle", "/controls/engines/engine[1]/throttle"))


def _functions(root):
    return [f.get("name") for f in root.find("aerodynamics").iter("function")]


def test_the_derivation_removes_the_engines_their_channels_the_propwash_and_the_yaw_damper():
    """The checked-in file is the README's (43202 bytes, its SHA-256). ``Fokker50_glide`` is that file without its
    two ``<engine>`` (PW125B and Dowty Rotol propeller), the ``EEC`` and ``Thruster`` channels and the two
    ``/systems/fokker50/erp`` properties, the three propwash functions, the four yaw-damper components and the
    rudder summer's damper input; the tanks and every other element are equal (metrics, mass balance, ground
    reactions, the NWS system, every other FCS element, the other 33 aerodynamic functions). The spec's notes carry
    the derived XML's hash."""
    src, der, spec = checked_in_model("fokker50", "Fokker50_glide", SRC, 43202, SRC_SHA256)
    ET.indent(src, space=" ")
    assert_kept_but_engines(src, der, ("metrics", "mass_balance", "ground_reactions", "system"), 2, 2)
    assert [c.tag for c in der] == [c.tag for c in src]
    fc_s = src.find("flight_control")
    for ch in [c for c in fc_s.findall("channel") if c.get("name") in ("EEC", "Thruster")]:
        fc_s.remove(ch)
    for p in [p for p in fc_s.findall("property") if p.text.strip().startswith("/systems/fokker50/erp/")]:
        fc_s.remove(p)
    yaw = [c for c in fc_s.findall("channel") if c.get("name") == "Yaw"][0]
    for c in [c for c in yaw if c.get("name", "").startswith("Yaw Damper")]:
        yaw.remove(c)
    rsum = [c for c in yaw if c.get("name") == "Rudder Sum"][0]
    rsum.remove([i for i in rsum.findall("input") if i.text.strip() == "fcs/yaw-damper-final"][0])
    assert bare_xml(fc_s) == bare_xml(der.find("flight_control"))
    assert len(_functions(src)) == 36 and set(_functions(src)) - set(_functions(der)) == set(WASH)
    aero_s = src.find("aerodynamics")
    for axis in aero_s.findall("axis"):
        for f in [f for f in axis.findall("function") if f.get("name") in WASH]:
            axis.remove(f)
    assert same_xml(aero_s, der.find("aerodynamics"))
    assert [p.text.strip() for p in der.find("aerodynamics").iter("property")].count("fcs/elevator-pos-rad") == 2
    assert not any("propulsion" in (p.text or "") for p in der.iter("property"))


def test_the_derived_aerodynamics_are_the_stock_models_without_propwash():
    """At four states (alpha, sideslip, the three commands), every aerodynamic function of ``Fokker50_glide`` equals
    the wheel's stock ``fokker50``'s (its engines stopped, their propellers windmilling: total thrust coefficient
    -1.25) to the last bit, but three that read a state the propellers change: ``CDi`` (0.03 CL^2 k_ge, whose CL
    includes the stock model's propwash lift) and the alpha-dot terms ``Lift_alpha_rate`` (1.4906) and ``Cmadot``
    (-5.7526), whose alpha-dot ``run_ic`` computes from accelerations that include the windmilling propellers'
    forces; those three are the derived model's state times the file's numbers (the stock model's alpha-dot after
    ``run_ic`` can be NaN in JSBSim 1.3.3 once another instance with its turboprops has run in the process: the
    harness never flies the stock model). The derivation changes no number and
    removes three terms; the stock model's propwash terms are 0 where their tables are (alpha below -0.15 rad for
    the lift and pitch terms; equal propellers for the roll term) and not at alpha 0."""
    from benchmarks.jsbsim_harness.derived import derived_xml

    names = _functions(ET.fromstring(derived_xml("Fokker50_glide")))
    assert len(names) == 33 and "aero/coefficient/CDi" in names
    for alpha, beta, cmds in ((4.0, 4.0, (0.3, -0.4, 0.2)), (-3.0, -2.0, (-0.2, 0.3, -0.5)), (0.0, 0.0, (0, 0, 0)),
                              (-9.0, 3.0, (0.2, 0.3, -0.4))):
        a, b = _state(alpha, beta, cmds), _stock_state(alpha, beta, cmds)
        assert a.get_propulsion().get_num_engines() == 0 and b.get_propulsion().get_num_engines() == 2
        assert b["systems/propulsion/thrust-coefficient"] == pytest.approx(-1.248, abs=1e-3)
        assert b["systems/propulsion/thrust-coefficient-left-right"] == 0.0
        for name in names:
            if name not in OWN_STATE:
                assert a[name] == b[name], (alpha, name)
        for m in (a,):     # the derived model's own (the stock model's alpha-dot: see above)
            qs = m["aero/qbar-psf"] * m["metrics/Sw-sqft"]
            assert m["aero/coefficient/CDi"] == pytest.approx(
                qs * m["aero/cl-squared"] * m["aero/function/kCDge"] * 0.03, rel=1e-12)
            adot = m["aero/alphadot-rad_sec"] * m["aero/ci2vel"]
            assert m["aero/force/Lift_alpha_rate"] == pytest.approx(qs * adot * 1.4906, rel=1e-12)
            assert m["aero/coefficient/Cmadot"] == pytest.approx(qs * m["metrics/cbarw-ft"] * adot * -5.7526,
                                                                  rel=1e-12)
        assert b["aero/moment/Roll_differential_propwash"] == 0.0
        if alpha < -8.6 or alpha == 0.0:
            assert (b["aero/force/Lift_propwash"] == 0.0) == (b["aero/moment/Pitch_propwash"] == 0.0) == (alpha < 0)
        del a, b


def test_the_fokker50_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface (``aerosurface_scale``): elevator -0.35 rad (trailing
    edge up) to +0.30 rad, the left aileron +-0.35 rad with the command's sign and the right its mirror (delta_a =
    -0.5 (left - right) with ``aileron_sign`` -1), rudder +-0.35 rad with no yaw damper (the check's yaw rate of 0.2
    rad/s leaves it at the command); the harness's command scale is the elevator's larger, trailing-edge-up side (as
    the navion's). No engine; 31900 lb (29700 empty, 2 x 1100 lb of fuel 3 in either side of the centre line); the
    gear retracts (``gear_up``); after 50 frames every non-gravity force and moment is aerodynamic."""
    spec = aircraft("fokker50")
    assert spec.gear_up and spec.cmd_per_rad == pytest.approx((1 / 0.35, 1 / 0.35, 1 / 0.35))
    assert _state()["inertia/weight-lbs"] == pytest.approx(31900.0, abs=0.01)
    check_direct_fcs(spec, min_lift_lbs=10000.0)
    assert_deflections_map_back(spec)


def test_the_fokker50_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 180 kt at
    10000 ft, Mach 0.378 as ``ic_state`` sets it, Reynolds number 16.0 million) without the ``Cmadot`` term
    (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha: -1.911 per rad between alpha -4 and 0 deg, -2.001 between 0 and 4, -2.179
      between 4 and 8 (Cmalpha -1.876 and the lift and drag acting 24.9 in below the reference point); Cm +0.0201 at
      alpha 0; per rad of elevator -1.385 (trailing edge down) and -1.406 (up) (Cmde -1.628 + 0.6105 Mach, and
      CLde).
    - **Roll and yaw:** per rad of the left aileron Cl +0.1287 (Clda 0.15 - 0.05625 Mach; the project's Cl_delta_a
      -0.129) and Cn -0.008 (Cnda: the project's Cn_delta_a +0.008, adverse); per rad of rudder Cn -0.1102 (Cndr) and
      Cl +0.0155 (Cldr 0.01 and the rudder's side force 24.9 in above the CG); Cl_beta -0.0403 at alpha 0 and
      -0.0445 at 6 deg (Clb a table in alpha and Reynolds number, and CYb's arm), Cn_beta 0.1809 (a constant).
    """
    spec = aircraft("fokker50")
    s0 = _state()
    assert s0["velocities/mach"] == pytest.approx(0.3782, abs=0.002)
    assert s0["aero/Re"] == pytest.approx(16.03e6, rel=0.01)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-1.911, abs=0.005)), (0.0, 4.0, approx(-2.001, abs=0.005)),
                                    (4.0, 8.0, approx(-2.179, abs=0.005))),
                             ((0.3, approx(-1.385, abs=0.003)), (-0.3, approx(-1.406, abs=0.003))),
                             cm_at={0.0: approx(0.0201, abs=0.0005)})
    assert_lateral_derivatives(spec, (approx(0.1287, abs=2e-4), approx(-0.008, abs=1e-6)),
                               (approx(-0.1102, abs=1e-4), approx(0.0155, abs=1e-4)),
                               {0.0: (approx(-0.0403, abs=5e-4), approx(0.1809, abs=1e-4)),
                                6.0: (approx(-0.0445, abs=5e-4), approx(0.1809, abs=1e-4))})
