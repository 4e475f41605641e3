"""The estimator's stated sigma of p_dot q_dot r_dot against JSBSim's truth, and what the true error is made of.

For each flight of an ``eval_jsbsim.py`` work directory (``<AC>-<turb>-s<seed>-ahrs.tlog`` and its
``-truth.npz``; nothing is flown here) it runs ``estimate_states`` as the replay does and prints per axis:

  ratio     RMS of the stated sigma / RMS of the true error (all valid rows; 1 = right)
  err       true RMS error, rad/s^2, and its lag-1 autocorrelation
  noise     the part of the true error driven by the gyro's white noise: the error regressed on the
            gyro's known noise (gyro less the truth's rate, a two-sided FIR of +-60 samples; truth side,
            a diagnosis), RMS
  rest      the remainder: the signal the smoother cuts off (and the controls' fitted response's error), RMS
  >3 Hz, >8 Hz  share of the true error's variance above 3 and 8 Hz (Welch)
  st_noise, st_dist  the stated variance's two parts (:func:`gcs_sysid.estimation.smootherror.
            accel_error_split`): the noise-driven part and the white-snap prior's distortion, RMS

Usage::

    python benchmarks/eval_accel_sigma.py --work DIR --aircraft f16 t6 --seeds 1 2 3 \\
        --turbulence light moderate --json F.jsonl
    python benchmarks/eval_accel_sigma.py --summarize F.jsonl

Results: docs/benchmarks.md, "Thirteenth session, i8-sigma".
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy.signal import welch

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.eval_common import append_jsonl  # noqa: E402

FIR_TAPS = 60


def _capture_rates():
    """Wrap ``estimate.smooth_rates`` so the last call's gyro input and :class:`RateEstimate` are kept
    (the states carry the rates' results, not the smoother's bandwidth and gyro noise)."""
    import gcs_sysid.estimation.estimate as E

    cap: dict = {}
    orig = E.smooth_rates

    def wrapped(*a, **k):
        r = orig(*a, **k)
        cap["gyro"], cap["R"] = np.asarray(a[1], float), r
        return r
    E.smooth_rates = wrapped
    return cap


def measure(work: Path, ac: str, turb: str, seed: int, cap: dict) -> dict:
    """One flight's per-axis numbers (module docstring). Raises FileNotFoundError if the flight is missing."""
    from benchmarks.jsbsim_harness import load_truth
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.estimation import estimate_states
    from gcs_sysid.estimation.smootherror import accel_error_split
    from gcs_sysid.telemetry import read_log

    stem = f"{ac}-{turb}-s{seed}-ahrs"
    tlog, tpath = work / f"{stem}.tlog", work / f"{stem}-truth.npz"
    if not tlog.is_file() or not tpath.is_file():
        raise FileNotFoundError(f"{tlog} or {tpath} missing (fly it with eval_jsbsim.py --fly-only)")
    st = estimate_states(read_log(tlog), load_airframe(aircraft(ac).airframe_path))
    truth = load_truth(tpath)
    t = np.asarray(st.t)
    dt = float(np.median(np.diff(t)))
    R, Z = cap["R"], cap["gyro"]
    valid = np.asarray(st.valid, bool)
    out = {"ac": ac, "turb": turb, "seed": seed}
    for i, k in enumerate("pqr"):
        w = np.interp(t, truth.t, truth.fields[k])
        wd = np.interp(t, truth.t, truth.fields[k + "_dot"])
        e_all = np.asarray(st.data[k + "_dot"]) - wd
        s_all = np.asarray(st.sigma[k + "_dot"])
        ok = valid & np.isfinite(e_all) & np.isfinite(s_all)
        e, s = e_all[ok], s_all[ok]
        err = float(np.sqrt(np.mean(e**2)))
        row = {"err": err, "ratio": float(np.sqrt(np.mean(s**2))) / err,
               "lag1": float(np.corrcoef(e[1:], e[:-1])[0, 1]), "bw": float(R.bandwidth_hz[i])}
        # the longest gap-free stretch: the noise-driven part by regression on the gyro's known noise
        good = np.isfinite(Z[:, i]) & np.isfinite(e_all)
        idx = np.flatnonzero(good)
        sl = slice(idx[0], idx[-1] + 1)
        if good[sl].all():
            v = (Z[sl, i] - w[sl]) - np.mean(Z[sl, i] - w[sl])
            ee = e_all[sl]
            n, L = len(v), FIR_TAPS
            V = np.stack([np.roll(v, j) for j in range(-L, L + 1)], 1)[L:n - L]
            c, *_ = np.linalg.lstsq(V, ee[L:n - L], rcond=None)
            en = V @ c
            row["noise"] = float(np.sqrt(np.mean(en**2)))
            row["rest"] = float(np.sqrt(np.mean((ee[L:n - L] - en) ** 2)))
            f, S = welch(ee, 1.0 / dt, nperseg=128)
            row["above3"] = float(S[f > 3].sum() / S.sum())
            row["above8"] = float(S[f > 8].sum() / S.sum())
        sn, sd = accel_error_split(dt, float(R.bandwidth_hz[i]), float(R.noise_std[i]))
        row["st_noise"], row["st_dist"] = float(np.sqrt(sn)), float(np.sqrt(sd))
        out[k + "_dot"] = row
    return out


