"""The J3Cub in the JSBSim harness: the sixth session's untouched aircraft of issues 8 and 9
(docs/jsbsim.md); evaluated since, it now counts as used (the t6 is the untouched one).

Only the harness is checked here, on JSBSim's exact truth: the rigid-body consistency of the truth
with the checked-in airframe file, the sign map, the .tlog as the pipeline decodes it, the XML
edits of every hidden effect, and (slow) that the evaluation's flights stay in the envelope with
enough excitation on every axis. No pipeline fit, GP or diagnosis is run on the J3Cub in the
test suite. The shared checks are in ``truth_fits.py`` and ``static_checks.py``
(also used by ``test_jsbsim_roster.py``).
"""

from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft, canonical_name, fly, make_flight
from benchmarks.jsbsim_harness.effects import EFFECTS, Effect, _write_model
from static_checks import delay_trace, effect_state, injected_moment
from truth_fits import (EVALUATION_FLIGHTS, decoded_servo_errors, derivative_slopes, non_aero_residual,
                        rigid_body_residual)
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log

FAST = FlightConfig("j3cub", duration_s=30.0, turbulence="calm", seed=1)


@pytest.fixture(scope="module")
def cub(tmp_path_factory):
    """A 30-s J3Cub flight ("calm" turbulence, the harness's light until the fifteenth session; seed 1,
    AHRS AOA_SSA): FlightFiles."""
    return make_flight(FAST, tmp_path_factory.mktemp("j3cub"))


def test_names_resolve_to_the_harness_name():
    assert canonical_name("J3Cub") == canonical_name("j3cub") == canonical_name(" J3CUB ") == "j3cub"
    assert canonical_name("SGS") == "sgs" and canonical_name("pa28") == "pa28"
    with pytest.raises(KeyError, match="unknown aircraft 'j3' .*j3cub"):
        canonical_name("j3")


