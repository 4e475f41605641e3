"""The f16 in the JSBSim harness: the eleventh session's untouched aircraft (docs/jsbsim.md, "The f16").

The F-16 is flown as a derived model (``benchmarks/jsbsim_harness/derived.py``): the wheel's
``f16.xml`` with its fly-by-wire replaced by a direct map of the commands to the surfaces and its
flaps fixed. Only the harness and the derivation are checked here, on the XML and JSBSim's own
properties and exact truth: the derived XML is the stock one but for the flight control and the
elevator alias, its hash is the one in the spec (so in the fingerprint), the commands reach the
surfaces the aerodynamics read and nothing else moves them, the aerodynamics read through the alias
give the stock tables' forces and moments, it is statically stable about the CG, the summaries'
label; and (slow) the rigid-body consistency of the truth with the airframe file, the sign map, the
gear, the .tlog, every hidden effect in JSBSim, the airspeed bias, the evaluation's flights in the
envelope, the eval scripts' ``--fly-only``. No pipeline fit, GP, diagnosis or scoring is run on the
f16 here: its first evaluation is the final one, after the merge.
"""

import json
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft
from benchmarks.jsbsim_harness.derived import ELEVATOR_ALIAS, derived_sha, derived_xml
from truth_fits import (ENVELOPE_FLIGHTS, assert_airspeed_bias_in_log, assert_hidden_effects_in_jsbsim,
                        assert_in_envelope, assert_names_resolve, assert_rigid_body_glide, assert_servos_map_back,
                        derivative_slopes, evaluation_envelope, short_flight_fixture)
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log


f16_flight = short_flight_fixture("f16")      # fixture "f16": 30 s, light, seed 1 (slow tests only)

SLUG_FT2 = 1.3558179483314004     # kg m^2 per slug ft^2


