"""Save a :class:`~gcs_sysid.result.ReplayResult` as ``result.npz`` (arrays) + ``result.json`` (the rest).

No pickle: the npz is read with ``allow_pickle=False`` and the JSON holds plain values, so a saved
run can be re-rendered (``write_report(load_result(path), out)``) without recomputing and without
trusting executable content.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..aero.table import CoefficientTable
from ..envelope import EnvelopeMap
from ..errors import InputError
from ..estimation.states import FlightStates
from ..maneuvers import Suggestion, SuggestionList
from ..result import ReplayResult
from ..telemetry.types import StreamSummary

__all__ = ["save_result", "load_result", "jsonable", "FORMAT_VERSION"]

FORMAT_VERSION = 1


def jsonable(x: Any) -> Any:
    """Plain JSON values: numpy scalars and arrays unwrapped, non-finite floats as None, tuples as lists."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(float(x)) else None
    if x is None or isinstance(x, str):
        return x
    if hasattr(x, "to_dict"):
        return jsonable(x.to_dict())
    return str(x)


def _nan(v: Any) -> float:
    return float("nan") if v is None else float(v)


def _savez_fast(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """``numpy.savez`` (stored, not deflated) without pickling: the float arrays of a flight
    deflate by only ~23 % (19 MB to 15 MB for a 10-minute 50 Hz flight) and deflating them cost
    ~0.35 s of the report stage, so they are stored as they are. Read by ``numpy.load``."""
    import zipfile

    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as zf:
        for k, v in arrays.items():
            with zf.open(f"{k}.npy", "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asarray(v), allow_pickle=False)


def save_result(result: ReplayResult, path: str | Path) -> dict[str, Path]:
    """Write ``path/result.json`` and ``path/result.npz`` (directory created).

    Returns:
        ``{"result_json": Path, "result_npz": Path}``.
    """
    out = Path(path)
    out.mkdir(parents=True, exist_ok=True)
    st, tb = result.states, result.table
    arrays: dict[str, np.ndarray] = {
        "states_t": st.t, "table_t": tb.t, "table_X": tb.X, "table_Y": tb.Y, "table_valid": tb.valid,
        "table_qbar": tb.qbar, "held_out": result.held_out, "train": result.train,
        "pred_mean": result.pred_mean, "pred_sigma": result.pred_sigma, "pred_sigma_obs": result.pred_sigma_obs,
    }
    if st.valid is not None:
        arrays["states_valid"] = st.valid
    for k, v in st.data.items():
        arrays[f"states__{k}"] = np.asarray(v)
    for k, v in st.sigma.items():
        arrays[f"sigma__{k}"] = np.asarray(v)
    npz = out / "result.npz"
    _savez_fast(npz, arrays)
    doc = {
        "format": "gcs-sysid ReplayResult", "version": FORMAT_VERSION,
        "log_path": result.log_path, "airframe_name": result.airframe_name, "airframe_path": result.airframe_path,
        "vehicle": result.vehicle, "window": list(result.window),
        "summaries": [{**s.__dict__, "gaps": [list(g) for g in s.gaps]} for s in result.summaries.values()],
        "messages": result.messages, "metrics": result.metrics,
        "identifiable": {k: [bool(v[0]), str(v[1])] for k, v in result.identifiable.items()},
        "envelope": result.envelope.to_dict() if result.envelope is not None else None,
        "suggestions": [s.to_dict() for s in result.suggestions],
        "suggestion_context": getattr(result.suggestions, "context", {}), "gp_summary": result.gp_summary,
        "model_path": result.model_path, "missing": result.missing, "notes": result.notes,
        "timings": result.timings,
        "states": {"rate_hz": st.rate_hz, "sources": st.sources, "missing": st.missing, "notes": st.notes},
        "table": {"notes": tb.notes},
    }
    js = out / "result.json"
    # no indent: json's C encoder only runs without it (several times faster on the envelope grids)
    js.write_text(json.dumps(jsonable(doc), allow_nan=False, separators=(",", ":")))
    return {"result_json": js, "result_npz": npz}


def load_result(path: str | Path) -> ReplayResult:
    """Read a result written by :func:`save_result`.

    Raises:
        InputError: files missing or not a saved gcs-sysid result.
    """
    p = Path(path)
    js, npz = p / "result.json", p / "result.npz"
    if not js.is_file() or not npz.is_file():
        raise InputError(f"{p}: not a saved result (expected result.json and result.npz)")
    try:
        doc = json.loads(js.read_text())
    except (OSError, ValueError) as e:
        raise InputError(f"{js}: cannot read saved result ({e.__class__.__name__})") from None
    if doc.get("format") != "gcs-sysid ReplayResult":
        raise InputError(f"{js}: not a gcs-sysid result file (field 'format')")
    with np.load(npz, allow_pickle=False) as z:
        a = {k: z[k] for k in z.files}
    sm = doc["states"]
    states = FlightStates(a["states_t"], float(sm["rate_hz"]),
                          {k[8:]: v for k, v in a.items() if k.startswith("states__")},
                          {k[7:]: v for k, v in a.items() if k.startswith("sigma__")},
                          a.get("states_valid"), dict(sm["sources"]), list(sm["missing"]), list(sm["notes"]))
    table = CoefficientTable(a["table_t"], a["table_X"], a["table_Y"], a["table_valid"].astype(bool),
                             a["table_qbar"], list(doc["table"]["notes"]))
    summaries = {}
    for s in doc["summaries"]:
        summaries[s["name"]] = StreamSummary(s["name"], s["source"], int(s["count"]), _nan(s["rate_hz"]),
                                             _nan(s["t_start"]), _nan(s["t_end"]),
                                             [(float(g[0]), float(g[1])) for g in s["gaps"]], int(s["dropped"]))
    metrics = {c: {k: _nan(v) if k.startswith(("error", "rms")) else (v if v is not None else float("nan"))
                   for k, v in m.items()} for c, m in doc["metrics"].items()}
    env = EnvelopeMap.from_dict(doc["envelope"]) if doc.get("envelope") else None
    window = tuple(None if v is None else float(v) for v in doc["window"])
    if "pred_sigma_obs" in a:
        sigma, sigma_obs = a["pred_sigma"], a["pred_sigma_obs"]
    else:       # saved before the eleventh session: its pred_sigma was the band for a new measurement
        sigma, sigma_obs = np.full(a["pred_sigma"].shape, np.nan), a["pred_sigma"]
    return ReplayResult(
        log_path=doc["log_path"], airframe_name=doc["airframe_name"], airframe_path=doc["airframe_path"],
        vehicle=dict(doc["vehicle"]), window=window, summaries=summaries, messages=dict(doc["messages"]),
        states=states, table=table, held_out=a["held_out"].astype(bool), train=a["train"].astype(bool),
        pred_mean=a["pred_mean"], pred_sigma=sigma, pred_sigma_obs=sigma_obs, metrics=metrics,
        identifiable={k: (bool(v[0]), str(v[1])) for k, v in doc["identifiable"].items()}, envelope=env,
        suggestions=SuggestionList([Suggestion.from_dict(s) for s in doc["suggestions"]],
                                   doc.get("suggestion_context") or {}), gp_summary=dict(doc["gp_summary"]),
        model_path=doc["model_path"], missing=list(doc["missing"]), notes=list(doc["notes"]),
        timings={k: _nan(v) for k, v in doc["timings"].items()},
    )
