"""``gcs-sysid predict`` on the model a real replay of a JSBSim flight saved."""

import csv
import subprocess
import sys

import numpy as np
import pytest

from benchmarks.jsbsim_harness import load_truth
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.gp import load_gp
from gcs_sysid.pipeline import ReplayOptions, error_pct, run_replay
from gcs_sysid.cli import main
from gcs_sysid.predict import read_conditions
from gcs_sysid.errors import InputError


@pytest.fixture(scope="module")
def replay_dir(fast_flight, tmp_path_factory):
    """A real replay of the fast flight (its report and saved model); ~35 s with a cold JAX cache."""
    out = tmp_path_factory.mktemp("replay")
    result = run_replay(fast_flight.tlog, fast_flight.airframe, out, ReplayOptions(progress=False))
    assert (out / "model.npz").is_file()
    return out, result


@pytest.fixture(scope="module")
def fitted_dir(fast_flight, tmp_path_factory):
    """The replay's model-fitting steps alone (measured table -> fit_gp -> save as OUT/model), cheaper
    than a whole replay: the default suite's model for predict."""
    from gcs_sysid.aero import compute_coefficients
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.estimation import estimate_states
    from gcs_sysid.gp import GPConfig, fit_gp
    from gcs_sysid.telemetry import read_log

    af = load_airframe(fast_flight.airframe)
    table = compute_coefficients(estimate_states(read_log(fast_flight.tlog), af), af)
    ok = table.valid & np.isfinite(table.X).all(1) & np.isfinite(table.Y).all(1)
    model, _ = fit_gp(table.X[ok][::2], table.Y[ok][::2], GPConfig(n_inducing=32, steps=60, local_steps=15))
    out = tmp_path_factory.mktemp("fitted")
    model.save(out / "model")
    return out, table.t[ok][::2]


def _write_conditions(path, X, extra=True):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow((["case"] if extra else []) + list(REGRESSORS))
        for i, row in enumerate(X):
            w.writerow(([f"c{i}"] if extra else []) + [repr(float(v)) for v in row])


def _check_cli(out, truth, times, tmp_path):
    X, Y = truth.at(times)
    cond, pred = tmp_path / "cond.csv", tmp_path / "pred.csv"
    _write_conditions(cond, X)
    assert main(["predict", str(out), "--inputs", str(cond), "--out", str(pred)]) == 0
    with open(pred, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(X) and rows[0]["case"] == "c0"
    mean = np.array([[float(r[f"{c}_mean"]) for c in COEFFICIENTS] for r in rows])
    sigma = np.array([[float(r[f"{c}_sigma"]) for c in COEFFICIENTS] for r in rows])
    sigma_obs = np.array([[float(r[f"{c}_sigma_obs"]) for c in COEFFICIENTS] for r in rows])
    m_ref, v_ref = load_gp(out / "model").predict(X, include_noise=False, input_noise=False)   # exact conditions
    np.testing.assert_allclose(mean, m_ref, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(sigma, np.sqrt(v_ref), rtol=1e-6, atol=1e-12)
    assert (sigma_obs >= sigma).all() and (sigma > 0).all()
    assert error_pct(mean[:, 2], Y[:, 2]) < 10.0


def test_predict_cli_at_true_conditions(fitted_dir, fast_flight, tmp_path):
    """The CLI writes mean and sigma per coefficient equal to the loaded model's, copies the extra
    column, and at the true conditions of the training data the mean is close to the truth for the
    well-measured CZ (within 10 %)."""
    out, times = fitted_dir
    _check_cli(out, load_truth(fast_flight.truth), times[::10], tmp_path)


@pytest.mark.slow
def test_predict_cli_on_a_replay_model(replay_dir, fast_flight, tmp_path):
    """The same on the model a whole ``run_replay`` saved (OUT/model)."""
    out, result = replay_dir
    _check_cli(out, load_truth(fast_flight.truth), result.table.t[result.train][::10], tmp_path)


def test_predict_errors_are_one_line(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("alpha_deg,beta\n1,2\n")
    with pytest.raises(InputError, match="missing column.*alpha.*degree columns such as alpha_deg"):
        read_conditions(bad)
    X = np.zeros((2, len(REGRESSORS)))
    X[:, -1] = 30.0
    cond = tmp_path / "c.csv"
    _write_conditions(cond, X, extra=False)
    cond.write_text(cond.read_text().replace("30.0", "fast", 1))
    with pytest.raises(InputError, match="row 2, column V: expected a finite number"):
        read_conditions(cond)
    r = subprocess.run([sys.executable, "-m", "gcs_sysid.cli", "predict", str(tmp_path / "nothing"), "--inputs",
                        str(cond), "--out", str(tmp_path / "p.csv")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "no saved model" in r.stderr


def test_output_names_come_from_the_replay_record_when_the_model_has_generic_names(tmp_path):
    """A replay that identifies only some coefficients saves the model with names y0, y1...; the
    replay's record beside it names them."""
    import json

    from gcs_sysid.predict import _output_names

    (tmp_path / "model.json").write_text(json.dumps({"output_names": ["y0", "y1"]}))
    assert _output_names(tmp_path / "model", 2) == ("y0", "y1")
    (tmp_path / "result").mkdir()
    (tmp_path / "result" / "result.json").write_text(json.dumps({"gp_summary": {"outputs": ["CX", "CZ"]}}))
    assert _output_names(tmp_path / "model", 2) == ("CX", "CZ")
    (tmp_path / "model.json").write_text(json.dumps({"output_names": list(COEFFICIENTS)}))
    assert _output_names(tmp_path / "model", 6) == COEFFICIENTS
