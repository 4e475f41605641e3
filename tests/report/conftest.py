"""A small ReplayResult built from synthetic data (no log, no JAX GP): the report's input."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.envelope import DEFAULT_SLICES, EnvelopeConfig, confidence_map
from gcs_sysid.estimation.states import FlightStates
from gcs_sysid.maneuvers import suggest_maneuvers
from gcs_sysid.result import ReplayResult
from gcs_sysid.telemetry.types import Stream, StreamSummary

_spec = importlib.util.spec_from_file_location("exact_gp_double", Path(__file__).parents[1] / "exact_gp_double.py")
double = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(double)

REPO = Path(__file__).resolve().parents[2]


def build_result(seed: int = 3, n: int = 400, drop_moments: bool = False, n_slices: int = 7) -> ReplayResult:
    """A synthetic replay: states, table, held-out segment, model predictions, map and suggestions."""
    tab = double.synthetic_table(n=n, seed=seed)
    T = len(tab.t)
    held = np.zeros(T, bool)
    held[int(0.8 * T):] = True
    train = tab.valid & ~held
    cols = [0, 1, 2] if drop_moments else list(range(6))
    outs = [("CX", "CY", "CZ", "Cl", "Cm", "Cn")[i] for i in cols]
    model = double.fit_double(tab.X[train], tab.Y[train][:, cols], rel_lengthscale=2.0, max_points=200)
    mean, var = model.predict(tab.X)
    pm = np.full(tab.Y.shape, np.nan)
    ps = np.full(tab.Y.shape, np.nan)
    pm[:, cols], ps[:, cols] = mean, np.sqrt(var)
    x = {name: tab.X[:, i] for i, name in enumerate(("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e",
                                                     "delta_a", "delta_r", "delta_t", "V"))}
    rng = np.random.default_rng(seed)
    V = x["V"]
    data = {"phi": np.cumsum(rng.normal(0, 0.01, T)), "theta": x["alpha"] + 0.02, "psi": np.linspace(0, 3, T),
            "p": x["p_hat"] * 2 * V / 2.0, "q": x["q_hat"] * 2 * V / 0.28, "r": x["r_hat"] * 2 * V / 2.0,
            "V": V, "alpha": x["alpha"], "beta": x["beta"], "delta_e": x["delta_e"], "delta_a": x["delta_a"],
            "delta_r": x["delta_r"], "delta_t": x["delta_t"], "qbar": tab.qbar}
    states = FlightStates(tab.t, 20.0, data, {}, tab.valid.copy(), {"V": "synthetic"}, [], [])
    summaries = {}
    for name, rate in (("imu", 20.0), ("attitude", 10.0), ("servo", 10.0), ("vfr_hud", 4.0)):
        t = np.arange(tab.t[0], tab.t[-1], 1.0 / rate)
        if name == "servo":
            t = t[(t < 110) | (t > 112)]
        summaries[name] = StreamSummary.of(Stream(name, name.upper(), t, {}), dropped=2 if name == "imu" else 0)
    af = load_airframe(REPO / "data" / "airframes" / "sim-trainer.toml")
    env = confidence_map(model, tab, train, EnvelopeConfig(slices=DEFAULT_SLICES[:n_slices], n_grid=16), outputs=outs)
    sug = suggest_maneuvers(env, model, tab, af, max_suggestions=5)
    metrics, ident = {}, {}
    for j, c in enumerate(("CX", "CY", "CZ", "Cl", "Cm", "Cn")):
        y = tab.Y[:, j]
        err = lambda m: 100 * np.sqrt(np.nanmean((pm[m, j] - y[m]) ** 2)) / np.sqrt(np.mean(y[m] ** 2))  # noqa: E731
        metrics[c] = {"error_pct_heldout": float(err(held)) if j in cols else float("nan"),
                      "error_pct_train": float(err(train)) if j in cols else float("nan"),
                      "rms_measured": float(np.sqrt(np.mean(y**2))), "n_heldout": int(held.sum()) if j in cols else 0,
                      "n_train": int(train.sum())}
        ident[c] = (True, "") if j in cols else (False, "IMU at 4 Hz: rate derivatives cannot be formed")
    notes = ["synthetic flight for the report tests"]
    if drop_moments:
        notes.append("moment coefficients not identifiable: IMU at 4 Hz; raise the stream rates (SR*_RAW_SENS)")
    return ReplayResult(
        log_path="synthetic/flight.tlog", airframe_name=af.name, airframe_path=str(af.source),
        vehicle={"mav_type": 1, "autopilot": 3}, window=(None, None), summaries=summaries,
        messages={"ATTITUDE": 200, "RAW_IMU": 400, "SERVO_OUTPUT_RAW": 190}, states=states, table=tab,
        held_out=held, train=train, pred_mean=pm, pred_sigma=ps, pred_sigma_obs=np.sqrt(ps**2 + (0.1 * ps) ** 2),
        metrics=metrics, identifiable=ident,
        envelope=env, suggestions=sug, gp_summary=model.summary() | {"outputs": outs}, model_path="",
        missing=["wind: no WIND message"] if drop_moments else [], notes=notes, timings={"learn GP": 1.0},
    )


@pytest.fixture(scope="session")
def replay_result() -> ReplayResult:
    """Full synthetic result (all six coefficients)."""
    return build_result(n_slices=4)


@pytest.fixture(scope="session")
def partial_result() -> ReplayResult:
    """Synthetic result where only the forces are identified."""
    return build_result(seed=4, drop_moments=True, n_slices=2)
