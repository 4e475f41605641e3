"""What a model of the ten regressors can reach in turbulence: the gyro's rates against the air-relative rates.

JSBSim's aerodynamics reads the body rates relative to the air, ``p_aero = p - p_g`` (and ``q``, ``r``); a gyro
measures ``p``. Scored against JSBSim's exact coefficients, any model ``C(x)`` evaluated with the inertial rates
misses the rotational gust's share, ``C_p (p_g - E[p_g | x])``, however well it was learned. This script measures
that floor on the truth files alone (no estimation, no GP): an ordinary least-squares model, linear in the ten
regressors plus ``alpha^2 beta^2 alpha*beta alpha*q_hat alpha*delta_e`` and ``alpha_dot_hat`` (the pipeline's
mean-only input of Cm), is fitted to the truth's own coefficients on the first 80 % of the airborne rows and scored
on the last 20 % (the held-out share ``eval_jsbsim.py`` scores), once with the inertial rates in ``p_hat q_hat r_hat``
(the reading of ``eval_jsbsim``'s ``true`` column) and once with the air-relative rates (its ``tair`` column).
A model fitted to exact truth at exact regressors is a lower bound for the GP's ``true`` error where the truth is
(nearly) of this form; the aircraft's own tables are not all of it (``Cm`` keeps its nonlinear rest).

It also checks the size of the rotational gust against MIL-F-8785C's Dryden model, as the estimator would state it
(:func:`gcs_sysid.estimation.gustrates.dryden_rate_sigma` with the intensity from the horizontal gusts' structure
function, :func:`gcs_sysid.estimation.gustrates.gust_intensity`, here from the truth's wind).

Usage::

    python benchmarks/rate_floor.py /tmp/baseline15/ejm-t6 /tmp/baseline15/ejm-rascal ...   # folders of *-truth.npz
    python benchmarks/rate_floor.py DIR --json floor.jsonl

Columns: ``gyro`` and ``air`` the held-out errors ``100 RMS(fit - truth) / RMS(truth)`` per coefficient;
``p_g q_g r_g``: the truth's rotational gust RMS (rad/s) and, after ``/``, the Dryden statement.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.eval_jsbsim import true_alpha_dot  # noqa: E402
from benchmarks.jsbsim_harness import load_truth  # noqa: E402
from gcs_sysid.aero.table import COEFFICIENTS  # noqa: E402
from gcs_sysid.estimation.gustrates import dryden_rate_sigma, gust_intensity  # noqa: E402


def _features(X: np.ndarray, adot: np.ndarray) -> np.ndarray:
    """``(T, 17)`` the oracle's terms: 1, the ten regressors, five products, ``alpha_dot_hat``."""
    a = X[:, 0]
    return np.c_[np.ones(len(X)), X, a * a, X[:, 1] ** 2, a * X[:, 1], a * X[:, 3], a * X[:, 5], adot]


def floor(path: Path) -> dict:
    """One truth file: the oracle's held-out errors with both rate readings and the gust-rate check.

    Args:
        path: a ``*-truth.npz`` written by the harness.

    Returns:
        JSON-able dict: ``gyro`` and ``air`` (``{coefficient: %}``), ``gust_rms`` (the truth's ``p_g q_g r_g`` RMS,
        rad/s), ``dryden`` (the statement, rad/s), ``sigma`` (m/s), ``n_train``, ``n_test``.
    """
    truth = load_truth(path)
    f, cst = truth.fields, truth.meta["constants"]
    b, c = float(cst["b"]), float(cst["c"])
    X, Y = truth.at(truth.t)
    V = f["V"]
    airborne = np.isfinite(X).all(1) & np.isfinite(Y).all(1) & (V > 0.5 * np.nanmedian(V))
    adot = true_alpha_dot(truth) * c / (2.0 * V)
    idx = np.nonzero(airborne & np.isfinite(adot))[0]
    cut = int(0.8 * len(idx))
    tr, te = idx[:cut], idx[cut:]
    Xa = X.copy()
    for j, (ax, ref) in enumerate(zip("pqr", (b, c, b))):
        Xa[:, 2 + j] = f[f"{ax}_aero"] * ref / (2.0 * V)
    out: dict = {"file": path.name, "n_train": int(len(tr)), "n_test": int(len(te))}
    rms = np.sqrt(np.mean(Y[te] ** 2, axis=0))
    for name, XX in (("gyro", X), ("air", Xa)):
        F = _features(XX, adot)
        w, *_ = np.linalg.lstsq(F[tr], Y[tr], rcond=None)
        err = 100.0 * np.sqrt(np.mean((F[te] @ w - Y[te]) ** 2, axis=0)) / rms
        out[name] = {k: float(e) for k, e in zip(COEFFICIENTS, err)}
    m = airborne
    out["gust_rms"] = [float(np.std((f[ax] - f[f"{ax}_aero"])[m])) for ax in "pqr"]
    dt = float(np.median(np.diff(truth.t)))
    sigma = gust_intensity(dt, np.stack([f["wn"], f["we"]], axis=1)[m], V[m])
    out["sigma"] = sigma
    out["dryden"] = [float(v) for v in dryden_rate_sigma(sigma, b)]
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+", type=Path, help="folders holding the harness's *-truth.npz files")
    ap.add_argument("--json", type=Path, help="append one JSON line per flight here")
    a = ap.parse_args(argv)
    files = sorted(p for d in a.dirs for p in Path(d).glob("*-truth.npz"))
    if not files:
        print(f"error: no *-truth.npz in {' '.join(map(str, a.dirs))}", file=sys.stderr)
        return 2
    print(f"{'flight':28s} {'gyro: ' + ' '.join(f'{k:>5s}' for k in COEFFICIENTS):44s} | "
          f"{'air: ' + ' '.join(f'{k:>5s}' for k in COEFFICIENTS):43s} | p_g q_g r_g truth / Dryden (rad/s)")
    for p in files:
        r = floor(p)
        g = " ".join(f"{r['gyro'][k]:5.1f}" for k in COEFFICIENTS)
        ai = " ".join(f"{r['air'][k]:5.1f}" for k in COEFFICIENTS)
        gr = " ".join(f"{t:.3f}/{s:.3f}" for t, s in zip(r["gust_rms"], r["dryden"]))
        print(f"{r['file'][:-10]:28s} gyro: {g} | air: {ai} | {gr}")
        append_jsonl(a.json, [r])
    return 0


if __name__ == "__main__":
    sys.exit(main())