def _state(spec, aircraft_path=None, alpha_deg=4.0, beta_deg=4.0, cmds=(0.3, -0.4, 0.2)):
    """JSBSim at the harness's initial condition with the given alpha, sideslip and fixed commands,
    after ``run_ic`` (models evaluated, nothing integrated)."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    fdm = load_model(spec, 1 / 200, 0, aircraft_path)
    _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
    fdm["ic/alpha-deg"], fdm["ic/beta-deg"] = alpha_deg, beta_deg
    fdm["fcs/elevator-cmd-norm"], fdm["fcs/aileron-cmd-norm"], fdm["fcs/rudder-cmd-norm"] = cmds
    fdm.run_ic()
    return fdm


def test_names_resolve_and_only_the_f16_is_untouched():
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, UNTOUCHED_AIRCRAFT

    assert_names_resolve("f16", "f16_direct", "f15x")
    assert UNTOUCHED_AIRCRAFT == HELD_OUT_AIRCRAFT == ("f16",)
    assert {"pa28", "j3cub", "c182", "t37", "t6", "b747"} <= set(TUNING_AIRCRAFT) and "f16" not in TUNING_AIRCRAFT


def test_the_derived_model_is_the_wheels_f16_with_direct_surfaces():
    """The derived XML (hash in the spec's notes, so in the f16's fingerprint; the installed copy
    is it) keeps every element of the stock f16.xml but the flight control, with the aerodynamics
    equal once the elevator alias is undone; its flight control reads only the three commands, the
    gear and the throttle commands (no sensor, no law). In JSBSim, at alpha 4 deg, sideslip 4 deg
    and commands (0.3, -0.4, 0.2): the surfaces are the commands times 0.436, 0.375 and 0.524 rad,
    the flaps 0; and every force and moment equals that of the same model whose tables read
    ``fcs/elevator-pos-rad`` directly (the alias changes no number)."""
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    spec = aircraft("f16")
    xml = derived_xml("f16_direct")
    assert f"XML sha256 {derived_sha('f16_direct')}" in spec.notes
    assert (stock_model_dir(spec) / "f16_direct.xml").read_bytes() == xml
    derived = ET.fromstring(xml)
    stock = ET.parse(stock_model_dir(aircraft("f16")).parent / "f16" / "f16.xml").getroot()
    aero = derived.find("aerodynamics")
    alias = aero.find("function")
    assert alias.get("name") == ELEVATOR_ALIAS and alias.find("property").text == "fcs/elevator-pos-rad"
    aero.remove(alias)
    for iv in aero.iter("independentVar"):
        if iv.text == ELEVATOR_ALIAS:
            iv.text = "fcs/elevator-pos-rad"
    canon = lambda e: ET.tostring(e, encoding="unicode").replace(" ", "").replace("\n", "")   # noqa: E731
    assert [c.tag for c in derived] == [c.tag for c in stock]
    for d, s in zip(derived, stock):
        assert d.tag == "flight_control" or canon(d) == canon(s), d.tag
    inputs = {i.text.strip().lstrip("-") for i in derived.find("flight_control").iter("input")}
    assert inputs == {"fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm", "gear/gear-cmd-norm",
                      "fcs/steer-cmd-norm", "fcs/throttle-cmd-norm"}, inputs

    fdm = _state(spec)
    assert fdm["fcs/elevator-pos-rad"] == pytest.approx(0.3 * 0.436, rel=1e-12)
    assert fdm["fcs/aileron-pos-rad"] == pytest.approx(-0.4 * 0.375, rel=1e-12)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.2 * 0.524, rel=1e-12)
    assert fdm["fcs/lef-pos-rad"] == fdm["fcs/flaperon-mix-rad"] == fdm["fcs/speedbrake-pos-rad"] == 0.0
    assert fdm[ELEVATOR_ALIAS] == fdm["fcs/elevator-pos-rad"]
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copytree(stock_model_dir(spec), Path(tmp) / "f16_direct")     # its Systems/ too
        root = ET.fromstring(xml)
        a = root.find("aerodynamics")
        a.remove(a.find("function"))
        for iv in a.iter("independentVar"):
            if iv.text == ELEVATOR_ALIAS:
                iv.text = "fcs/elevator-pos-rad"
        ET.ElementTree(root).write(Path(tmp) / "f16_direct" / "f16_direct.xml")
        direct = _state(spec, tmp)
        for k in ("forces/fbx-aero-lbs", "forces/fby-aero-lbs", "forces/fbz-aero-lbs", "moments/l-aero-lbsft",
                  "moments/m-aero-lbsft", "moments/n-aero-lbsft"):
            assert fdm[k] == pytest.approx(direct[k], rel=1e-12, abs=1e-9), k
            assert abs(fdm[k]) > 10.0, k


def test_the_f16_is_statically_stable_about_its_cg():
    """JSBSim's pitching moment about the CG at fixed surfaces (``run_ic``, the harness's initial
    condition, sideslip 0) falls with alpha: Cm_alpha -0.026 per rad between 0 and 4 deg and -0.079
    between 4 and 8 deg (relaxed: the CG is 2.4 in ahead of the reference point), and the elevator
    is powerful (Cm per rad of elevator -0.54)."""
    spec = aircraft("f16")

    def cm(alpha, de=0.0):
        fdm = _state(spec, alpha_deg=alpha, beta_deg=0.0, cmds=(de, 0.0, 0.0))
        return fdm["moments/m-aero-lbsft"] / (fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm["metrics/cbarw-ft"])

    c0, c4, c8 = cm(0.0), cm(4.0), cm(8.0)
    slope = lambda a, b: (b - a) / np.radians(4.0)   # noqa: E731
    assert slope(c0, c4) == pytest.approx(-0.026, abs=0.005) and slope(c4, c8) == pytest.approx(-0.079, abs=0.005)
    assert (cm(4.0, 0.2 / 0.436) - c4) / 0.2 == pytest.approx(-0.54, abs=0.02)


def test_summaries_mark_the_f16_untouched_and_the_others_used(tmp_path):
    """The markdown summaries of eval_jsbsim and eval_jsbsim_diagnose label f16 "(untouched)" and
    no other aircraft, the b747 included (synthetic rows: no f16 result exists before the final
    evaluation)."""
    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose
    from gcs_sysid.aero.table import COEFFICIENTS

    def row(ac):
        errs = {k: {c: 10.0 for c in COEFFICIENTS} for k in ("meas", "gp", "true", "ls")}
        return {"aircraft": ac, "turbulence": "light", "aoa": "ahrs", "seed": 1, **errs, "cov_gp": 90.0,
                "cov_true": 90.0, "alpha_deg": 0.1, "beta_deg": 0.1, "alpha_rms_deg": 1.0, "beta_rms_deg": 1.0}

    acs = ("c172x", "pa28", "j3cub", "c182", "t37", "t6", "b747", "f16")
    p = tmp_path / "r.jsonl"
    p.write_text("".join(json.dumps(row(ac)) + "\n" for ac in acs))
    lines = eval_jsbsim.summarize([str(p)]).splitlines()
    assert any(ln.startswith("| f16 (untouched) | light") for ln in lines)
    for ac in acs[:7]:
        assert any(ln.startswith(f"| {ac} | light") for ln in lines), ac
    assert not any("(held out)" in ln for ln in lines)
    d = tmp_path / "d.jsonl"
    d.write_text("".join(json.dumps({"aircraft": ac, "seed": 11, "effects": [], "score": {"ok": True}}) + "\n"
                         for ac in acs))
    lines = eval_jsbsim_diagnose.summarize([str(d)]).splitlines()
    assert any(ln.startswith("| f16 (untouched) | clean |") for ln in lines)
    assert any(ln.startswith("| b747 | clean |") for ln in lines)


@pytest.mark.slow
def test_truth_is_rigid_body_consistent_with_the_airframe_file(f16):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J, its Ixz
    included; in the glide every non-gravity force and moment is aerodynamic (the turbofan on a
    "direct" thruster: no force once stopped; the hook and pushback forces zero); the mass is the
    model's 17400 lb empty, the 230 lb pilot on the centre line (kept: no off-centre point mass) and
    2 x 1500 lb of fuel in two wing tanks at y = +-65 in (a symmetric pair); the product of inertia
    is Ixz alone."""
    assert_rigid_body_glide(f16, mass_lb=20630)
    const, af = f16.recording.constants, load_airframe(f16.airframe)
    assert const["Ixy"] == const["Iyz"] == 0.0 and const["Ixz"] > 0.0
    assert -af.inertia[0, 2] == pytest.approx(const["Ixz"], rel=1e-5)


