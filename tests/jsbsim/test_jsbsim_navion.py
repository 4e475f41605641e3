"""The navion in the JSBSim harness: the twenty-sixth session's untouched aircraft, a tuning aircraft since the
twenty-seventh session (docs/jsbsim.md, "The navion").

The model is JSBSim's Ryan Navion (the jsbsim 1.3.3 wheel's ``aircraft/L17/L17.xml``, "Originally from Bruce Jackson
(LaRCSim)?", LGPL-2.1 with JSBSim), a four-seat light aircraft of 2770 lb as the harness flies it and 33.42 ft
(10.19 m) of span, whose constant derivatives are the Navion's textbook set (Teper, NASA CR-96008, 1969; Nelson,
*Flight Stability and Automatic Control*, 2nd ed., 1998, appendix B): Cm_alpha -0.683, Cm_q -9.96, Cm_alphadot
-4.36, CY_beta -0.564 (the only side-force term), Cl_beta -0.074, Cl_p -0.41, Cl_r 0.107, Cn_beta 0.071, Cn_p
-0.0575, Cn_r -0.125, Cn_delta_r -0.072, a lift table in alpha with a kink at alpha 0. The file is checked in under
``data/jsbsim_models/navion/`` and flown as the derived model ``Navion_glide`` (``derived.py``): the engine and
propeller removed, the flap normaliser reading the flap kinematic's output (the file's ``fcs/flaps-pos-deg`` exists
nowhere, so JSBSim alone could not initialise it).

The checks here use the file and JSBSim's own properties (the harness's initial condition, ``run_ic``, no turbulence:
a mechanism check); none of them flies the harness:

- the checked-in file is the one the README names, and the derivation makes only its two edits; JSBSim's
  aerodynamic forces and moments of the derived model equal the stock wheel model's (which initialises in JSBSim
  alone once ``fcs/flaps-pos-deg`` exists);
- the FCS maps the commands straight to the surfaces (elevator -20.1 / +17.2 deg, ailerons +-20.1 deg, rudder
  +-20.1 deg); no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its XML says;
- the summaries label it bare, as every tuning aircraft (until the next untouched aircraft is added, no aircraft is
  labelled "(untouched)").

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, gear,
.tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the
names are slow.

No pipeline fit, GP, diagnosis or scoring ran on the navion before its final evaluation (twenty-sixth session); it
is a tuning aircraft since.
"""

import dataclasses
import xml.etree.ElementTree as ET

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_kept_but_engines, assert_same_aero_as_stock, assert_summaries_label_bare, bare_xml, \
    checked_in_model
from static_checks import assert_deflections_map_back, assert_lateral_derivatives, assert_pitch_derivatives, \
    check_direct_fcs, ic_state

SRC = "data/jsbsim_models/navion/L17.xml"
SRC_SHA256 = "4472cb86623b4fc6529381a270f09d722d52d352428787d93610d349aa23ccbf"


def _state(alpha_deg=0.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0)):
    """:func:`static_checks.ic_state` for the navion (120 kt at 10000 ft; it glides near alpha 0)."""
    return ic_state(aircraft("navion"), alpha_deg, beta_deg, cmds)


def _stock_state(alpha_deg, beta_deg, cmds):
    """The wheel's stock ``L17`` at the same initial condition as :func:`_state` (``fcs/flaps-pos-deg``, which its
    flap normaliser reads and nothing writes, created at 0 before ``run_ic``; its engine present, stopped)."""
    return ic_state(dataclasses.replace(aircraft("navion"), model="L17"), alpha_deg, beta_deg, cmds,
                    props=("fcs/flaps-pos-deg",))


def test_the_derivation_removes_the_engine_and_repoints_the_flap_normaliser():
    """The checked-in file is the README's (24580 bytes, its SHA-256). ``Navion_glide`` is that file without its
    ``<engine>`` (the IO-470-D and its propeller), its ``Flap Position Normalizer`` reading ``fcs/flap-pos-deg``
    (the flap kinematic's output) for ``fcs/flaps-pos-deg``; the tanks and every other element are equal (metrics,
    mass balance, ground reactions, every other FCS element, all 27 aerodynamic functions). The spec's notes carry
    the derived XML's hash."""
    src, der, spec = checked_in_model("navion", "Navion_glide", SRC, 24580, SRC_SHA256)
    ET.indent(src, space=" ")
    assert_kept_but_engines(src, der, ("metrics", "mass_balance", "ground_reactions", "aerodynamics"), 1, 2)
    assert [c.tag for c in der] == [c.tag for c in src]
    fc_s, fc_d = src.find("flight_control"), der.find("flight_control")
    norm = [c for c in fc_s.iter("aerosurface_scale") if c.get("name") == "Flap Position Normalizer"]
    assert len(norm) == 1 and norm[0].find("input").text.strip() == "fcs/flaps-pos-deg"
    norm[0].find("input").text = "fcs/flap-pos-deg"
    assert bare_xml(fc_s) == bare_xml(fc_d)
    assert len(list(src.find("aerodynamics").iter("function"))) == 27
    assert [p.text.strip() for p in der.find("aerodynamics").iter("property")].count("fcs/elevator-pos-rad") == 2


