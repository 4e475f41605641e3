"""How a harness flight was flown, from its truth file only: envelope, excitation per axis, energy.

What a flight-test engineer checks before trusting a system-identification flight (Morelli and
Klein, *Aircraft System Identification*, 2nd ed., 2016, ch. 9: inputs that excite every axis
while the aircraft stays near the condition being identified): the alpha and sideslip flown,
bank, airspeed, angular rates, how much each axis was excited (the standard deviation of the
rates and of the surfaces, also on the replay's held-out last 20 %), the knock-it-offs, and the
sink rate. It reads the ``-truth.npz`` the pipeline never reads and none of the pipeline's output,
so it may be used to set up an untouched aircraft (``docs/jsbsim.md``, J3Cub).

Usage::

    python -m benchmarks.jsbsim_harness.envelope DIR [DIR ...]     # one line per *-truth.npz
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

__all__ = ["flight_envelope", "format_envelope"]

HELD_OUT_SHARE = 0.2     # the replay's held-out segment: the last 20 % of the logged flight


def flight_envelope(truth_path: str | Path) -> dict:
    """The envelope and excitation of one flight from its truth file.

    Args:
        truth_path: a ``<stem>-truth.npz`` written by :func:`~benchmarks.jsbsim_harness.truth.save_truth`.

    Returns:
        dict (degrees, deg/s, m/s): ``alpha`` and ``beta`` (min, max) and 1st/99th percentiles
        ``alpha_p``/``beta_p``; ``bank_max``; ``V`` (min, max); ``rate_max`` (p, q, r) of the
        absolute rates; ``rate_std`` and ``rate_std_held`` (p, q, r) on the whole flight and the
        held-out last 20 %; ``surface_std`` (delta_e, delta_a, delta_r); ``aborts`` (the
        knock-it-offs flown, ``Recording.meta["aborts"]``); ``sink_mps`` (mean height lost per second).

    Raises:
        KeyError: the file is not a harness truth file (a field is missing).
    """
    with np.load(truth_path) as z:
        meta = json.loads(str(z["meta"]))
        t = z["t"]
        f = {k: np.asarray(z[k]) for k in ("alpha", "beta", "phi", "V", "p", "q", "r", "delta_e", "delta_a",
                                           "delta_r", "alt")}
    d = np.degrees
    held = t >= (1.0 - HELD_OUT_SHARE) * meta["config"]["duration_s"]
    rates = [d(f[k]) for k in ("p", "q", "r")]
    a, b = d(f["alpha"]), d(f["beta"])
    return {"alpha": (float(a.min()), float(a.max())), "alpha_p": tuple(float(x) for x in np.percentile(a, [1, 99])),
            "beta": (float(b.min()), float(b.max())), "beta_p": tuple(float(x) for x in np.percentile(b, [1, 99])),
            "bank_max": float(d(np.abs(f["phi"])).max()), "V": (float(f["V"].min()), float(f["V"].max())),
            "rate_max": tuple(float(np.abs(x).max()) for x in rates),
            "rate_std": tuple(float(x.std()) for x in rates),
            "rate_std_held": tuple(float(x[held].std()) for x in rates),
            "surface_std": tuple(float(d(f[k]).std()) for k in ("delta_e", "delta_a", "delta_r")),
            "aborts": list(meta.get("aborts", [])),
            "sink_mps": float((f["alt"][0] - f["alt"][-1]) / (t[-1] - t[0]))}


def format_envelope(name: str, e: dict) -> str:
    """One line of :func:`flight_envelope`'s result."""
    three = lambda x, fmt="{:.1f}": "/".join(fmt.format(v) for v in x)   # noqa: E731
    return (f"{name:44s} alpha {e['alpha'][0]:5.1f}..{e['alpha'][1]:4.1f} "
            f"({e['alpha_p'][0]:.1f}..{e['alpha_p'][1]:.1f})"
            f" beta {e['beta'][0]:5.1f}..{e['beta'][1]:4.1f} bank {e['bank_max']:3.0f} "
            f"V {e['V'][0]:4.1f}-{e['V'][1]:4.1f}"
            f" |pqr| {three(e['rate_max'], '{:.0f}')} std pqr {three(e['rate_std'])} (held {three(e['rate_std_held'])})"
            f" std surf {three(e['surface_std'], '{:.2f}')} sink {e['sink_mps']:.2f} aborts {len(e['aborts'])}")


def main(argv=None) -> int:   # pragma: no cover - thin CLI
    paths = [p for d in (argv if argv is not None else sys.argv[1:]) for p in sorted(Path(d).glob("*-truth.npz"))]
    if not paths:
        print("envelope: no *-truth.npz in the folders given", file=sys.stderr)
        return 2
    for p in paths:
        print(format_envelope(p.name[: -len("-truth.npz")], flight_envelope(p)))
    return 0


if __name__ == "__main__":   # pragma: no cover
    raise SystemExit(main())
