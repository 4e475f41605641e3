"""The aided sideslip against JSBSim's exact sideslip, per side-force estimator (issue 8; the sixty-second session).

The aided sideslip is the force-derived angle ``(CY - CY_rest) / CY_beta`` at every frequency its gust state reaches,
so its error is the side-force model's (``gcs_sysid.estimation.airangles``). This script runs the replay's estimator
(:func:`gcs_sysid.estimation.estimate_states`) on JSBSim harness flights once per side-force estimator and reads the
aided sideslip against the harness truth beside each log (``<stem>-truth.npz``; the pipeline never reads it):

* ``error``: the SD of (aided - true) over the SD of the true sideslip, on the span the truth covers;
* ``gain``: the cross-spectral gain of the aided on the true sideslip, ``|S_xy / S_xx|`` summed over each band
  (Bendat and Piersol, *Random Data*, 4th ed., Wiley 2010, sec. 6.1), 1 where the aided angle has the true one's scale;
* the side-force model's slopes and how they were fitted (``AxisFit.slope_method``).

Estimators: ``ls`` least squares (the default), ``gls`` generalised least squares under the gust model
(``airangles.BETA_GLS``, ``estimate_states(gls_beta=True)``). The summary compares each with the first one given: the
median and mean error, the flights better or worse by more than 5 %, and the median ``|log gain|`` over 0.03-0.3 Hz.
Measured in ``docs/benchmarks.md``, "Sixty-second session, lead".

Usage::

    python benchmarks/sideslip_truth_screen.py FLY/*/*-ref-*.tlog [--estimators ls gls] [--json OUT.jsonl]

A log's aircraft is the first part of its name (``c684-ref-sweep-pa-pt.tlog``: the harness's ``c684``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

#: the bands of the gain, Hz
BANDS = ((0.01, 0.03), (0.03, 0.1), (0.1, 0.3), (0.3, 0.7), (0.7, 1.5))
ESTIMATORS = ("ls", "gls")


def band_gains(t: np.ndarray, truth: np.ndarray, est: np.ndarray) -> list[float]:
    """Cross-spectral gain of ``est`` on ``truth`` (both (N,), on the uniform times ``t``, s) in each of :data:`BANDS`
    (Welch, segments of up to 4096 samples); NaN for a band with no frequency bin. Rows where either is not finite are
    dropped first."""
    from scipy import signal

    ok = np.isfinite(truth) & np.isfinite(est)
    x, y = truth[ok] - truth[ok].mean(), est[ok] - est[ok].mean()
    fs = 1.0 / float(np.median(np.diff(t)))
    f, Pxy = signal.csd(x, y, fs=fs, nperseg=min(len(x), 4096))
    _, Pxx = signal.welch(x, fs=fs, nperseg=min(len(x), 4096))
    out = []
    for lo, hi in BANDS:
        m = (f >= lo) & (f < hi)
        out.append(float(abs(Pxy[m].sum() / Pxx[m].sum())) if m.any() and Pxx[m].sum() > 0 else float("nan"))
    return out


def screen_flight(tlog: Path, estimators: tuple[str, ...]) -> list[dict]:
    """One line per estimator for a harness flight: ``aircraft``, ``flight``, ``estimator``, ``error`` (-),
    ``gains`` (per band), ``signal_deg`` (SD of the true sideslip), ``method``, ``columns``, ``coef``.

    Raises:
        KeyError: the log's aircraft is not the harness's. FileNotFoundError: no truth beside the log.
    """
    from benchmarks.jsbsim_harness.aircraft import AIRCRAFT
    from benchmarks.jsbsim_harness.truth import load_truth
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.estimation import estimate_states
    from gcs_sysid.telemetry import read_log

    ac = tlog.name.split("-")[0]
    airframe = load_airframe(AIRCRAFT[ac].airframe_path)
    truth = load_truth(tlog.with_name(tlog.name.removesuffix(".tlog") + "-truth.npz"))
    flight = read_log(tlog)
    lines = []
    for name in estimators:
        st = estimate_states(flight, airframe, gls_beta=(name == "gls"))
        beta_true = truth.at(st.t)[0][:, 1]
        est = st.data["beta"]
        m = np.isfinite(beta_true) & np.isfinite(est)
        fit = st.angle_fits["beta"]
        lines.append({"aircraft": ac, "flight": tlog.name, "estimator": name,
                      "error": float(np.std(est[m] - beta_true[m]) / np.std(beta_true[m])),
                      "gains": band_gains(st.t[m], beta_true[m], est[m]),
                      "signal_deg": float(np.degrees(np.std(beta_true[m]))), "method": fit.slope_method,
                      "columns": list(fit.columns), "coef": [float(c) for c in fit.coef]})
    return lines


def summary(lines: list[dict]) -> list[str]:
    """Markdown lines: per flight the error and the 0.03-0.3 Hz gain per estimator, then each estimator against the
    first one (median and mean error, flights better / worse by more than 5 %, median ``|log gain|``)."""
    names = list(dict.fromkeys(r["estimator"] for r in lines))
    by = {}
    for r in lines:
        by.setdefault(r["flight"], {})[r["estimator"]] = r
    flights = [f for f, v in by.items() if all(n in v for n in names)]
    low = lambda r: float(np.mean(r["gains"][1:3]))         # noqa: E731  the 0.03-0.3 Hz bands
    out = ["| flight | " + " | ".join(f"error {n}" for n in names) + " | " + " | ".join(f"gain {n}" for n in names)
           + " |", "|---" * (1 + 2 * len(names)) + "|"]
    for f in flights:
        out.append(f"| {f} | " + " | ".join(f"{by[f][n]['error']:.3f}" for n in names) + " | "
                   + " | ".join(f"{low(by[f][n]):.2f}" for n in names) + " |")
    base = names[0]
    for n in names:
        e = np.array([by[f][n]["error"] for f in flights])
        e0 = np.array([by[f][base]["error"] for f in flights])
        g = np.array([abs(np.log(low(by[f][n]))) for f in flights])
        line = f"{n}: error median {np.median(e):.3f}, mean {np.mean(e):.3f}; median |log gain| {np.median(g):.3f}"
        if n != base:
            line += f"; against {base}: better {int(np.sum(e < e0 / 1.05))}, worse {int(np.sum(e > e0 * 1.05))}"
        out.append(line)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tlogs", nargs="+", type=Path, help="JSBSim harness logs with <stem>-truth.npz beside them")
    ap.add_argument("--estimators", nargs="+", default=list(ESTIMATORS), choices=ESTIMATORS)
    ap.add_argument("--json", type=Path, default=None, help="append one JSON line per flight and estimator here")
    a = ap.parse_args(argv)
    lines = []
    for tl in a.tlogs:
        new = screen_flight(tl, tuple(a.estimators))
        lines += new
        if a.json is not None:
            with a.json.open("a") as fh:
                fh.writelines(json.dumps(r) + "\n" for r in new)
    print("\n".join(summary(lines)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
