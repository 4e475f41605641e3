"""The c182 in the JSBSim harness: the seventh session's untouched aircraft of issues 8 and 9
(docs/jsbsim.md, "The c182"); evaluated since, it now counts as used (the b747 is the untouched one:
``test_jsbsim_b747.py`` checks the summaries' label and the eval scripts' ``--fly-only`` on it).

Only the harness is checked here, on JSBSim's exact truth and its own properties: the rigid-body
consistency of the truth with the checked-in airframe file, the sign map against the model's XML
constants, the .tlog as the pipeline decodes it, every hidden effect as JSBSim computes it (the
injected moments reach JSBSim's total aerodynamic moments), the summaries' label, and (slow) that
the evaluation's flights stay in the envelope with every axis excited. No pipeline fit, GP,
diagnosis or scoring is run on the c182 here (it was set up before its final evaluation).
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import aircraft
from truth_fits import (ENVELOPE_FLIGHTS, assert_airspeed_bias_in_log, assert_hidden_effects_in_jsbsim,
                        assert_in_envelope, assert_names_resolve, assert_rigid_body_glide, assert_servos_map_back,
                        derivative_slopes, evaluation_envelope, short_flight_fixture)
from gcs_sysid.airframe import load_airframe


c182_flight = short_flight_fixture("c182")      # fixture "c182": 30 s, light, seed 1


def test_names_resolve_and_the_c182_now_counts_as_used():
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, summary_label

    assert_names_resolve("c182", "c182", "c18")
    assert "c182" in TUNING_AIRCRAFT and "c182" not in HELD_OUT_AIRCRAFT and summary_label("c182") == "c182"


def test_truth_is_rigid_body_consistent_with_the_airframe_file(c182):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J; in the glide
    every non-gravity force and moment is aerodynamic (engine stopped); the mass is the model's
    1700 lb empty plus 400 lb of fuel, its one point mass (a 180 lb pilot at y = -14 in) emptied
    by the harness, so no product of inertia but Ixz remains."""
    assert_rigid_body_glide(c182, mass_lb=2100)
    const, af = c182.recording.constants, load_airframe(c182.airframe)
    assert const["Ixy"] == 0.0 and const["Iyz"] == 0.0 and af.inertia[0, 2] != 0.0


def test_sign_map_gives_the_project_conventions(c182):
    """Least squares on the exact truth: Cm_delta_e, Cl_delta_a, Cn_delta_r, Cm_alpha, Cl_p < 0,
    Cn_beta > 0, and the lateral control derivatives at the model's constants (c182.xml: ClDa
    +0.15 x left-aileron-pos, so Cl_delta_a = -0.15 in the project's sign; CnDr -0.0645 at alpha 0
    to -0.0805 at 5.4 deg, the flight's alpha in between)."""
    cm, cl, cn = derivative_slopes(c182.recording)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    assert cl[3] == pytest.approx(-0.15, rel=0.03)
    assert -0.0805 < cn[4] < -0.0645, cn


def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(c182):
    """The pipeline's decoder reads the c182's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (the elevator's 25.5-deg end
    makes 0.064 deg per microsecond)."""
    assert_servos_map_back(c182)


def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments():
    """On the c182's XML (LIFT/DRAG/SIDE and ROLL/PITCH/YAW axes, qbar and S as separate factors,
    one aileron property in the aerodynamics) every effect does what ``effects.py`` specifies, in
    JSBSim's own properties at the same initial condition (alpha 4 deg, sideslip 4 deg, fixed
    surfaces; ``run_ic`` evaluates the models there): each injected moment is k alpha^2, k alpha beta or k delta_a (the
    harness's delta_a) times qbar S c|b, and is exactly the change of JSBSim's total aerodynamic
    moment against the stock model; CY:scale multiplies the sum of the SIDE functions by k (the
    wind-axis side force by k); the delay holds the elevator that the lift and
    pitching-moment functions read 24 frames (0.12 s at 200 Hz) behind the surface."""
    assert_hidden_effects_in_jsbsim(aircraft("c182"), np.radians(23.0))     # +1 = 23 deg trailing edge down


@pytest.mark.slow
def test_airspeed_bias_reaches_the_logged_airspeed(c182, tmp_path):
    """``bias:airspeed`` = 2 m/s of TAS in a second log of the fixture's flight: 2 sqrt(rho / rho0) m/s
    more decoded airspeed, sample by sample."""
    assert_airspeed_bias_in_log(c182, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", ENVELOPE_FLIGHTS)    # with the evaluation's pair
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """The c182 flies the evaluation's plans as a test pilot would (``flight_envelope`` of the truth
    file): no knock-it-off; alpha far below the stall (about 16 deg: CLalpha's peak at 0.28 rad);
    sideslip under 8 deg (13 deg with the reversed dihedral of Cl:alpha*beta = 3) and bank under
    15 deg (25); airspeed at least 1.15 times the stall (49 kt EAS, 27.8 m/s TAS at 6000 ft) and
    far below the C182's never-exceed 175 kt; every axis excited (rates, also in the held-out
    last 20 %, and surfaces); the glide loses height."""
    e = evaluation_envelope("c182", seed, turbulence, plan, effects, tmp_path)
    assert_in_envelope(e, alpha=(-4.0, 8.0), beta=(8.0, 13.0), bank=(15.0, 25.0), speed=(1.15 * 27.8, 70.0),
                       rate_std=1.8, rate_std_held=1.5)          # least measured: 2.0, 1.8 deg/s
