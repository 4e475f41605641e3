"""The b747 in the JSBSim harness: the tenth session's untouched aircraft (docs/jsbsim.md, "The b747"),
evaluated in its final evaluation and used since (the eleventh session's untouched aircraft is the f16,
``test_jsbsim_f16.py``, which also checks the summaries' labels). Its checks below are slow tests now,
but for the names' test.

Only the harness is checked here, on JSBSim's exact truth and its own properties: the rigid-body
consistency of the truth with the checked-in airframe file (the model's product of inertia Ixz
included), the sign map against the model's XML constants, the gear retracted by the harness, the
model's own yaw damper standing in for the harness's, the .tlog as the pipeline decodes it, every
hidden effect as JSBSim computes it (the injected moments reach JSBSim's total aerodynamic moments),
and (slow) the airspeed bias in the log and that the evaluation's flights stay
in the envelope with every axis excited. No pipeline fit, GP, diagnosis or scoring is run on the
b747 here (it was set up before its final evaluation). One 30-s flight serves the module's tests.
"""

import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft
from truth_fits import (ENVELOPE_FLIGHTS, assert_airspeed_bias_in_log, assert_hidden_effects_in_jsbsim,
                        assert_in_envelope, assert_names_resolve, assert_rigid_body_glide, assert_servos_map_back,
                        derivative_slopes, evaluation_envelope, short_flight_fixture)
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log


b747_flight = short_flight_fixture("b747")      # fixture "b747": 30 s, light, seed 1

SLUG_FT2 = 1.3558179483314004     # kg m^2 per slug ft^2


def test_names_resolve_and_the_b747_is_used():
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, summary_label

    assert_names_resolve("b747", "B747", "b74")
    assert "b747" in TUNING_AIRCRAFT and "b747" not in HELD_OUT_AIRCRAFT and summary_label("b747") == "b747"