def test_the_derived_aerodynamics_are_the_stock_models():
    """At three states (alpha, sideslip, the three commands), JSBSim's aerodynamic forces and moments of
    ``Navion_glide`` equal those of the wheel's stock ``L17`` (its engine stopped, ``fcs/flaps-pos-deg`` at 0) to the
    last bit: the derivation changes no number."""
    assert_same_aero_as_stock(_state, _stock_state, 1, zero=("fcs/flap-pos-norm",))


def test_the_navion_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface (``aerosurface_scale``): elevator -0.35 rad (trailing
    edge up) to +0.30 rad, the left aileron +-0.35 rad with the command's sign and the right its mirror (delta_a =
    -0.5 (left - right) with ``aileron_sign`` -1), rudder +-0.35 rad; the harness's command scale is the elevator's
    larger, trailing-edge-up side (as the ka350's). No engine; 2770 lb (2750 empty, 2 x 10 lb of fuel); the gear
    retracts (``gear_up``); after 50 frames every non-gravity force and moment is aerodynamic."""
    spec = aircraft("navion")
    assert spec.gear_up and spec.cmd_per_rad == pytest.approx((1 / 0.35, 1 / 0.35, 1 / 0.35))
    assert _state()["inertia/weight-lbs"] == pytest.approx(2770.0, abs=0.01)
    check_direct_fcs(spec, min_lift_lbs=1000.0)
    assert_deflections_map_back(spec)


def test_the_navion_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 120 kt at
    10000 ft, Mach 0.253) without the ``Cmadot`` term (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha: -0.678 per rad between alpha -4 and 0 deg, -0.719 between 0 and 4, -0.768
      between 4 and 8 (Cmalpha -0.683 and the lift and drag acting 8.3 in below the reference point); Cm +0.0068 at
      alpha 0; per rad of elevator -0.836 (trailing edge down) and -0.844 (up) (Cmde -0.923 + 0.324 Mach, and CLde).
    - **Roll and yaw:** per rad of the left aileron Cl +0.1242 (Clda 0.134 - 0.0385 Mach; the project's Cl_delta_a
      -0.124) and Cn -0.0035 (Cnda: the project's Cn_delta_a +0.0035, adverse); per rad of rudder Cn -0.072 (Cndr)
      and Cl +0.0107 (Cldr; no rudder side force); Cl_beta -0.0871 (Clb -0.074 and CYb's arm) and Cn_beta 0.071 at
      alpha 0 and 6 deg (constants).
    """
    spec = aircraft("navion")
    assert _state()["velocities/mach"] == pytest.approx(0.2534, abs=0.002)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.678, abs=0.003)), (0.0, 4.0, approx(-0.719, abs=0.003)),
                                    (4.0, 8.0, approx(-0.768, abs=0.005))),
                             ((0.3, approx(-0.836, abs=0.002)), (-0.3, approx(-0.844, abs=0.002))),
                             cm_at={0.0: approx(0.0068, abs=0.0005)})
    beta = (approx(-0.0871, abs=5e-4), approx(0.071, abs=1e-4))
    assert_lateral_derivatives(spec, (approx(0.1242, abs=2e-4), approx(-0.0035, abs=1e-6)),
                               (approx(-0.072, abs=1e-6), approx(0.0107, abs=1e-6)), {0.0: beta, 6.0: beta})


def test_summaries_mark_no_aircraft_untouched_the_navion_included(tmp_path):
    """The markdown summaries of eval_jsbsim and eval_jsbsim_diagnose label the navion bare, as every other aircraft
    (synthetic rows): the twenty-seventh session moved it to tuning, the twenty-eighth the fokker50, and no aircraft is
    "(untouched)" or "(held out)" until the next one is added."""
    assert_summaries_label_bare(tmp_path, "fokker50", ("navion", "dr1", "fokker50"))
