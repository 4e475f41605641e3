"""The c182 in the JSBSim harness: the untouched aircraft of issues 8 and 9 (docs/jsbsim.md, "The c182").

Only the harness is checked here, on JSBSim's exact truth and its own properties: the rigid-body
consistency of the truth with the checked-in airframe file, the sign map against the model's XML
constants, the .tlog as the pipeline decodes it, every hidden effect as JSBSim computes it (the
injected moments reach JSBSim's total aerodynamic moments), the summaries' label, and (slow) that
the evaluation's flights stay in the envelope with every axis excited. No pipeline fit, GP,
diagnosis or scoring is run on the c182 here: its first evaluation is the final one, after the merge.
"""

import copy
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft, canonical_name, make_flight, write_log
from benchmarks.jsbsim_harness.effects import EFFECTS, RHO0, Effect, _bias_airspeed, inject_xml, make_effect_flight, \
    stock_model_dir
from benchmarks.jsbsim_harness.envelope import flight_envelope
from benchmarks.jsbsim_harness.sensors import make_sensors
from truth_fits import (EVALUATION_FLIGHTS, decoded_servo_errors, delay_trace, derivative_slopes, effect_state,
                        injected_moment, non_aero_residual, rigid_body_residual)
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log

FAST = FlightConfig("c182", duration_s=30.0, turbulence="light", seed=1)
LB = 0.45359237          # kg per lb


@pytest.fixture(scope="module")
def c182(tmp_path_factory):
    """A 30-s c182 flight (light turbulence, seed 1, AHRS AOA_SSA): FlightFiles."""
    return make_flight(FAST, tmp_path_factory.mktemp("c182"))


def test_names_resolve_and_only_the_c182_is_untouched():
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, UNTOUCHED_AIRCRAFT

    assert canonical_name("C182") == canonical_name(" c182 ") == "c182"
    assert UNTOUCHED_AIRCRAFT == HELD_OUT_AIRCRAFT == ("c182",)
    assert {"pa28", "j3cub"} <= set(TUNING_AIRCRAFT) and "c182" not in TUNING_AIRCRAFT
    with pytest.raises(KeyError, match="unknown aircraft 'c18' .*c182"):
        canonical_name("c18")