@pytest.mark.slow
def test_truth_is_rigid_body_consistent_with_the_airframe_file(b747):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J, its Ixz
    included; in the glide every non-gravity force and moment is aerodynamic (four turbofans on
    "direct" thrusters: no force once stopped); the mass is the model's 523816 lb empty plus five
    fuel tanks of 5456.4 lb on the centre line, no point mass; the model's product of inertia is Ixz
    alone (``<ixz>`` -970000 slug ft^2 with ``negated_crossproduct_inertia``: JSBSim's
    ``inertia/ixz-slugs_ft2`` -970000, the project's Ixz = +970000 slug ft^2)."""
    assert_rigid_body_glide(b747, mass_lb=551098)
    const, af = b747.recording.constants, load_airframe(b747.airframe)
    assert const["Ixy"] == const["Iyz"] == 0.0
    assert const["Ixz"] == pytest.approx(970000 * SLUG_FT2, rel=1e-4) and -af.inertia[0, 2] == pytest.approx(
        const["Ixz"], rel=1e-5)


@pytest.mark.slow
def test_sign_map_gives_the_project_conventions(b747):
    """Least squares on the exact truth (Mach 0.53-0.54): Cm_delta_e, Cl_delta_a, Cn_delta_r,
    Cm_alpha, Cl_p < 0, Cn_beta > 0, and the derivatives at the model's constants (B747.xml: Cmde
    (-1.3 + 0.4875 Mach) x elevator-pos, with CLde 0.2 acting at the aerodynamic reference point 50 in
    aft of the CG: -1.068 at the CG; Clda (0.1 - 0.0335 Mach) x left-aileron-pos, so Cl_delta_a =
    -0.082 in the project's sign; Clb -0.1, Clp -0.4, Clr 0.15, Cldr 0.01; Cnb 0.12 plus the side
    force's arm, 0.140 at the CG; Cnr -0.15, Cndr -0.1; its Cnda function is 0 and no side force
    comes from a surface, so Cn_delta_a = 0)."""
    cm, cl, cn = derivative_slopes(b747.recording)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    assert cm[2] == pytest.approx(-1.068, rel=0.02) and cl[3] == pytest.approx(-0.082, rel=0.02), (cm, cl)
    assert cl[0] == pytest.approx(-0.1, rel=0.02) and cl[1] == pytest.approx(-0.4, rel=0.02), cl
    assert cl[4] == pytest.approx(0.01, rel=0.05) and cn[4] == pytest.approx(-0.1, rel=0.02), (cl, cn)
    assert cn[0] == pytest.approx(0.140, rel=0.02) and cn[2] == pytest.approx(-0.15, rel=0.02), cn
    assert abs(cn[3]) < 1e-3, cn


@pytest.mark.slow
def test_the_harness_flies_the_b747_with_its_gear_up_and_its_own_yaw_damper():
    """``gear_up``: the retractable gear is up before the log starts (the 15-s settling phase), so
    its drag (CDgear 0.011) is zero. The model's FCS adds 2 x ``velocities/r-aero-rad_sec`` to the
    normalised rudder (clipped to +-0.2), which the harness cannot switch off: the harness's own
    yaw damper is off (k_r = 0) and the model's moves the rudder against a yaw rate."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("b747")
    assert spec.gear_up and spec.gains[5] == 0.0
    fdm = load_model(spec, 1 / 200)
    _set_ic(fdm, spec, FlightConfig("b747", turbulence="none"))
    for _ in range(int(FlightConfig("b747").settle_s * 200)):
        fdm.run()
    assert fdm["gear/gear-pos-norm"] == 0.0 and fdm["aero/coefficient/CDgear"] == 0.0
    fdm["ic/r-rad_sec"] = 0.05
    fdm.run_ic()
    fdm.run()
    assert fdm["fcs/yaw-damper-final"] == pytest.approx(2 * fdm["velocities/r-aero-rad_sec"], rel=0.02)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.35 * fdm["fcs/yaw-damper-final"], rel=1e-9)
    assert fdm["fcs/rudder-pos-rad"] > 0.03


@pytest.mark.slow
def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(b747):
    """The pipeline's decoder reads the b747's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (the 20.05-deg ends make 0.05
    deg per microsecond)."""
    assert_servos_map_back(b747)


@pytest.mark.slow
def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments():
    """On the b747's XML (LIFT/DRAG/SIDE and ROLL/PITCH/YAW axes, one aileron property in the
    aerodynamics) every effect does what ``effects.py`` specifies, in JSBSim's own properties at
    the same initial condition (alpha 4 deg, sideslip 4 deg, fixed surfaces; ``run_ic`` evaluates
    the models there): each injected moment is k alpha^2, k alpha beta or k delta_a (the harness's
    delta_a) times qbar S c|b, and is exactly the change of JSBSim's total aerodynamic moment
    against the stock model; CY:scale multiplies its one SIDE function (CYb) by k (the wind-axis
    side force by k); the delay holds the elevator that the lift and pitching-moment functions read
    (CLde, and Cmde in its Mach table) 24 frames (0.12 s at 200 Hz) behind the surface."""
    assert_hidden_effects_in_jsbsim(aircraft("b747"), 0.175, n_side=1)     # +1 = 0.175 rad trailing edge down


@pytest.mark.slow
def test_airspeed_bias_reaches_the_logged_airspeed(b747, tmp_path):
    """``bias:airspeed`` = 2 m/s of TAS in a second log of the fixture's flight: 2 sqrt(rho / rho0) m/s
    more decoded airspeed, sample by sample."""
    assert_airspeed_bias_in_log(b747, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", ENVELOPE_FLIGHTS)    # with the evaluation's pair
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """Each flight the final evaluation flies on the b747 (120 s) keeps inside its linear envelope,
    read from ``flight_envelope`` of the truth file: no knock-it-off, alpha within -7..8 deg (the
    stall is near 13 deg, CLalpha's peak at 0.23 rad), at most 6 deg of sideslip and 15 of bank
    (both also with Cl:alpha*beta = 3, whose reversed dihedral rolls it), a TAS above 1.3 x the
    stall's (about 95 m/s at 10000 ft for 155 kt EAS) and under 230 m/s, every rate and surface
    moving (also in the held-out 20 %), and still 500 m above sea level at the end of the glide."""
    limits = dict(alpha=(-7.0, 8.0), beta=(6.0, 6.0), bank=(15.0, 15.0), speed=(1.3 * 95.0, 230.0), alt_min=500.0)
    assert_in_envelope(evaluation_envelope("b747", seed, turbulence, plan, effects, tmp_path), **limits,
                       rate_std=0.5, rate_std_held=0.4)     # deg/s


@pytest.mark.slow
def test_eval_scripts_fly_the_b747_without_scoring_it(tmp_path, capsys, monkeypatch):
    """``--aircraft B747`` resolves to ``b747`` in both scripts; with ``--fly-only`` they fly into
    ``--work`` / ``--out``, reuse the flights on a second run and score nothing (the b747 is used
    now: no untouched-aircraft note)."""
    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose

    monkeypatch.setattr(eval_jsbsim_diagnose, "DURATION_S", 2.0)
    runs = ((eval_jsbsim.main, ["--turbulence", "light", "--duration", "2", "--work", str(tmp_path / "f")], 1, 1),
            (eval_jsbsim_diagnose.main, ["--clean-seeds", "--pairs", "--effects", "delay:delta_e",
                                         "--out", str(tmp_path / "d")], -3, 3))      # reference + 2 sizes
    for main, extra, column, n in runs:
        argv = ["--aircraft", "B747", "--seeds", "1", *extra, "--fly-only"]
        assert main(argv) == 0 and main(argv) == 0
        cap = capsys.readouterr()
        assert [ln.split()[column] for ln in cap.out.splitlines()] == ["flown"] * n + ["reused"] * n, cap.out
        assert "b747 is the untouched aircraft" not in cap.err
    assert read_log(tmp_path / "f" / "b747-light-s1-ahrs.tlog").streams["servo"].t.size > 50
    assert not (tmp_path / "d" / "results.jsonl").exists() or not (tmp_path / "d" / "results.jsonl").read_text()
