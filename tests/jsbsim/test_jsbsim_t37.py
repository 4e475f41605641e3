"""The t37 in the JSBSim harness: the eighth session's untouched aircraft (docs/jsbsim.md, "The t37"),
evaluated in its final evaluation and used since (the ninth session's untouched aircraft is the t6,
``test_jsbsim_t6.py``). Its checks below are slow tests now, but for the names' test.

Only the harness is checked here, on JSBSim's exact truth and its own properties: the rigid-body
consistency of the truth with the checked-in airframe file, the sign map against the model's XML
constants, the gear retracted by the harness, the .tlog as the pipeline decodes it, every hidden
effect as JSBSim computes it (the injected moments reach JSBSim's total aerodynamic moments), the
airspeed bias in the log and that the evaluation's flights stay in
the envelope with every axis excited. No pipeline fit, GP, diagnosis or scoring is run on the t37
here. One 30-s flight serves the module's tests.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft
from truth_fits import (ENVELOPE_FLIGHTS, assert_airspeed_bias_in_log, assert_hidden_effects_in_jsbsim,
                        assert_in_envelope, assert_names_resolve, assert_rigid_body_glide, assert_servos_map_back,
                        derivative_slopes, evaluation_envelope, short_flight_fixture)
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log


t37_flight = short_flight_fixture("t37")      # fixture "t37": 30 s, light, seed 1


def test_names_resolve_and_the_t37_is_used():
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, summary_label

    assert_names_resolve("t37", "T37", "t3")
    assert "t37" in TUNING_AIRCRAFT and "t37" not in HELD_OUT_AIRCRAFT and summary_label("t37") == "t37"


@pytest.mark.slow
def test_truth_is_rigid_body_consistent_with_the_airframe_file(t37):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J; in the glide
    every non-gravity force and moment is aerodynamic (both jets stopped, "direct" thrusters); the
    mass is the model's 4056 lb empty plus 2 x 350 lb of fuel on the centre line, no point mass,
    and the model gives no product of inertia at all."""
    assert_rigid_body_glide(t37, mass_lb=4756)
    const, af = t37.recording.constants, load_airframe(t37.airframe)
    assert const["Ixy"] == const["Iyz"] == const["Ixz"] == 0.0 and af.inertia[0, 2] == 0.0


@pytest.mark.slow
def test_sign_map_gives_the_project_conventions(t37):
    """Least squares on the exact truth: Cm_delta_e, Cl_delta_a, Cn_delta_r, Cm_alpha, Cl_p < 0,
    Cn_beta > 0, and the lateral control derivatives at the model's constants (T37.xml: Clda
    0.181 - 0.0705 Mach x left-aileron-pos, so Cl_delta_a = -0.157 in the project's sign at the
    flight's Mach 0.34; Cnda -0.0254 x left-aileron-pos, so Cn_delta_a = +0.0254; Cndr -0.0365)."""
    cm, cl, cn = derivative_slopes(t37.recording)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    assert cl[3] == pytest.approx(-0.157, rel=0.03)
    assert cn[3] == pytest.approx(0.0254, rel=0.1) and cn[4] == pytest.approx(-0.0365, rel=0.05), cn


@pytest.mark.slow
def test_the_harness_flies_the_t37_with_its_gear_up():
    """``gear_up``: the retractable gear (5 s from down to up) is up before the log starts (the 15-s
    settling phase), so its drag and its gear-down stability terms (DCYbdf, DClrDg, DCnbDg) are zero."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("t37")
    assert spec.gear_up and not aircraft("c182").gear_up
    fdm = load_model(spec, 1 / 200)
    _set_ic(fdm, spec, FlightConfig("t37", turbulence="none"))
    for _ in range(int(FlightConfig("t37").settle_s * 200)):
        fdm.run()
    assert fdm["gear/gear-pos-norm"] == 0.0
    assert all(fdm[f"aero/coefficient/{n}"] == 0.0 for n in ("CDgear", "DCYbdf", "DClrDg", "DCnbDg"))


@pytest.mark.slow
def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(t37):
    """The pipeline's decoder reads the t37's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (the elevator's 18.6-deg end,
    the mean of its -20.1 and +17.2 deg, makes 0.047 deg per microsecond)."""
    assert_servos_map_back(t37)


@pytest.mark.slow
def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments():
    """On the t37's XML (LIFT/DRAG/SIDE and ROLL/PITCH/YAW axes, one aileron property in the
    aerodynamics) every effect does what ``effects.py`` specifies, in JSBSim's own properties at
    the same initial condition (alpha 4 deg, sideslip 4 deg, fixed surfaces; ``run_ic`` evaluates
    the models there): each injected moment is k alpha^2, k alpha beta or k delta_a (the harness's
    delta_a) times qbar S c|b, and is exactly the change of JSBSim's total aerodynamic moment
    against the stock model; CY:scale multiplies the sum of the five SIDE functions by k (the
    wind-axis side force by k); the delay holds the elevator that the lift and pitching-moment
    functions read 24 frames (0.12 s at 200 Hz) behind the surface."""
    assert_hidden_effects_in_jsbsim(aircraft("t37"), 0.30)     # +1 = 0.30 rad trailing edge down


@pytest.mark.slow
def test_airspeed_bias_reaches_the_logged_airspeed(t37, tmp_path):
    """``bias:airspeed`` = 2 m/s of TAS in a second log of the fixture's flight: 2 sqrt(rho / rho0) m/s
    more decoded airspeed, sample by sample."""
    assert_airspeed_bias_in_log(t37, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", ENVELOPE_FLIGHTS)    # with the evaluation's pair
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """Each flight the final evaluation flies on the t37 (120 s) keeps inside its linear envelope,
    read from ``flight_envelope`` of the truth file: no knock-it-off, alpha within -5..7 deg (the
    stall is near 15 deg, CLalpha's peak at 0.26 rad), at most 6 deg of sideslip and 18 of bank
    (9 and 30 with Cl:alpha*beta = 3, whose reversed dihedral rolls it), a TAS above 1.3 x the
    stall's (46.9 m/s at 12000 ft for 76 kt EAS) and under 150 m/s, every rate and surface moving
    (also in the held-out 20 %), and still 500 m above sea level at the end of the glide."""
    limits = dict(alpha=(-5.0, 7.0), beta=(6.0, 9.0), bank=(18.0, 30.0), speed=(1.3 * 46.9, 150.0), alt_min=500.0)
    assert_in_envelope(evaluation_envelope("t37", seed, turbulence, plan, effects, tmp_path), **limits,
                       rate_std=1.8, rate_std_held=1.8)     # deg/s; least measured 2.2, 2.4
