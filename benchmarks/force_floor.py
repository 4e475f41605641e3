"""Where the measured force coefficients' error comes from, on eval_jsbsim's flights (attribution only).

For every flight that ``benchmarks/eval_jsbsim.py`` left in a work directory (``*-truth.npz`` with its
``*-replay/coefficients.csv``), on the replay's held-out segment, per force coefficient (``CY`` by
default) in m/s^2 of specific force (the coefficient times ``qbar S / m`` with JSBSim's qbar):

* ``meas``: the measured coefficient's error, % (as eval_jsbsim's ``meas``);
* ``prop``: what the accelerometer carries that the aerodynamic truth does not (JSBSim's total minus
  aerodynamic force: propulsion, gear), % of the aerodynamic signal;
* ``qbar``: the error the replay's airspeed puts into ``qbar`` (the measured coefficient rescaled by
  ``(V_est / V_true)^2``, change in points);
* ``mean``: the error's mean (the accelerometer bias the velocity filter left), m/s^2;
* ``err`` / ``sig``: the error's and the aerodynamic signal's RMS, m/s^2;
* ``floor``: :func:`~benchmarks.jsbsim_harness.scoring.wiener_floor`, the error of the best stationary
  linear smoother of the one accelerometer channel, with the signal's spectrum from the truth and the
  noise level read from the log's raw samples above 15 Hz, %.

The truth is read here to attribute errors; the pipeline never reads it.

Usage::

    python benchmarks/force_floor.py /tmp/baseline10/ej-pa28 /tmp/baseline10/ej-t6 [--coef CY] [--turbulence light]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.jsbsim_harness.scoring import white_noise_psd, wiener_floor  # noqa: E402
from benchmarks.jsbsim_harness.truth import load_truth  # noqa: E402
from gcs_sysid.telemetry import read_log  # noqa: E402

AXES = {"CX": ("x", "ax"), "CY": ("y", "ay"), "CZ": ("z", "az")}


def attribute(stem: Path, coef: str = "CY", noise_sigma: float | None = None) -> dict:
    """Error attribution of one flight (module docstring); ``stem`` is the path without ``-truth.npz``.

    ``noise_sigma`` (m/s^2 per sample at the log's rate), if given, replaces the noise level read from
    the log in ``floor`` (white noise: PSD ``2 sigma^2 dt``): the floor another accelerometer would
    set on the same flight (``benchmarks/imu_noise.py --floor``).

    Raises:
        FileNotFoundError: the truth, log or replay table is missing.
        ValueError: ``coef`` is not CX, CY or CZ.
    """
    if coef not in AXES:
        raise ValueError(f"coef must be one of {sorted(AXES)}, got '{coef}'")
    ax, field = AXES[coef]
    tr = load_truth(f"{stem}-truth.npz")
    F, c = tr.fields, tr.meta["constants"]
    D = np.genfromtxt(f"{stem}-replay/coefficients.csv", delimiter=",", names=True)
    t, h = D["time_s"], (D["held_out"] > 0) & np.isfinite(D[coef])
    ip = lambda k: np.interp(t, tr.t, F[k])  # noqa: E731
    qS, m = ip("qbar") * c["S"], c["mass"]
    aero, total = ip(f"F{ax}_aero") / qS, ip(f"F{ax}_total") / qS
    est = D[coef]
    e = lambda a, b: float(100 * np.sqrt(np.mean((a[h] - b[h]) ** 2)) / np.sqrt(np.mean(b[h] ** 2)))  # noqa: E731
    err = (est - aero) * qS / m
    imu = read_log(f"{stem}.tlog")["imu"]
    dt = float(np.median(np.diff(imu.t)))
    N = white_noise_psd(imu[field], dt) if noise_sigma is None else 2.0 * noise_sigma ** 2 * dt
    sel = tr.t >= t[h][0]
    sig = F[f"F{ax}_aero"][sel] / m
    floor = wiener_floor(sig, N, float(np.median(np.diff(tr.t))))
    sig_rms = float(np.sqrt(np.mean((aero * qS / m)[h] ** 2)))
    meas = e(est, aero)
    return {"flight": Path(stem).name, "meas": meas, "prop": e(total, aero),
            "qbar": e(est * (D["V"] / ip("V")) ** 2, aero) - meas, "mean": float(np.mean(err[h])),
            "err": float(np.sqrt(np.mean(err[h] ** 2))), "sig": sig_rms,
            "noise": float(np.sqrt(N / (2 * dt))), "floor": 100 * floor / sig_rms}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("work", nargs="+", help="eval_jsbsim work directories")
    ap.add_argument("--coef", default="CY", choices=sorted(AXES))
    ap.add_argument("--turbulence", default="light")
    a = ap.parse_args(argv)
    print(f"| flight | {a.coef} meas % | floor % | prop % | qbar pts | mean m/s^2 | err m/s^2 | signal m/s^2 |"
          " noise m/s^2 |")
    print("|---|---|---|---|---|---|---|---|---|")
    for w in a.work:
        for p in sorted(Path(w).glob(f"*-{a.turbulence}-s*-truth.npz")):
            stem = Path(str(p)[: -len("-truth.npz")])
            if not Path(f"{stem}-replay/coefficients.csv").exists():
                continue
            r = attribute(stem, a.coef)
            print(f"| {r['flight']} | {r['meas']:.2f} | {r['floor']:.2f} | {r['prop']:.2f} | {r['qbar']:+.2f} | "
                  f"{r['mean']:+.4f} | {r['err']:.4f} | {r['sig']:.3f} | {r['noise']:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
