"""Why the model misses at the true regressors (issue 8's true-air line): a decomposition without refitting a GP.

On JSBSim flights the GP's held-out predictions at the *reconstructed* regressors are close to the truth, but at
JSBSim's *true* regressors (``eval_jsbsim``'s ``true``/``true_air``, ``eval_gp_jsbsim``'s ``err_true``) the side
force, the normal force and the pitching and yawing moments miss by 10-50 %. The model is a map from the estimated
regressors to the measured coefficients; whatever the estimated regressors carry systematically (a scale, a level) is
learned into the map and reappears as an error where the map is asked at the exact ones. This script measures, per
flight of an ``eval_jsbsim --work`` folder (``<stem>-replay/coefficients.csv`` and ``<stem>-truth.npz``):

* each air angle's error against the truth: its *gain* ``k = cov(x_hat, x) / var(x)`` (the estimate as
  ``level + k x + u``), the *level* (mean of ``x_hat - x`` on the training rows, deg), the remainder ``u``'s SD (deg)
  and the reliability ``lambda = cov(x, x_hat) / var(x_hat)`` (the slope ratio errors in variables would give: below
  1 attenuates, Fuller, *Measurement Error Models*, Wiley 1987, sec. 1.1; ``lambda = 1 / k`` for a pure scale error,
  which *inflates* the slope learned on the estimate);
* a linear least-squares proxy of the model (intercept + the ten regressors, fitted on the table's training rows: on
  the fokker50 it reproduces the GP's held-out and true-regressor errors within 0.3 points) asked at the held-out
  rows' estimated regressors (``held``), at the true ones (``true``), and at the true ones with one part of one
  angle's error put back: the whole estimate (``<angle>_est``: the miss that angle explains), only its gain and
  level (``<angle>_gain``: the truth passed through ``level + k x``), only its level (``<angle>_level``);
* the ratio of the proxy's slopes ``d CY / d beta``, ``d Cn / d beta``, ``d CZ / d alpha``, ``d Cm / d alpha`` on the
  estimated table to the same least squares on the exact regressors and coefficients (JSBSim's linear derivatives).

Errors are ``100 RMS(model - truth) / RMS(truth)`` per coefficient on the held-out rows (the project's metric).

Usage::

    python benchmarks/truereg_decomp.py /tmp/ej-work [more folders] [--json out.json]

Thirty-first session, i8-truereg (``docs/benchmarks.md``).
"""

from __future__ import annotations

import argparse
import glob
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS  # noqa: E402

#: the angles decomposed (columns of ``REGRESSORS``) and the coefficients each one's error reaches
ANGLES = {"alpha": ("CZ", "Cm"), "beta": ("CY", "Cn")}


