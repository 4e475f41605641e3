"""The dr1 in the JSBSim harness: the twenty-fifth session's untouched aircraft, a tuning aircraft since the
twenty-sixth session (docs/jsbsim.md, "The dr1").

The model is JSBSim's Fokker Dr.I triplane (Ron Jensen and Erik Hofman 2008, from an Aeromatic 0.9 start; the jsbsim
1.3.3 wheel's ``aircraft/dr1/dr1.xml``, LGPL-2.1 with JSBSim), a 1917 triplane fighter of 945 lb as the harness flies
it and 23.62 ft (7.20 m) of span, whose aerodynamics are its own: a lift table over +-180 deg of alpha, the pitching
moment as a table in alpha plus a table in alpha and elevator, constant lateral-directional derivatives with five
side-force terms, a negative Clr and a proverse aileron yaw. The file is checked in under
``data/jsbsim_models/fokkerdr1/`` and flown as the derived model ``Dr1_glide`` (``derived.py``): the rotary engine
and propeller, the pushback force and the pushback system removed, the Cmde table reading the elevator through an
identity alias.

The checks here use the file and JSBSim's own properties (the harness's initial condition, ``run_ic``, no turbulence:
a mechanism check); none of them flies the harness:

- the checked-in file is the one the README names, and the derivation makes only its four edits; JSBSim's
  aerodynamic forces and moments of the derived model equal the stock wheel model's (which initialises in JSBSim
  alone once the five FlightGear properties its pushback system reads exist);
- the FCS maps the commands straight to the surfaces (elevator +-20.1 deg, ailerons +-17.2 deg, rudder +-8.8 deg:
  the command clipped at 0.35 of +-25.2 deg); no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its XML says;
- the summaries label it bare, as every tuning aircraft (the navion's label is checked in
  ``test_jsbsim_navion.py``).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, .tlog,
hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the names
are slow.

No pipeline fit, GP, diagnosis or scoring ran on the dr1 before its final evaluation (twenty-fifth session); it is a
tuning aircraft since.
"""

import dataclasses
import xml.etree.ElementTree as ET

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_kept_but_engines, assert_same_aero_as_stock, assert_summaries_label_bare, bare_xml, \
    checked_in_model
from static_checks import assert_aero_is_the_only_force, assert_deflections_map_back, assert_lateral_derivatives, \
    assert_pitch_derivatives, ic_state, surface_state

SRC = "data/jsbsim_models/fokkerdr1/dr1.xml"
SRC_SHA256 = "bd394cb162b91e4a11e97e2fbf490e1d5a9ddb0feeed4f5a4c8cf237cedc22f8"

#: The FlightGear properties the stock model's pushback system reads (``Systems/pushback.xml``): without them
#: ``run_ic`` raises; at 0 its force switch stays at its default (no tug, ``external_reactions/pushback`` 0).
_PUSHBACK_PROPS = ("/sim/model/pushback/position-norm", "/sim/model/pushback/target-speed-fps",
                   "/sim/model/pushback/kp", "/sim/model/pushback/ki", "/sim/model/pushback/kd", "/gear/gear/wow")


def _state(alpha_deg=0.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0)):
    """:func:`static_checks.ic_state` for the dr1 (70 kt at 8000 ft; it glides near alpha 0)."""
    return ic_state(aircraft("dr1"), alpha_deg, beta_deg, cmds)


def _stock_state(alpha_deg, beta_deg, cmds):
    """The wheel's stock ``dr1`` at the same initial condition as :func:`_state` (its pushback system's FlightGear
    properties created at 0 before ``run_ic``; its engine present, stopped)."""
    return ic_state(dataclasses.replace(aircraft("dr1"), model="dr1"), alpha_deg, beta_deg, cmds,
                    props=_PUSHBACK_PROPS)


def test_the_derivation_removes_the_engine_and_pushback_and_aliases_the_elevator_lookup():
    """The checked-in file is the README's (30855 bytes, its SHA-256). ``Dr1_glide`` is that file without its
    ``<engine>``, its ``<external_reactions>`` (the pushback force) and its ``pushback`` system; its ``Cmde`` table
    looks the elevator up in ``aero/function/elevator-pos-rad``, the identity function of ``fcs/elevator-pos-rad``
    added as the aerodynamics' first child; the tank and every other element are equal (metrics, mass balance,
    ground reactions, the flight control, every other aerodynamic function). The spec's notes carry the derived
    XML's hash."""
    from benchmarks.jsbsim_harness.derived import ELEVATOR_ALIAS

    src, der, spec = checked_in_model("dr1", "Dr1_glide", SRC, 30855, SRC_SHA256)
    ET.indent(src, space=" ")
    assert_kept_but_engines(src, der, ("metrics", "mass_balance", "ground_reactions", "flight_control"), 1, 1)
    assert [x.get("file") for x in src.findall("system")] == ["pushback"] and der.find("system") is None
    assert src.find("external_reactions") is not None and der.find("external_reactions") is None
    assert [c.tag for c in der] == [c.tag for c in src if c.tag not in ("external_reactions", "system")]
    s_aero, d_aero = src.find("aerodynamics"), der.find("aerodynamics")
    assert d_aero[0].get("name") == ELEVATOR_ALIAS and [p.text for p in d_aero[0].iter("property")] == [
        "fcs/elevator-pos-rad"]
    lookups = [iv for iv in s_aero.iter("independentVar") if iv.text.strip() == "fcs/elevator-pos-rad"]
    assert len(lookups) == 1
    lookups[0].text = ELEVATOR_ALIAS
    assert [a.get("name") for a in s_aero] == [a.get("name") for a in d_aero][1:]
    s_fun, d_fun = list(s_aero.iter("function")), list(d_aero.iter("function"))[1:]
    assert len(s_fun) == len(d_fun) == 27
    for a, b in zip(s_fun, d_fun):
        assert bare_xml(a) == bare_xml(b), a.get("name")


