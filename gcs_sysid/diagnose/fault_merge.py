"""Telemetry faults meet the coefficient-level causes: fold, set aside, one failure at a time.

A fault read from the servo outputs (:mod:`gcs_sysid.diagnose.faults`) and a ``stuck:<u>`` found
in the coefficients can be the same failure, a consequence of it, or a coefficient-level
explanation the telemetry contradicts; these functions decide which, and say why.
"""

from __future__ import annotations

import numpy as np

from .context import DiagContext

__all__ = ["merge_faults", "set_aside_answering"]


def _response(ctx: DiagContext, u: str, m: np.ndarray) -> float:
    """How well the axis rate (or its derivative) follows control ``u`` on rows ``m``: max |correlation|."""
    axis = {"delta_a": 0, "delta_e": 1, "delta_r": 2}[u]
    w = ctx.rates()[:, axis]
    x = ctx.x(u)
    best = 0.0
    for y in (w, np.gradient(w, ctx.t)):
        if m.sum() >= 20 and np.std(x[m]) > 0 and np.std(y[m]) > 0:
            best = max(best, abs(float(np.corrcoef(x[m], y[m])[0, 1])))
    return best


def set_aside_answering(ctx: DiagContext, findings: list[dict], faults: list[dict], window_s: float = 30.0,
                     min_before: float = 0.3, keep_ratio: float = 0.5):
    """Drop a coefficient-level ``stuck:<u>`` when the telemetry shows the aircraft still answering ``u``.

    With the servo outputs in the log and no telemetry fault on ``u``, a surface that stopped
    following its command would also stop driving its axis: the body rate (or its derivative)
    would no longer correlate with the logged command after the onset. If it still does, with at
    least ``keep_ratio`` of the correlation of the ``window_s`` before (itself at least
    ``min_before``), the coefficient-level finding is set aside (returned with its evidence).
    """
    keep, rejected = [], []
    faulted = {f["cause"] for f in faults}
    for f in findings:
        u = f["cause"].split(":", 1)[1] if f["cause"].startswith("stuck:") else None
        if u is None or f["cause"] in faulted or f.get("onset_s") is None or u not in ("delta_a", "delta_e", "delta_r"):
            keep.append(f)
            continue
        t0 = f["onset_s"]
        before = _response(ctx, u, ctx.valid & (ctx.t >= t0 - window_s) & (ctx.t < t0))
        after = _response(ctx, u, ctx.valid & (ctx.t >= t0) & (ctx.t < t0 + window_s))
        if before >= min_before and after >= keep_ratio * before:
            rejected.append({"cause": f["cause"], "onset_s": t0, "gain": f["gain"], "response_before": before,
                             "response_after": after, "why": f"the aircraft still answers {u} after the onset "
                             f"(|corr| {after:.2f} against {before:.2f} before) and its servo output kept moving"})
        else:
            f["evidence"]["response_before_after"] = [before, after]
            keep.append(f)
    return keep, rejected


def merge_faults(findings: list[dict], faults: list[dict]) -> list[dict]:
    """Add the telemetry faults; a coefficient-level ``stuck:`` of the same control becomes their evidence.

    The telemetry says which servo froze and when; a coefficient-level ``stuck:<u>`` naming
    the same control is the same fault seen through the aerodynamics and is folded in.
    """
    out = list(findings)
    for fault in faults:
        same = [f for f in out if f["cause"] == fault["cause"]]
        for f in same:
            fault["evidence"]["coefficient_level"] = {"estimate": f["estimate"], "onset_s": f.get("onset_s"),
                                                      "gain": f["gain"]}
            fault["gain"] = dict(f["gain"])
            out.remove(f)
        out.append(fault)
    if faults:
        # one failure at a time: a coefficient-level stuck surface whose servo the telemetry shows moving,
        # with its onset after the first fault, is that fault's aftermath seen through the aerodynamics
        first = min(faults, key=lambda f: f["onset_s"])
        for f in [f for f in out if f.get("kind") != "fault" and f["cause"].startswith("stuck:")
                  and f.get("onset_s") is not None and f["onset_s"] >= first["onset_s"] - 3.0]:
            first["evidence"].setdefault("after_it", []).append(
                {"cause": f["cause"], "onset_s": f["onset_s"], "gain": f["gain"],
                 "note": "seen in the coefficients only (its servo kept moving), after this fault"})
            out.remove(f)
    return out