@pytest.mark.slow
def test_sign_map_gives_the_project_conventions(f16):
    """Least squares on the exact truth (Mach 0.5, alpha 0-6 deg): Cm_delta_e, Cl_delta_a,
    Cn_delta_r, Cm_alpha, Cl_p < 0, Cn_beta > 0, and the control derivatives near the model's tables
    (f16.xml: Clda 0.051-0.052 x aileron-pos at these alphas, so Cl_delta_a = -0.052 in the
    project's sign; Cnda +0.009-0.011 x aileron-pos, Cn_delta_a = -0.010; Cndr -0.045; CmDh about
    -0.53 per rad of elevator near 0)."""
    cm, cl, cn = derivative_slopes(f16.recording)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    assert cl[3] == pytest.approx(-0.052, rel=0.1) and cn[4] == pytest.approx(-0.045, rel=0.1), (cl, cn)
    assert cn[3] == pytest.approx(-0.010, abs=0.004) and cm[2] == pytest.approx(-0.53, rel=0.1), (cn, cm)


@pytest.mark.slow
def test_the_harness_flies_the_f16_with_its_gear_up():
    """``gear_up``: the retractable gear (5 s from down to up, the stock channel) is up before the
    log starts, so its drag (CDgear 0.027) is zero."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("f16")
    assert spec.gear_up
    fdm = load_model(spec, 1 / 200)
    _set_ic(fdm, spec, FlightConfig("f16", turbulence="none"))
    for _ in range(int(FlightConfig("f16").settle_s * 200)):
        fdm.run()
    assert fdm["gear/gear-pos-norm"] == 0.0 and fdm["aero/coefficient/CDgear"] == 0.0


@pytest.mark.slow
def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(f16):
    """The pipeline's decoder reads the f16's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (the elevator's 24.98-deg end
    makes 0.062 deg per microsecond)."""
    assert_servos_map_back(f16)


@pytest.mark.slow
def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments():
    """On the derived f16's XML (LIFT/DRAG/SIDE and ROLL/PITCH/YAW axes, one aileron property in the
    aerodynamics, six SIDE functions: CYb, CYb_M, CYDa, CYdr, CYp, CYr) every effect does what
    ``effects.py`` specifies in JSBSim's own properties (``assert_hidden_effects_in_jsbsim``); the
    delay redirects the one aerodynamic read of the elevator, the alias that the three elevator
    tables (CDdHT, CLDh, CmDh) look up."""
    assert_hidden_effects_in_jsbsim(aircraft("f16"), 0.436, n_side=6, n_elevator_reads=1)


@pytest.mark.slow
def test_airspeed_bias_reaches_the_logged_airspeed(f16, tmp_path):
    """``bias:airspeed`` = 2 m/s of TAS in a second log of the fixture's flight: 2 sqrt(rho / rho0) m/s
    more decoded airspeed, sample by sample."""
    assert_airspeed_bias_in_log(f16, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed,turbulence,plan,effects", ENVELOPE_FLIGHTS)    # with the evaluation's pair
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(tmp_path, seed, turbulence, plan, effects):
    """Each flight the final evaluation flies on the f16 (120 s) keeps inside its envelope, read from
    ``flight_envelope`` of the truth file: no knock-it-off, alpha within -6..11 deg (the tables' rows
    every 5 deg; CL peaks near 35 deg), at most 6 deg of sideslip and 15 of bank (25 with
    Cl:alpha*beta = 3, whose reversed dihedral rolls it), a TAS above 110 m/s (1.5 x the
    model's stall at 15000 ft) and under 200 m/s (Mach 0.6 at the lowest altitude flown, where the
    Mach tables start), every rate and surface moving (also in the held-out 20 %), and still 1000 m
    above sea level at the end of the glide."""
    limits = dict(alpha=(-6.0, 11.0), beta=(6.0, 6.0), bank=(15.0, 25.0), speed=(110.0, 200.0), alt_min=1000.0)
    assert_in_envelope(evaluation_envelope("f16", seed, turbulence, plan, effects, tmp_path), **limits,
                       rate_std=1.0, rate_std_held=1.0)     # deg/s


@pytest.mark.slow
def test_eval_scripts_fly_the_f16_without_scoring_it(tmp_path, capsys, monkeypatch):
    """``--aircraft f16_direct`` resolves to ``f16`` in both scripts; with ``--fly-only`` they fly
    into ``--work`` / ``--out``, say that the f16 is the untouched aircraft, reuse the flights on a
    second run and score nothing."""
    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose

    monkeypatch.setattr(eval_jsbsim_diagnose, "DURATION_S", 2.0)
    runs = ((eval_jsbsim.main, ["--turbulence", "light", "--duration", "2", "--work", str(tmp_path / "f")], 1, 1),
            (eval_jsbsim_diagnose.main, ["--clean-seeds", "--pairs", "--effects", "delay:delta_e",
                                         "--out", str(tmp_path / "d")], -3, 3))      # reference + 2 sizes
    for main, extra, column, n in runs:
        argv = ["--aircraft", "F16_DIRECT", "--seeds", "1", *extra, "--fly-only"]
        assert main(argv) == 0 and main(argv) == 0
        cap = capsys.readouterr()
        assert [ln.split()[column] for ln in cap.out.splitlines()] == ["flown"] * n + ["reused"] * n, cap.out
        assert "f16 is the untouched aircraft" in cap.err
    assert read_log(tmp_path / "f" / "f16-light-s1-ahrs.tlog").streams["servo"].t.size > 50
    assert not (tmp_path / "d" / "results.jsonl").exists() or not (tmp_path / "d" / "results.jsonl").read_text()