def errors(est: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``100 RMS(est - ref) / RMS(ref)`` per column ``(P,)`` of ``(N, P)`` arrays."""
    return 100.0 * np.sqrt(np.mean((est - ref) ** 2, 0)) / np.sqrt(np.mean(ref ** 2, 0))


def decompose(X: np.ndarray, Y: np.ndarray, Xt: np.ndarray, Yt: np.ndarray, train: np.ndarray,
              held: np.ndarray) -> dict:
    """The decomposition of one flight (module docstring).

    Args:
        X: ``(T, 10)`` estimated regressors (``REGRESSORS``: rad, -, m/s); Y: ``(T, 6)`` measured coefficients
            (``COEFFICIENTS``); Xt, Yt: the truth's on the same rows; rows with a NaN in any of them are left out.
        train, held: ``(T,)`` bool, the table's training and held-out rows.

    Returns:
        JSON-able dict: ``held``, ``true`` and for each angle ``a`` in :data:`ANGLES` ``a_est``, ``a_gain``,
        ``a_level`` (``{coefficient: error %}``), ``a_k``, ``a_lambda``, ``a_level_deg``, ``a_u_deg``, ``a_sd_deg``
        (the truth's SD on the training rows) and ``slope_ratio`` (``{"CY/beta": ratio, ...}``).

    Raises:
        ValueError: fewer usable training or held-out rows than twice the regressors.
    """
    X, Y, Xt, Yt = (np.asarray(a, float) for a in (X, Y, Xt, Yt))
    ok = np.isfinite(X).all(1) & np.isfinite(Y).all(1) & np.isfinite(Xt).all(1) & np.isfinite(Yt).all(1)
    tr, h = ok & np.asarray(train, bool), ok & np.asarray(held, bool)
    if tr.sum() < 2 * X.shape[1] or h.sum() < 2 * X.shape[1]:
        raise ValueError(f"too few rows: {int(tr.sum())} training, {int(h.sum())} held out")
    use = [j for j in range(X.shape[1]) if np.std(X[tr, j]) > 1e-12 and np.std(Xt[tr, j]) > 1e-12]

    def design(Z):
        return np.column_stack([np.ones(len(Z)), Z[:, use]])

    coef, *_ = np.linalg.lstsq(design(X[tr]), Y[tr], rcond=None)
    coef_t, *_ = np.linalg.lstsq(design(Xt[tr]), Yt[tr], rcond=None)

    def score(Z):
        return dict(zip(COEFFICIENTS, np.round(errors(design(Z) @ coef, Yt[h]), 2).tolist()))

    out: dict = {"n_train": int(tr.sum()), "n_held": int(h.sum()), "held": score(X[h]), "true": score(Xt[h]),
                 "slope_ratio": {}}
    for a, coefs in ANGLES.items():
        j = REGRESSORS.index(a)
        x, xt = X[tr, j], Xt[tr, j]
        k = float(np.cov(x, xt)[0, 1] / np.var(xt, ddof=1))
        lam = float(np.cov(x, xt)[0, 1] / np.var(x, ddof=1))
        lvl = float(np.mean(x - xt))
        u = (x - x.mean()) - k * (xt - xt.mean())
        out.update({f"{a}_k": k, f"{a}_lambda": lam, f"{a}_level_deg": float(np.degrees(lvl)),
                    f"{a}_u_deg": float(np.degrees(np.std(u))), f"{a}_sd_deg": float(np.degrees(np.std(xt)))})
        Z = Xt[h].copy()
        Z[:, j] = X[h, j]
        out[f"{a}_est"] = score(Z)
        Z = Xt[h].copy()
        Z[:, j] = (x.mean() - k * xt.mean()) + k * Xt[h, j]
        out[f"{a}_gain"] = score(Z)
        Z = Xt[h].copy()
        Z[:, j] = Xt[h, j] + lvl
        out[f"{a}_level"] = score(Z)
        if j in use:
            for c in coefs:
                i = COEFFICIENTS.index(c)
                out["slope_ratio"][f"{c}/{a}"] = float(coef[use.index(j) + 1, i] / coef_t[use.index(j) + 1, i])
    return out


def read_flight(folder: Path, stem: str):
    """``(X, Y, Xt, Yt, train, held)`` of one ``eval_jsbsim --work`` flight ``stem`` (its replay's
    ``coefficients.csv`` and the truth ``<stem>-truth.npz`` on the table's rows)."""
    from benchmarks.jsbsim_harness import load_truth

    a = np.genfromtxt(folder / f"{stem}-replay" / "coefficients.csv", delimiter=",", names=True)
    X = np.column_stack([a[r] for r in REGRESSORS])
    Y = np.column_stack([a[c] for c in COEFFICIENTS])
    held = a["held_out"] > 0.5
    Xt, Yt = load_truth(folder / f"{stem}-truth.npz").at(a["time_s"])
    return X, Y, Xt, Yt, ~held, held


def _fmt(d: dict, keys=("CY", "CZ", "Cm", "Cn")) -> str:
    return " ".join(f"{d[k]:5.1f}" for k in keys)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", help="eval_jsbsim --work folders")
    ap.add_argument("--json", default=None, help="write the rows here")
    a = ap.parse_args(argv)
    rows = []
    print(f"{'flight':28s} {'CY CZ Cm Cn:':>12s} held | true | beta_est | beta_gain | alpha_est | alpha_level | "
          "beta k, alpha level deg, k")
    for folder in map(Path, a.folders):
        for csv in sorted(glob.glob(str(folder / "*-replay" / "coefficients.csv"))):
            stem = Path(csv).parent.name[: -len("-replay")]
            if not (folder / f"{stem}-truth.npz").exists():
                continue
            r = dict(flight=stem, folder=str(folder), **decompose(*read_flight(folder, stem)))
            rows.append(r)
            print(f"{stem:28s} {'':12s} {_fmt(r['held'])} | {_fmt(r['true'])} | {_fmt(r['beta_est'])} | "
                  f"{_fmt(r['beta_gain'])} | {_fmt(r['alpha_est'])} | {_fmt(r['alpha_level'])} | "
                  f"{r['beta_k']:.2f}, {r['alpha_level_deg']:+.2f} {r['alpha_k']:.2f}", flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
