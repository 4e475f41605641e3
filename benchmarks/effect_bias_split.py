"""Where a ``Cn:delta_a`` change reads low: the reference model, the regressors or the sideslip (issue 9).

The records' ``Cn:delta_a`` findings read the injected change low (seed 3: median -4 %, the c684's -0.06 as -0.0385)
and their +-2 standard-error intervals cover JSBSim's value on about half the cases. This script splits the error on
one effect flight and its reference flight, both flown by the JSBSim harness (``benchmarks/jsbsim_harness``): the
change is read as the difference of two one-term regressions, effect flight minus reference flight, of the Cn residual
(a coefficient less a reference model) on ``delta_a`` with a free constant, under

* ``model at truth``: the reference model the diagnosis uses (a ``-model.toml`` fitted on the reference flight by the
  pipeline), evaluated at JSBSim's exact regressors against its exact Cn;
* ``linear at truth``: in its place a linear model (constant and the eight regressors alpha, beta, p_hat, q_hat,
  r_hat, delta_e, delta_a, delta_r), least squares on the reference flight's exact regressors and Cn;
* ``linear, pipeline``: the same linear model fitted and read on the pipeline's regressors and measured Cn;
* ``linear, true beta``: as the last with only the pipeline's sideslip replaced by JSBSim's.

Where ``linear, true beta`` recovers the injected change and ``linear, pipeline`` does not, the bias is the aided
sideslip's (its error along ``delta_a`` differs between the two flights). JSBSim's truth is read here only to
attribute the error; the pipeline never reads it. Measured in ``docs/benchmarks.md``, "Sixty-first session, lead".

Usage::

    python benchmarks/effect_bias_split.py --effect FLIGHT.tlog --reference REF.tlog --model REF-model.toml \
        --airframe data/airframes/jsbsim-c684.toml [--term delta_a] [--coefficient Cn]

``FLIGHT.tlog`` and ``REF.tlog`` need their harness truth beside them (``<stem>-truth.npz``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from benchmarks.jsbsim_harness.truth import load_truth
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.diagnose.run import load_measurements
from gcs_sysid.sim.model_file import load_model

#: The regressors of the linear reference (no throttle, no airspeed: the coefficients' own arguments).
LINEAR = ("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a", "delta_r")


def flight_arrays(tlog: Path, airframe: str) -> dict[str, np.ndarray]:
    """One flight's pipeline and exact arrays on the pipeline's valid rows.

    Returns:
        ``{"X": (N, 10) pipeline regressors, "Y": (N, 6) measured coefficients, "Xt": (N, 10) JSBSim's regressors,
        "Yt": (N, 6) JSBSim's coefficients}`` (``aero.table.REGRESSORS`` and ``COEFFICIENTS`` order; SI, rad).

    Raises:
        FileNotFoundError: no ``<stem>-truth.npz`` beside the log.
    """
    truth = tlog.with_name(tlog.stem + "-truth.npz")
    if not truth.exists():
        raise FileNotFoundError(f"{truth}: the harness truth of {tlog.name} (benchmarks/jsbsim_harness) is needed")
    tab = load_measurements(tlog, airframe).table
    Xt, Yt = load_truth(truth).at(tab.t)      # JSBSim's aerodynamic coefficients (the total's in a glide)
    ok = np.all(np.isfinite(tab.X), 1) & np.all(np.isfinite(tab.Y), 1) & np.all(np.isfinite(Xt), 1) \
        & np.all(np.isfinite(Yt), 1)
    return {"X": tab.X[ok], "Y": tab.Y[ok], "Xt": Xt[ok], "Yt": Yt[ok]}


def one_term_change(resid: dict[str, np.ndarray], column: dict[str, np.ndarray]) -> float:
    """Effect minus reference of the slope of each flight's residual ``(N_f,)`` on its ``column (N_f,)`` (constant
    free): the one-term differential estimate of a change of that term."""
    slope = {}
    for role in ("effect", "reference"):
        A = np.column_stack([np.ones(len(column[role])), column[role]])
        slope[role] = float(np.linalg.lstsq(A, resid[role], rcond=None)[0][1])
    return slope["effect"] - slope["reference"]


def split(effect: dict, reference: dict, model, coefficient: str = "Cn", term: str = "delta_a") -> dict[str, float]:
    """The change of ``coefficient:term`` read four ways (module docstring), keyed by the way's name."""
    c, j = COEFFICIENTS.index(coefficient), REGRESSORS.index(term)
    lin = [REGRESSORS.index(n) for n in LINEAR]
    flights = {"effect": effect, "reference": reference}

    def linear_change(xkey: str, ykey: str, beta_from: str | None = None) -> float:
        def X(f):
            x = f[xkey].copy()
            if beta_from is not None:
                x[:, 1] = f[beta_from][:, 1]
            return x

        F = {r: np.column_stack([np.ones(len(f[ykey])), X(f)[:, lin]]) for r, f in flights.items()}
        w = np.linalg.lstsq(F["reference"], reference[ykey][:, c], rcond=None)[0]
        return one_term_change({r: f[ykey][:, c] - F[r] @ w for r, f in flights.items()},
                               {r: X(f)[:, j] for r, f in flights.items()})

    at_truth = one_term_change({r: f["Yt"][:, c] - model.evaluate(f["Xt"])[:, c] for r, f in flights.items()},
                               {r: f["Xt"][:, j] for r, f in flights.items()})
    return {"model at truth": at_truth, "linear at truth": linear_change("Xt", "Yt"),
            "linear, pipeline": linear_change("X", "Y"), "linear, true beta": linear_change("X", "Y", "Xt")}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--effect", type=Path, required=True)
    ap.add_argument("--reference", type=Path, required=True)
    ap.add_argument("--model", type=Path, required=True, help="the reference model the diagnosis uses")
    ap.add_argument("--airframe", required=True)
    ap.add_argument("--coefficient", default="Cn", choices=COEFFICIENTS)
    ap.add_argument("--term", default="delta_a", choices=LINEAR)
    a = ap.parse_args(argv)
    out = split(flight_arrays(a.effect, a.airframe), flight_arrays(a.reference, a.airframe), load_model(a.model),
                a.coefficient, a.term)
    print(f"{a.effect.name}: change of {a.coefficient}:{a.term} | "
          + " | ".join(f"{k}: {v:+.4f}" for k, v in out.items()))


if __name__ == "__main__":
    main()