def test_truth_is_rigid_body_consistent_with_the_airframe_file(cub):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J (the pilot's
    point mass gives the J3Cub an Ixz), and in the glide every non-gravity force is aerodynamic
    (the stopped propeller makes no thrust)."""
    tr, af = cub.recording.truth, load_airframe(cub.airframe)
    assert af.inertia[0, 2] != 0.0
    rel = rigid_body_residual(tr, af.inertia)
    assert (rel < 2e-3).all(), rel
    assert non_aero_residual(tr) < 1e-9
    assert af.mass == pytest.approx(cub.recording.constants["mass"], rel=1e-5)


def test_sign_map_gives_the_project_conventions(cub):
    """Least squares on the exact truth: Cm_delta_e, Cl_delta_a, Cn_delta_r, Cm_alpha, Cl_p < 0,
    Cn_beta > 0, and the lateral control derivatives at the model's own constants (Du 2011 via
    J3Cub.xml: Cl_delta_a -0.3498 in the project's sign, Cn_delta_r -0.0565). (Cm_delta_e comes
    out at -0.96 to -1.0 against the table's -1.2004, also without turbulence: the model's
    Cm_alpha_dot term (-7.59) is no regressor here and moves with the elevator; with alpha_dot
    added it is -1.15. Only its sign is asserted.)"""
    cm, cl, cn = derivative_slopes(cub.recording)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    assert cl[3] == pytest.approx(-0.3498, rel=0.05) and cn[4] == pytest.approx(-0.0565, rel=0.05)


def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(cub):
    """The pipeline's decoder reads the J3Cub's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (the elevator's +-8 deg make
    0.02 deg per microsecond)."""
    empty, errors = decoded_servo_errors(cub)
    assert empty == []
    for k, (err, std) in errors.items():
        assert err < np.radians(0.1) and std > np.radians(0.5), k      # maps back; every surface moves


def test_every_hidden_effect_edits_the_j3cub_as_specified():
    """The J3Cub's XML (Aeromatic layout: qbar and S as separate factors, one aileron property in the
    aerodynamics, its surfaces in a system file and an empty <flight_control>) takes every effect:
    the injected moments are k alpha^2, k alpha beta, k delta_a (the harness's delta_a) times
    qbar S c|b to rounding; CY:scale scales the wind-axis side force; the elevator delay holds the
    aerodynamics' elevator 24 frames (0.12 s at 200 Hz) behind the surface."""
    assert set(EFFECTS) >= {"Cm:alpha^2", "Cl:alpha*beta", "Cn:delta_a", "CY:scale", "delay:delta_e"}
    spec = aircraft("j3cub")
    for name, k in (("Cm:alpha^2", -8.0), ("Cl:alpha*beta", 3.0), ("Cn:delta_a", -0.06)):
        got, want, _ = injected_moment(spec, name, k)
        assert abs(want) > 1e-3
        assert got == pytest.approx(want, rel=1e-9), name
    stock, scaled = effect_state(spec, []), effect_state(spec, [Effect("CY:scale", 1.6)])
    assert scaled["forces/fwy-aero-lbs"] / stock["forces/fwy-aero-lbs"] == pytest.approx(1.6, rel=0.02)
    pos, delayed = delay_trace(spec, 0.12)
    assert pos[0] == pytest.approx(0.07) and np.all(delayed[:23] == 0.0) and delayed[23:] == pytest.approx(0.07)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", EVALUATION_FLIGHTS)
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """The J3Cub flies the evaluation's plans as a test pilot would: no knock-it-off, alpha far
    below the stall (about 13 deg), sideslip under 12 deg, bank under 20 deg, airspeed at least
    1.15 times the stall and far below the never-exceed speed, every axis excited (rates and surfaces), and the glide
    loses height. The alpha ceiling (7.5 deg) and the sideslip limit (12 deg) were re-derived in the fifteenth
    session (turb15) from the flights in MIL-F-8785C light / moderate turbulence (severity 3 / 4): the seed-100
    sweep reaches alpha 6.3 deg, the moderate standard flight (seed 2) 10.1 deg of sideslip (calm-air limits 6
    and 10; docs/jsbsim.md, J3Cub)."""
    spec = aircraft("j3cub")
    cfg = FlightConfig("j3cub", duration_s=120.0, turbulence=turbulence, seed=seed, plan=plan)
    rec = fly(cfg, _write_model(spec, [Effect(n, v) for n, v in effects], tmp_path) if effects else None)
    tr, d = rec.truth, np.degrees
    assert rec.meta["aborts"] == []
    assert d(tr["alpha"]).max() < 7.5 and d(tr["alpha"]).min() > -5.0
    assert d(np.abs(tr["beta"])).max() < 12.0 and d(np.abs(tr["phi"])).max() < 20.0
    # the model's power-off stall: about 31 kt EAS (967 lb, CL_max 1.62), 17.7 m/s TAS at 6000 ft;
    # never-exceed speed of the J-3: 106 kt (54 m/s)
    assert 1.15 * 17.7 < tr["V"].min() and tr["V"].max() < 45.0
    assert min(d(tr[k]).std() for k in ("p", "q", "r")) > 2.0                  # deg/s
    assert min(d(tr[k]).std() for k in ("delta_e", "delta_a", "delta_r")) > 1.0  # deg
    held = rec.t >= 0.8 * cfg.duration_s                                        # the replay's held-out segment
    assert min(d(tr[k][held]).std() for k in ("p", "q", "r")) > 2.0
    assert tr["alt"][0] - tr["alt"][-1] > 100.0


def test_eval_scripts_take_the_j3cub_and_reuse_its_flights(tmp_path, capsys, monkeypatch):
    """``--aircraft J3Cub`` resolves to ``j3cub``; ``--fly-only`` flies into ``--work`` / ``--out``
    and a second run reuses the files (same configuration and harness fingerprint), while a
    file from another harness is flown again. No scoring is run."""
    import json

    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose

    args = ["--aircraft", "J3Cub", "--seeds", "1", "--turbulence", "light", "--duration", "2",
            "--work", str(tmp_path / "f"), "--fly-only"]
    assert eval_jsbsim.main(args) == 0 and eval_jsbsim.main(args) == 0
    out = capsys.readouterr().out.splitlines()
    assert [ln.split()[1] for ln in out] == ["flown", "reused"] and "j3cub-light-s1-ahrs.tlog" in out[0]
    assert read_log(tmp_path / "f" / "j3cub-light-s1-ahrs.tlog").streams["servo"].t.size > 50

    monkeypatch.setattr(eval_jsbsim_diagnose, "DURATION_S", 2.0)
    diag = ["--aircraft", "j3cub", "--seeds", "1", "--clean-seeds", "--pairs", "--effects", "bias:airspeed",
            "--out", str(tmp_path / "d"), "--fly-only"]
    assert eval_jsbsim_diagnose.main(diag) == 0
    first = capsys.readouterr().out.splitlines()
    assert len(first) == 3 and all(ln.split()[-3] == "flown" for ln in first), first    # reference + 2 sizes
    doc = tmp_path / "d" / "j3cub-s1-bias_airspeed=1-sweep-pa-pt-effects.json"
    stale = json.loads(doc.read_text()) | {"harness": "0" * 16}
    doc.write_text(json.dumps(stale))
    flown = []
    monkeypatch.setattr(eval_jsbsim_diagnose, "make_effect_flight",
                        lambda cfg, effs, out, stem=None: flown.append(stem) or SimpleNamespace(recording="flown"))
    assert eval_jsbsim_diagnose.main(diag) == 0
    second = capsys.readouterr().out.splitlines()
    assert [ln.split()[-3] for ln in second] == ["reused", "reused", "flown"], second
    assert flown == ["j3cub-s1-bias_airspeed=1-sweep-pa-pt"]                # only the stale one is flown again
    assert not (tmp_path / "d" / "results.jsonl").exists() or not (tmp_path / "d" / "results.jsonl").read_text()


def test_flight_envelope_reads_the_truth_file(cub):
    """The envelope summary of the fast flight agrees with its recording: ranges, excitation on
    every axis, no knock-it-off, a glide that loses height."""
    from benchmarks.jsbsim_harness.envelope import flight_envelope, format_envelope

    e, tr = flight_envelope(cub.truth), cub.recording.truth
    assert e["alpha"] == pytest.approx((np.degrees(tr["alpha"]).min(), np.degrees(tr["alpha"]).max()))
    assert e["aborts"] == [] and e["sink_mps"] > 0.5 and min(e["rate_std"]) > 1.0 and min(e["surface_std"]) > 0.5
    assert e["alpha_p"][0] >= e["alpha"][0] and e["V"][0] > 20.0
    assert "aborts 0" in format_envelope("j3cub", e)