def test_the_derived_aerodynamics_are_the_stock_models():
    """At three states (alpha, sideslip, the three commands), JSBSim's aerodynamic forces and moments of
    ``Dr1_glide`` equal those of the wheel's stock ``dr1`` (its rotary engine stopped, its pushback idle) to the last
    bit: the derivation changes no number."""
    assert_same_aero_as_stock(_state, _stock_state, 1)


def test_the_dr1_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface (``aerosurface_scale``): elevator +-0.35 rad, both
    ailerons +-0.30 rad with the command's sign (the aerodynamics read the left one: delta_a = -left with
    ``aileron_sign`` -1), rudder 0.44 rad per unit command with the command clipped at +-0.35 (0.154 rad, 8.8 deg,
    of travel). No engine; 945 lb (895 empty, 50 of fuel); after 50 frames every non-gravity force and moment is
    aerodynamic and the external forces are 0."""
    spec = aircraft("dr1")
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 0.35), "fcs/left-aileron-pos-rad": (1, 0.30),
                               "fcs/right-aileron-pos-rad": (1, 0.30), "fcs/rudder-pos-rad": (2, 0.44)},
                        alpha_deg=0.0, rel=1e-6)
    assert fdm.get_propulsion().get_num_engines() == 0 and fdm["inertia/weight-lbs"] == pytest.approx(945.0, abs=0.01)
    assert _state(cmds=(0.0, 0.0, 0.9))["fcs/rudder-pos-rad"] == pytest.approx(0.35 * 0.44, rel=1e-6)
    assert spec.cmd_per_rad == pytest.approx((1 / 0.35, 1 / 0.30, 1 / 0.44))
    assert_deflections_map_back(spec)
    assert_aero_is_the_only_force(fdm, 200.0, external_zero=True)


def test_the_dr1_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 70 kt at
    8000 ft, Mach 0.138) without the ``Cmadot`` term (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha: -0.175 per rad between alpha -4 and 0 deg, -0.202 between 0 and 4, -0.408
      between 4 and 8 (the Cmalpha table, flat there, and the Cmde table at zero elevator); Cm -0.0131 at alpha 0;
      per rad of elevator -0.283 (trailing edge down) and -0.275 (up): Cmde's table has a kink at 0.
    - **Roll and yaw:** per rad of the left aileron Cl +0.087 (Clda; the project's Cl_delta_a -0.087) and Cn
      +0.0552 (Cnda: the project's Cn_delta_a -0.0552, proverse); per rad of rudder Cn -0.0503 (Cndr -0.0502 and
      CYdr's arm) and Cl -0.0031 (Cldr -0.005 and CYdr 5.75 in above the CG); Cl_beta -0.0287 (Clbeta -0.02 and
      CYbeta's arm) and Cn_beta 0.0965 at alpha 0 and 6 deg (constants).
    """
    spec = aircraft("dr1")
    assert _state()["velocities/mach"] == pytest.approx(0.1383, abs=0.002)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.175, abs=0.003)), (0.0, 4.0, approx(-0.202, abs=0.003)),
                                    (4.0, 8.0, approx(-0.408, abs=0.005))),
                             ((0.3, approx(-0.283, abs=0.002)), (-0.3, approx(-0.275, abs=0.002))),
                             cm_at={0.0: approx(-0.0131, abs=0.0005)})
    beta = (approx(-0.0287, abs=3e-4), approx(0.0965, abs=3e-4))
    assert_lateral_derivatives(spec, (approx(0.087, abs=1e-6), approx(0.0552, abs=1e-6)),
                               (approx(-0.0503, abs=2e-4), approx(-0.0031, abs=2e-4)), {0.0: beta, 6.0: beta})


def test_summaries_mark_no_aircraft_untouched_the_dr1_included(tmp_path):
    """The markdown summaries of eval_jsbsim and eval_jsbsim_diagnose label the dr1 bare, as every other tuning
    aircraft (synthetic rows of tuning aircraft only): the twenty-sixth session moved it to tuning, so none of them
    is "(untouched)" or "(held out)"."""
    assert_summaries_label_bare(tmp_path, "dr1", ("dr1", "s23"))
