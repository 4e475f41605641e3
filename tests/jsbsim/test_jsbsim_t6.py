"""The t6 in the JSBSim harness: the ninth session's untouched aircraft (docs/jsbsim.md, "The t6"),
evaluated in its final evaluation and used since (the tenth session's untouched aircraft is the b747,
``test_jsbsim_b747.py``). Its checks below are slow tests now, but for the names' test.

Only the harness is checked here, on JSBSim's exact truth and its own properties: the rigid-body
consistency of the truth with the checked-in airframe file (the model's product of inertia Ixz
included), the sign map against the model's XML constants, the gear retracted by the harness, the
.tlog as the pipeline decodes it, every hidden effect as JSBSim computes it (the injected moments
reach JSBSim's total aerodynamic moments), the airspeed bias in the log and that the evaluation's
flights stay in the envelope with every axis excited. No pipeline fit, GP, diagnosis or scoring is
run on the t6 here. One 30-s flight serves the module's tests.
"""

import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft
from truth_fits import (ENVELOPE_FLIGHTS, assert_airspeed_bias_in_log, assert_hidden_effects_in_jsbsim,
                        assert_in_envelope, assert_names_resolve, assert_rigid_body_glide, assert_servos_map_back,
                        derivative_slopes, evaluation_envelope, short_flight_fixture)
from gcs_sysid.airframe import load_airframe


t6_flight = short_flight_fixture("t6")      # fixture "t6": 30 s, light, seed 1

SLUG_FT2 = 1.3558179483314004     # kg m^2 per slug ft^2


def test_names_resolve_and_the_t6_is_used():
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, summary_label

    assert_names_resolve("t6", "t6texan2", "t66")
    assert "t6" in TUNING_AIRCRAFT and "t6" not in HELD_OUT_AIRCRAFT and summary_label("t6") == "t6"


@pytest.mark.slow
def test_truth_is_rigid_body_consistent_with_the_airframe_file(t6):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J, its Ixz
    included; in the glide every non-gravity force and moment is aerodynamic (the turboprop drives a
    "direct" thruster: no force once stopped, no propeller to windmill); the mass is the model's
    5000 lb empty plus 2 x 500 lb of fuel in two wing tanks at y = +-50 in (a symmetric pair), no
    point mass; the model's product of inertia is Ixz alone (``<ixz>`` -1000 slug ft^2 with ``negated_crossproduct_inertia``: JSBSim's
    -997.4 with the tanks, the project's Ixz = +997.4 slug ft^2)."""
    assert_rigid_body_glide(t6, mass_lb=6000)
    const, af = t6.recording.constants, load_airframe(t6.airframe)
    assert const["Ixy"] == const["Iyz"] == 0.0
    assert const["Ixz"] == pytest.approx(997.41 * SLUG_FT2, rel=1e-4) and -af.inertia[0, 2] == pytest.approx(
        const["Ixz"], rel=1e-5)


@pytest.mark.slow
def test_sign_map_gives_the_project_conventions(t6):
    """Least squares on the exact truth: Cm_delta_e, Cl_delta_a, Cn_delta_r, Cm_alpha, Cl_p < 0,
    Cn_beta > 0, and the control derivatives at the model's constants (t6texan2.xml: CmDe -1.2 x
    elevator-pos, Clda 0.29 x left-aileron-pos, so Cl_delta_a = -0.29 in the project's sign; Cldr
    0.012, Cndr -0.06; the model has no aileron yaw term and no side force from a surface, so
    Cn_delta_a = 0: the aerodynamic reference point, 0.2 in aft of and 2 in above the CG, transfers
    nothing measurable)."""
    cm, cl, cn = derivative_slopes(t6.recording)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    assert cm[2] == pytest.approx(-1.2, rel=0.02) and cl[3] == pytest.approx(-0.29, rel=0.02), (cm, cl)
    assert cl[4] == pytest.approx(0.012, rel=0.05) and cn[4] == pytest.approx(-0.06, rel=0.02), (cl, cn)
    assert abs(cn[3]) < 1e-3, cn


@pytest.mark.slow
def test_the_harness_flies_the_t6_with_its_gear_up():
    """``gear_up``: the retractable gear (5 s from down to up) is up before the log starts (the 15-s
    settling phase), so its drag (CDgear 0.03) is zero."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("t6")
    assert spec.gear_up
    fdm = load_model(spec, 1 / 200)
    _set_ic(fdm, spec, FlightConfig("t6", turbulence="none"))
    for _ in range(int(FlightConfig("t6").settle_s * 200)):
        fdm.run()
    assert fdm["gear/gear-pos-norm"] == 0.0 and fdm["aero/coefficient/CDgear"] == 0.0


@pytest.mark.slow
def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(t6):
    """The pipeline's decoder reads the t6's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (the elevator's 29.2-deg end
    makes 0.073 deg per microsecond)."""
    assert_servos_map_back(t6)


@pytest.mark.slow
def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments():
    """On the t6's XML (LIFT/DRAG/SIDE and ROLL/PITCH/YAW axes, one aileron property in the
    aerodynamics) every effect does what ``effects.py`` specifies, in JSBSim's own properties at
    the same initial condition (alpha 4 deg, sideslip 4 deg, fixed surfaces; ``run_ic`` evaluates
    the models there): each injected moment is k alpha^2, k alpha beta or k delta_a (the harness's
    delta_a) times qbar S c|b, and is exactly the change of JSBSim's total aerodynamic moment
    against the stock model; CY:scale multiplies its one SIDE function (CYb, a table in beta) by k
    (the wind-axis side force by k); the delay holds the elevator that the lift and pitching-moment
    functions read 24 frames (0.12 s at 200 Hz) behind the surface."""
    assert_hidden_effects_in_jsbsim(aircraft("t6"), 0.51, n_side=1)     # +1 = 30 x 0.017 rad trailing edge down


@pytest.mark.slow
def test_airspeed_bias_reaches_the_logged_airspeed(t6, tmp_path):
    """``bias:airspeed`` = 2 m/s of TAS in a second log of the fixture's flight: 2 sqrt(rho / rho0) m/s
    more decoded airspeed, sample by sample."""
    assert_airspeed_bias_in_log(t6, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", ENVELOPE_FLIGHTS)    # with the evaluation's pair
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """Each flight the final evaluation flies on the t6 (120 s) keeps inside its linear envelope,
    read from ``flight_envelope`` of the truth file: no knock-it-off, alpha within -6..7 deg (the
    stall is near 16 deg, CLwbh's peak at 0.28 rad), at most 6 deg of sideslip and 20 of bank
    (8 and 25 with Cl:alpha*beta = 3, whose reversed dihedral rolls it), a TAS above 1.3 x the
    stall's (about 50 m/s at 10000 ft for 83 kt EAS) and under 140 m/s, every rate and surface
    moving (also in the held-out 20 %), and still 500 m above sea level at the end of the glide."""
    limits = dict(alpha=(-6.0, 7.0), beta=(6.0, 8.0), bank=(20.0, 25.0), speed=(1.3 * 50.0, 140.0), alt_min=500.0)
    assert_in_envelope(evaluation_envelope("t6", seed, turbulence, plan, effects, tmp_path), **limits,
                       rate_std=1.5, rate_std_held=1.5)     # deg/s