def test_truth_is_rigid_body_consistent_with_the_airframe_file(c182):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J; in the glide
    every non-gravity force and moment is aerodynamic (engine stopped); the mass is the model's
    1700 lb empty plus 400 lb of fuel, its one point mass (a 180 lb pilot at y = -14 in) emptied
    by the harness, so no product of inertia but Ixz remains."""
    tr, af, const = c182.recording.truth, load_airframe(c182.airframe), c182.recording.constants
    rel = rigid_body_residual(tr, af.inertia)
    assert (rel < 2e-3).all(), rel
    assert non_aero_residual(tr) < 1e-9
    assert af.mass == pytest.approx(const["mass"], rel=1e-5) and const["mass"] == pytest.approx(2100 * LB, rel=1e-6)
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
    empty, errors = decoded_servo_errors(c182)
    assert empty == []
    for k, (err, std) in errors.items():
        assert err < np.radians(0.1) and std > np.radians(0.5), k      # maps back; every surface moves


def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments():
    """On the c182's XML (LIFT/DRAG/SIDE and ROLL/PITCH/YAW axes, qbar and S as separate factors,
    one aileron property in the aerodynamics) every effect does what ``effects.py`` specifies, in
    JSBSim's own properties at the same initial condition (alpha 4 deg, sideslip 4 deg, fixed
    surfaces; ``run_ic`` evaluates the models there): each injected moment is k alpha^2, k alpha beta or k delta_a (the
    harness's delta_a) times qbar S c|b, and is exactly the change of JSBSim's total aerodynamic
    moment against the stock model; CY:scale multiplies the sum of the SIDE functions by k (the
    wind-axis side force by k); the delay holds the elevator that the lift and
    pitching-moment functions read 24 frames (0.12 s at 200 Hz) behind the surface."""
    assert set(EFFECTS) >= {"Cm:alpha^2", "Cl:alpha*beta", "Cn:delta_a", "CY:scale", "delay:delta_e"}
    spec = aircraft("c182")
    for name, k in (("Cm:alpha^2", -8.0), ("Cl:alpha*beta", 3.0), ("Cn:delta_a", -0.06)):
        got, want, change = injected_moment(spec, name, k, n=0, alpha_deg=4.0)
        assert abs(want) > 10.0, (name, want)                     # lbf ft
        assert got == pytest.approx(want, rel=1e-9) and change == pytest.approx(got, rel=1e-9), (name, got, change)
    root = ET.parse(stock_model_dir(spec) / "c182.xml").getroot()
    side = [f.get("name") for ax in root.iter("axis") if ax.get("name") == "SIDE" for f in ax.findall("function")]
    assert len(side) == 5
    stock, scaled = (effect_state(spec, e, n=0, alpha_deg=4.0) for e in ([], [Effect("CY:scale", 1.6)]))
    total = lambda fdm: sum(fdm[n] for n in side)   # noqa: E731
    assert total(scaled) == pytest.approx(1.6 * total(stock), rel=1e-9) and abs(total(stock)) > 10.0
    assert scaled["forces/fwy-aero-lbs"] / stock["forces/fwy-aero-lbs"] == pytest.approx(1.6, rel=1e-9)
    pos, delayed = delay_trace(spec, 0.12)
    assert pos[0] == pytest.approx(0.5 * np.radians(23.0), rel=1e-3)          # +1 = 23 deg trailing edge down
    assert np.all(delayed[:23] == 0.0) and delayed[23:] == pytest.approx(pos[0])
    edited = inject_xml(copy.deepcopy(root), spec, [Effect("delay:delta_e", 0.12)])
    reads = lambda r, p: sum((e.text or "").strip() == p for e in r.find("aerodynamics").iter("property"))  # noqa: E731
    assert reads(root, "fcs/elevator-pos-rad") == 2 and reads(edited, "fcs/elevator-pos-rad") == 0
    assert reads(edited, "fcs/elevator-pos-delayed-rad") == 2


@pytest.mark.slow
def test_airspeed_bias_reaches_the_logged_airspeed(c182, tmp_path):
    """``bias:airspeed`` = 2 m/s: the decoded airspeed (EAS, from SCALED_PRESSURE) of the biased log
    exceeds the clean log's (the fixture's, same seed, same sensor noise) by 2 m/s of TAS times
    sqrt(rho / rho0), sample by sample."""
    rec = c182.recording
    write_log(rec, tmp_path / "biased.tlog", sensors=_bias_airspeed(make_sensors(rec, "ahrs"), rec, 2.0))
    a, b = (read_log(p).streams["airspeed"] for p in (c182.tlog, tmp_path / "biased.tlog"))
    want = 2.0 * np.sqrt(np.interp(a.t, rec.t, rec.truth["rho"]) / RHO0)
    np.testing.assert_allclose(b.fields["eas"] - a.fields["eas"], want, atol=0.01)


def test_summaries_mark_the_c182_untouched_and_the_others_used(tmp_path):
    """The markdown summaries of eval_jsbsim and eval_jsbsim_diagnose label c182 "(untouched)" and
    no other aircraft (synthetic rows: no c182 result exists before the final evaluation)."""
    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose
    from gcs_sysid.aero.table import COEFFICIENTS

    def row(ac):
        errs = {k: {c: 10.0 for c in COEFFICIENTS} for k in ("meas", "gp", "true", "ls")}
        return {"aircraft": ac, "turbulence": "light", "aoa": "ahrs", "seed": 1, **errs, "cov_gp": 90.0,
                "cov_true": 90.0, "alpha_deg": 0.1, "beta_deg": 0.1, "alpha_rms_deg": 1.0, "beta_rms_deg": 1.0}

    acs = ("c172x", "pa28", "j3cub", "c182")
    p = tmp_path / "r.jsonl"
    p.write_text("".join(json.dumps(row(ac)) + "\n" for ac in acs))
    lines = eval_jsbsim.summarize([str(p)]).splitlines()
    assert any(ln.startswith("| c182 (untouched) | light") for ln in lines)
    for ac in acs[:3]:
        assert any(ln.startswith(f"| {ac} | light") for ln in lines), ac
    assert not any("(held out)" in ln for ln in lines)
    d = tmp_path / "d.jsonl"
    d.write_text("".join(json.dumps({"aircraft": ac, "seed": 11, "effects": [], "score": {"ok": True}}) + "\n"
                         for ac in acs))
    lines = eval_jsbsim_diagnose.summarize([str(d)]).splitlines()
    assert any(ln.startswith("| c182 (untouched) | clean |") for ln in lines)
    assert any(ln.startswith("| j3cub | clean |") for ln in lines)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", EVALUATION_FLIGHTS + [
    (1, "light", "sweep", [("Cm:alpha^2", -8.0), ("Cn:delta_a", -0.06)]),   # the evaluation's pair
])
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """The c182 flies the evaluation's plans as a test pilot would (``flight_envelope`` of the truth
    file): no knock-it-off; alpha far below the stall (about 16 deg: CLalpha's peak at 0.28 rad);
    sideslip under 8 deg (13 deg with the reversed dihedral of Cl:alpha*beta = 3) and bank under
    15 deg (25); airspeed at least 1.15 times the stall (49 kt EAS, 27.8 m/s TAS at 6000 ft) and
    far below the C182's never-exceed 175 kt; every axis excited (rates, also in the held-out
    last 20 %, and surfaces); the glide loses height."""
    cfg = FlightConfig("c182", duration_s=120.0, turbulence=turbulence, seed=seed, plan=plan)
    files = (make_effect_flight(cfg, [Effect(n, v) for n, v in effects], tmp_path) if effects
             else make_flight(cfg, tmp_path))
    e = flight_envelope(files.truth)
    wild = any(n == "Cl:alpha*beta" for n, _ in effects)
    assert e["aborts"] == []
    assert -4.0 < e["alpha"][0] and e["alpha"][1] < 8.0, e["alpha"]
    assert max(map(abs, e["beta"])) < (13.0 if wild else 8.0) and e["bank_max"] < (25.0 if wild else 15.0), e
    assert 1.15 * 27.8 < e["V"][0] and e["V"][1] < 70.0, e["V"]
    assert min(e["rate_std"]) > 1.8 and min(e["rate_std_held"]) > 1.5, e      # deg/s (least measured: 2.0, 1.8)
    assert min(e["surface_std"]) > 1.0 and e["sink_mps"] > 3.0, e


@pytest.mark.slow
def test_eval_scripts_fly_the_c182_without_scoring_it(tmp_path, capsys, monkeypatch):
    """``--aircraft C182`` resolves to ``c182`` in both scripts; with ``--fly-only`` they fly into
    ``--work`` / ``--out``, say that the c182 is the untouched aircraft, reuse the flights on a
    second run and score nothing."""
    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose

    monkeypatch.setattr(eval_jsbsim_diagnose, "DURATION_S", 2.0)
    runs = ((eval_jsbsim.main, ["--turbulence", "light", "--duration", "2", "--work", str(tmp_path / "f")], 1, 1),
            (eval_jsbsim_diagnose.main, ["--clean-seeds", "--pairs", "--effects", "delay:delta_e",
                                         "--out", str(tmp_path / "d")], -3, 3))      # reference + 2 sizes
    for main, extra, column, n in runs:
        argv = ["--aircraft", "C182", "--seeds", "1", *extra, "--fly-only"]
        assert main(argv) == 0 and main(argv) == 0
        cap = capsys.readouterr()
        assert [ln.split()[column] for ln in cap.out.splitlines()] == ["flown"] * n + ["reused"] * n, cap.out
        assert "c182 is the untouched aircraft" in cap.err
    assert read_log(tmp_path / "f" / "c182-light-s1-ahrs.tlog").streams["servo"].t.size > 50
    assert not (tmp_path / "d" / "results.jsonl").exists() or not (tmp_path / "d" / "results.jsonl").read_text()
