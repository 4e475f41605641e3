"""What a JSBSim flight resolves of a pitot bias: the airspeed check's resolution on the harness (issue 9; analysis).

For each aircraft this script flies (or reuses) the clean reference flight and one test flight with a given pitot
bias (0: clean) on a given plan (``sweep``: one heading, the roster's plan; ``sweep_turn``: the heading-sweep form of
the cloverleaf), diagnoses it as ``eval_jsbsim_diagnose`` does, and prints the wind triangle of the flight and of the
reference (bias, stated standard error, the scatter part ``residual_rms / sqrt(n_eff)``, heading span), the change
since the reference against the injected bias, and the report's resolution
(:func:`gcs_sysid.diagnose.pitot.pitot_resolution`: the smallest change the flight could name, the wind estimate's
and the scatter's shares, the advice). With several clean aircraft, the change's ``z = change / std_error`` says how
well the stated standard error holds (truth: no change). Measured in ``docs/benchmarks.md``, "Fifty-third session,
lead".

Usage::

    python benchmarks/pitot_resolution.py --plan sweep_turn --seed 71 --out DIR --aircraft c172x dr1 [--bias 1.0]
        [--json F]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import eval_jsbsim_diagnose as E  # noqa: E402
from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.jsbsim_harness.effects import Effect  # noqa: E402

_WT: dict = {}


def _keep_wind_triangle(summary):
    """Wrap ``eval_jsbsim_diagnose._pitot_summary`` so that the whole wind-triangle document is kept too."""
    def wrapped(data: dict) -> dict:
        _WT.clear()
        _WT.update((data.get("pitot") or {}).get("wind_triangle") or {})
        return summary(data)
    return wrapped


def _triangle_line(label: str, c: dict) -> str:
    scatter = c["residual_rms_mps"] / np.sqrt(c["n_eff"]) if c.get("n_eff") else float("nan")
    return (f"  {label:<10s} bias {c['bias_mps']:+.2f} +- {c['std_error']:.3f} m/s, scatter {scatter:.3f} "
            f"(residual {c['residual_rms_mps']:.2f} m/s RMS, n_eff {c['n_eff']:.0f}), "
            f"span {c['heading_span_deg']:.0f} deg")


def run_case(ac: str, seed: int, bias: float, plan: str, out: Path) -> dict:
    """Diagnose one flight; returns its record (triangles, change, fused, resolution, what was named)."""
    d = out / f"{plan}-{ac}"
    files, model_path, ref = E.reference_model(ac, d, plan=plan)
    effects = [Effect("bias:airspeed", bias)] if bias else []
    findings, _, _ = E.diagnose_case(ac, seed, effects, d, model_path, ref, plan=plan)
    wt = dict(_WT)
    ch, fu, res = wt.get("change") or {}, wt.get("fused") or {}, wt.get("resolution") or {}
    rec = {"aircraft": ac, "seed": seed, "plan": plan, "bias_mps": bias,
           "named": [f["cause"] for f in findings], "flight": wt.get("flight"), "references": wt.get("references"),
           "change_mps": ch.get("change_mps"), "change_se": ch.get("std_error"),
           "z": (ch["change_mps"] - bias) / ch["std_error"] if ch.get("std_error") else None,
           "fused_mps": fu.get("estimate"), "fused_se": fu.get("std_error"),
           "refit": bool(wt.get("coefficients_rereduced")), "why": wt.get("why"), "resolution": res}
    print(f"{ac} s{seed} {plan} bias {bias:g} m/s: named {rec['named'] or 'nothing'}; why: {rec['why']}")
    if wt.get("flight"):
        print(_triangle_line("flight", wt["flight"]))
    for r in wt.get("references") or []:
        print(_triangle_line("reference", r))
    if ch:
        print(f"  change {ch['change_mps']:+.2f} +- {ch['std_error']:.2f} m/s (z against the injected {rec['z']:+.2f})")
    if res:
        print(f"  resolution: {res['summary']}\n  advice: {res['advice']}")
    sys.stdout.flush()
    return rec


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--aircraft", nargs="+", required=True)
    p.add_argument("--seed", type=int, default=71)
    p.add_argument("--bias", type=float, default=0.0, help="injected pitot bias, m/s (0: clean flights)")
    p.add_argument("--plan", default="sweep", choices=("sweep", "sweep_turn"))
    p.add_argument("--out", type=Path, required=True, help="flight and model folder (reused)")
    p.add_argument("--json", type=Path, default=None, help="append one record per case (JSON lines)")
    a = p.parse_args(argv)
    E.SENSOR_DRAW = E.TURBULENCE_DRAW = "per_aircraft"       # as the roster flies
    E._pitot_summary = _keep_wind_triangle(E._pitot_summary)
    z = []
    for ac in a.aircraft:
        rec = run_case(ac, a.seed, a.bias, a.plan, a.out)
        if a.json is not None:
            append_jsonl(str(a.json), [rec])
        if rec["z"] is not None:
            z.append(rec["z"])
    if len(z) > 1:
        z = np.array(z)
        print(f"{len(z)} flights: change z RMS {np.sqrt(np.mean(z ** 2)):.2f}, SD {np.std(z, ddof=1):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