def summarize(path: Path) -> str:
    """Markdown table of a ``--json`` file: per aircraft and level, the ratio per axis over the seeds."""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    axes = ("p_dot", "q_dot", "r_dot")
    lines = ["| aircraft | turb. | p_dot ratio | q_dot ratio | r_dot ratio | true err p q r (rad/s^2) "
             "| true noise-driven / rest (RMS, seed mean) p; q; r | stated/true: noise-driven p q r "
             "| stated prior/true: rest p q r | >3 Hz share p q r |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    keys = sorted({(r["ac"], r["turb"]) for r in rows}, key=lambda k: (k[0], k[1] != "light"))
    for ac, turb in keys:
        rs = [r for r in rows if r["ac"] == ac and r["turb"] == turb]

        def mean(a, f):
            return float(np.mean([r[a].get(f, np.nan) for r in rs]))
        cells = ["/".join(f"{r[a]['ratio']:.2f}" for r in rs) for a in axes]
        cells.append(" ".join(f"{mean(a, 'err'):.4f}" for a in axes))
        cells.append("; ".join(f"{mean(a, 'noise'):.4f} / {mean(a, 'rest'):.4f}" for a in axes))
        cells.append(" ".join(f"{mean(a, 'st_noise') / mean(a, 'noise'):.2f}" for a in axes))
        cells.append(" ".join(f"{mean(a, 'st_dist') / mean(a, 'rest'):.2f}" for a in axes))
        cells.append(" ".join(f"{mean(a, 'above3'):.2f}" for a in axes))
        lines.append(f"| {ac} | {turb} | " + " | ".join(cells) + " |")
    allr = np.array([r[a]["ratio"] for r in rows for a in axes])
    lines.append("")
    lines.append(f"{len(allr)} axis-flights: median ratio {np.median(allr):.2f}, within 0.8-1.25: "
                 f"{int(np.sum((allr >= 0.8) & (allr <= 1.25)))}, range {allr.min():.2f}-{allr.max():.2f}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, help="eval_jsbsim work directory holding the flights")
    ap.add_argument("--aircraft", nargs="+", default=["f16"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1])
    ap.add_argument("--turbulence", nargs="+", default=["light"])
    ap.add_argument("--json", type=Path, help="append one JSON line per flight")
    ap.add_argument("--summarize", type=Path, help="print the markdown table of a --json file and exit")
    a = ap.parse_args(argv)
    if a.summarize:
        print(summarize(a.summarize))
        return 0
    if a.work is None:
        ap.error("--work is required unless --summarize")
    cap = _capture_rates()
    for ac in a.aircraft:
        for turb in a.turbulence:
            for seed in a.seeds:
                try:
                    r = measure(a.work, ac, turb, seed, cap)
                except FileNotFoundError as exc:
                    print(f"skipped: {exc}", file=sys.stderr)
                    continue
                print(ac, turb, seed, "  ".join(f"{k}: {r[k]['ratio']:.2f}" for k in ("p_dot", "q_dot", "r_dot")),
                      flush=True)
                append_jsonl(a.json, [r])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
