"""Rows of the report's tables (shared by the HTML and Markdown renderers) and the CSV / JSON files."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..aero.table import COEFFICIENTS, FORCE_COEFFICIENTS, REGRESSORS
from ..errors import InputError
from ..result import ReplayResult
from .store import jsonable

__all__ = ["THESIS_FLOOR_PCT", "CSV_COLUMNS", "fmt", "fmt_axis", "facts", "stream_rows", "error_rows",
           "score_rows", "region_rows", "suggestion_rows", "gp_rows", "lengthscale_rows", "write_csv", "csv_data",
           "write_csv_data", "csv_measured_text", "write_suggestions_json", "correlation_of", "ANGLES", "CSV_MEASURED"]

#: Held-out error floor reported by the thesis this project follows (forces, moments), %.
THESIS_FLOOR_PCT = {"forces": 19.8, "moments": 23.8}
#: Columns of coefficients.csv.
CSV_COLUMNS = (["time_s", *REGRESSORS, *COEFFICIENTS] + [f"{c}_pred" for c in COEFFICIENTS]
               + [f"{c}_sigma" for c in COEFFICIENTS] + [f"{c}_sigma_obs" for c in COEFFICIENTS] + ["held_out"])
#: ``<C>_sigma``: 1-sigma of the coefficient itself at the row's estimated regressors (no white measurement
#: noise); ``<C>_sigma_obs``: of a new measurement (with it). Before the eleventh session ``<C>_sigma`` was the
#: latter and there was no ``<C>_sigma_obs``. docs/gp.md, "Two bands".
#: Regressors shown in degrees.
ANGLES = ("alpha", "beta", "delta_e", "delta_a", "delta_r")
#: coefficients.csv's leading columns that exist before the model: time, regressors, measured coefficients
CSV_MEASURED = 1 + len(REGRESSORS) + len(COEFFICIENTS)


def fmt(v: Any, nd: int = 3) -> str:
    """Number to text, '-' for missing / non-finite."""
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return f"{int(v):,}"
    try:
        f = float(v)
    except (TypeError, ValueError):
        return str(v)
    if not math.isfinite(f):
        return "-"
    return f"{f:.{nd}g}" if abs(f) >= 1e4 or (0 < abs(f) < 1e-3) else f"{f:.{nd}f}".rstrip("0").rstrip(".") or "0"


def fmt_axis(name: str, value: float) -> str:
    """A regressor value in display units (deg for angles, m/s for V)."""
    if name in ANGLES:
        return f"{math.degrees(value) + 0.0:.1f} deg".replace("-0.0 ", "0.0 ")
    if name == "V":
        return f"{value:.1f} m/s"
    return f"{value:.3f}"


def facts(r: ReplayResult) -> list[tuple[str, str]]:
    """Key facts of the run: (label, text)."""
    t = r.table.t
    dur = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    veh = ", ".join(f"{k} {v}" for k, v in r.vehicle.items()) or "-"
    win = " to ".join("open" if w is None else f"{w:g} s" for w in r.window)
    return [
        ("Log", r.log_path), ("Airframe", f"{r.airframe_name} ({r.airframe_path})"), ("Vehicle", veh),
        ("Window", win), ("Duration on the grid", f"{dur:.1f} s at {r.states.rate_hz:g} Hz ({len(t):,} rows)"),
        ("Valid rows", f"{int(r.table.valid.sum()):,}"), ("Training rows", f"{int(r.train.sum()):,}"),
        ("Held-out rows", f"{int(r.held_out.sum()):,}"
         + (f" ({t[r.held_out][0]:.1f}-{t[r.held_out][-1]:.1f} s)" if r.held_out.any() else "")),
        ("Model state", r.model_path or "not saved"),
    ]


def stream_rows(r: ReplayResult) -> list[dict[str, str]]:
    """Per-stream decode summary."""
    rows = []
    for s in sorted(r.summaries.values(), key=lambda s: s.name):
        gap_s = sum(b - a for a, b in s.gaps)
        rows.append({"stream": s.name, "source": s.source, "count": fmt(s.count), "rate (Hz)": fmt(s.rate_hz, 2),
                     "from (s)": fmt(s.t_start, 1), "to (s)": fmt(s.t_end, 1),
                     "gaps": f"{len(s.gaps)} ({gap_s:.1f} s)" if s.gaps else "0", "dropped": fmt(s.dropped)})
    return rows


def error_rows(r: ReplayResult) -> list[dict[str, str]]:
    """Held-out error per coefficient, 100 RMS(est - ref) / RMS(ref), against the thesis floor."""
    rows = []
    for c in COEFFICIENTS:
        m = r.metrics.get(c, {})
        ok, why = r.identifiable.get(c, (True, ""))
        floor = THESIS_FLOOR_PCT["forces" if c in FORCE_COEFFICIENTS else "moments"]
        e = m.get("error_pct_heldout", float("nan"))
        if not ok:
            verdict = f"not identified: {why}"
        elif e is None or not math.isfinite(float(e)):
            verdict = "no held-out prediction"
        else:
            verdict = "within thesis floor" if e <= floor else "above thesis floor"
        rows.append({"coefficient": c, "held-out error (%)": fmt(e, 1),
                     "training error (%)": fmt(m.get("error_pct_train"), 1),
                     "thesis floor (%)": fmt(floor, 1), "RMS measured": fmt(m.get("rms_measured"), 4),
                     "held-out rows": fmt(m.get("n_heldout")), "verdict": verdict})
    return rows


def score_rows(r: ReplayResult) -> list[dict[str, str]]:
    """Confidence score and flagged-region count per coefficient."""
    env = r.envelope
    if env is None:
        return []
    return [{"coefficient": c, "confidence score": fmt(env.scores.get(c), 2), "RMS spread": fmt(env.spread.get(c), 4),
             "flag threshold (sigma/spread)": fmt(env.thresholds.get(c), 2),
             "flagged regions": fmt(len(env.regions_of(c)))} for c in env.weakest()]


def region_rows(r: ReplayResult, limit: int = 30) -> list[dict[str, str]]:
    """Flagged regions, most uncertain first; regions of one slice with the same bounds share a row."""
    env = r.envelope
    if env is None:
        return []
    merged: dict[tuple, list] = {}
    for g in env.regions:
        key = (g.axes, tuple((k, round(a, 9), round(b, 9)) for k, (a, b) in sorted(g.bounds.items())))
        merged.setdefault(key, []).append(g)
    rows = []
    for gs in list(merged.values())[:limit]:
        g = gs[0]
        rows.append({"coefficients": ", ".join(x.coefficient for x in gs), "slice": f"{g.axes[0]} x {g.axes[1]}",
                     "bounds": "; ".join(f"{k} {fmt_axis(k, a)} .. {fmt_axis(k, b)}" for k, (a, b) in g.bounds.items()),
                     "mean sigma/spread": fmt(max(x.mean_rel_sigma for x in gs), 2), "samples": fmt(g.n_points),
                     "cells": fmt(g.n_cells), "reason": g.reason})
    return rows


def suggestion_rows(r: ReplayResult) -> list[dict[str, str]]:
    """Ranked maneuver suggestions."""
    rows = []
    for s in r.suggestions:
        fc = s.flight_condition
        rows.append({"rank": str(s.rank), "coefficients": ", ".join(s.coefficients), "maneuver": s.kind,
                     "surfaces": " + ".join({"delta_e": "elevator", "delta_a": "aileron", "delta_r": "rudder"}[c]
                                            for c in s.controls),
                     "amplitude (deg)": ", ".join(f"{math.degrees(a):.1f}" for a in s.amplitudes_rad.values()),
                     "pulse (s)": "-" if s.kind == "multisine" else fmt(s.pulse_width_s, 2),
                     "duration (s)": fmt(s.duration_s, 1),
                     "V (m/s)": fmt(fc.get("V"), 1), "alpha (deg)": fmt(fc.get("alpha_deg"), 1),
                     "peak p/q/r (deg/s)": "/".join(f"{s.expected[k]:.0f}"
                                                    for k in ("p_max_dps", "q_max_dps", "r_max_dps"))
                     if s.expected else "-",
                     "load factor (g)": f"{s.expected['n_min']:.2f}-{s.expected['n_max']:.2f}" if s.expected else "-",
                     "expected variance reduction": (f"{100 * s.expected_reduction:.2g} %" if s.expected_reduction < 0.1
                                                     else f"{100 * s.expected_reduction:.0f} %")})
    return rows


def gp_rows(r: ReplayResult) -> list[tuple[str, str]]:
    """Scalar facts of the GP summary."""
    out = []
    for k, v in r.gp_summary.items():
        if isinstance(v, (str, int, float, bool)) or v is None:
            out.append((k, fmt(v, 4) if not isinstance(v, str) else v))
        elif isinstance(v, list) and all(isinstance(x, str) for x in v):
            out.append((k, ", ".join(v) or "-"))
    return out


def lengthscale_rows(r: ReplayResult) -> list[dict[str, str]]:
    """Length-scales per input (global and local GP), data units."""
    g = r.gp_summary.get("global") or {}
    loc = r.gp_summary.get("local") or {}
    gl = g.get("lengthscales", r.gp_summary.get("lengthscales"))
    ll = loc.get("lengthscales") if isinstance(loc, dict) else None
    if gl is None:
        return []
    names = list(gl) if isinstance(gl, dict) else list(r.gp_summary.get("inputs", REGRESSORS))
    gv = list(gl.values()) if isinstance(gl, dict) else list(gl)
    rows = []
    for i, n in enumerate(names):
        row = {"input": n, "global length-scale": fmt(gv[i] if i < len(gv) else None, 4)}
        if isinstance(ll, dict):
            row["local length-scale"] = fmt(ll.get(n), 4)
        rows.append(row)
    return rows


def csv_data(t: np.ndarray, X: np.ndarray, Y: np.ndarray, pred_mean: np.ndarray, pred_sigma: np.ndarray,
             pred_sigma_obs: np.ndarray, held_out: np.ndarray) -> np.ndarray:
    """The values of coefficients.csv, ``(N, len(CSV_COLUMNS))``: ``t (N,)`` [s], the regressors ``X (N, 10)``,
    the measured coefficients ``Y (N, 6)``, the model's mean, sigma and sigma_obs ``(N, 6)`` each and the
    held-out mask ``(N,)`` as 0/1, side by side (a :class:`~gcs_sysid.result.ReplayResult`'s arrays)."""
    return np.column_stack([t, X, Y, pred_mean, pred_sigma, pred_sigma_obs, np.asarray(held_out).astype(float)])


def write_csv(r: ReplayResult, path: Path) -> Path:
    """coefficients.csv: one row per grid time (columns :data:`CSV_COLUMNS`; NaN written as ``nan``)."""
    tb = r.table
    return write_csv_data(csv_data(tb.t, tb.X, tb.Y, r.pred_mean, r.pred_sigma, r.pred_sigma_obs, r.held_out), path)


def csv_measured_text(t: np.ndarray, X: np.ndarray, Y: np.ndarray) -> list[str]:
    """Each row's first :data:`CSV_MEASURED` fields of coefficients.csv as :func:`write_csv` writes them
    (time, the regressors ``X (N, 10)``, the measured coefficients ``Y (N, 6)``; ``t (N,)`` [s]): they
    exist before the model, so the pipeline's worker formats them while the GP is fitted."""
    fmt = ",".join(["%.4f"] + ["%.7g"] * (CSV_MEASURED - 1))
    return [fmt % tuple(row) for row in np.column_stack([t, X, Y]).tolist()]


def write_csv_data(data: np.ndarray, path: str | Path, measured: list[str] | None = None) -> Path:
    """Write coefficients.csv from :func:`csv_data`'s ``(N, len(CSV_COLUMNS))`` array to ``path``; the same
    file as :func:`write_csv` (the pipeline writes it with the measured fields its worker process formatted while
    the GP was fitted, while the worker draws the last figures).

    Args:
        data: :func:`csv_data`'s array.
        path: the file written.
        measured: :func:`csv_measured_text` of the same rows (their first :data:`CSV_MEASURED` fields,
            already formatted), or None to format every field here.

    Raises:
        InputError: ``measured`` not one string per row.
    """
    path = Path(path)
    # one %-format per row (as numpy.savetxt does) is several times faster than csv.writer with
    # per-value f-strings; same text, same "\r\n" line ends as csv.writer. %-formatting is field by
    # field, so a row formatted in two parts joined by "," is the same text
    if measured is None:
        fmt = ",".join(["%.4f"] + ["%.7g"] * (data.shape[1] - 2) + ["%d"])
        lines = [fmt % tuple(row) + "\r\n" for row in data.tolist()]
    else:
        if len(measured) != len(data):
            raise InputError(f"write_csv_data: {len(measured)} formatted rows for {len(data)} rows")
        fmt = ",".join(["%.7g"] * (data.shape[1] - CSV_MEASURED - 1) + ["%d"])
        lines = [m + "," + fmt % tuple(row) + "\r\n" for m, row in zip(measured, data[:, CSV_MEASURED:].tolist())]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(CSV_COLUMNS)
        f.write("".join(lines))
    return path


def write_suggestions_json(r: ReplayResult, path: Path) -> Path:
    """suggestions.json: ranked suggestions, flagged regions and confidence scores (schema: docs/report.md)."""
    env = r.envelope
    doc = {
        "log": r.log_path, "airframe": r.airframe_name,
        "scores": env.scores if env is not None else {},
        "weakest_first": env.weakest() if env is not None else [],
        "suggestions": [s.to_dict() for s in r.suggestions],
        "regions": [g.to_dict() for g in env.regions] if env is not None else [],
        "not_identified": {c: why for c, (ok, why) in r.identifiable.items() if not ok},
        **{k: v for k, v in (getattr(r.suggestions, "context", None) or {}).items()},
    }
    path.write_text(json.dumps(jsonable(doc), indent=1, allow_nan=False))
    return path


def correlation_of(gp_summary: dict, outputs: list[str]) -> tuple[np.ndarray, list[str]] | None:
    """The GP's output correlation matrix and its names from a model summary, or None."""
    g = gp_summary.get("global") or {}
    corr = g.get("output_correlation", gp_summary.get("output_correlation"))
    names = list(gp_summary.get("outputs") or outputs)
    if corr is None or len(names) != np.asarray(corr).shape[0]:
        return None
    return np.asarray(corr, float), names
