"""The report of a live session: ``session.json`` (the data) and ``report.md`` (its rendering)."""

from __future__ import annotations

import json
import math
from pathlib import Path

__all__ = ["write_session_report", "render_markdown"]


def _clean(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    return x


def render_markdown(snap: dict) -> str:
    """Markdown rendering of a session snapshot (``session.json``)."""
    lines = ["# gcs-sysid live session", "",
             f"- link: `{snap['connection']}`, vehicle: {snap.get('vehicle')}",
             f"- packets received and kept in `raw.tlog`: {snap['raw_records']} "
             f"(corrupt byte runs skipped: {snap['bad_data']}; missed by sequence number: {snap['seq_lost']})",
             f"- ended by: {'Ctrl-C' if snap.get('interrupted') else 'end of duration'}"]
    if snap.get("can"):
        c = snap["can"]
        lines.append(f"- CAN: {c['frames']} frames in `{c['log']}`, DroneCAN transfers {c['transfers']}, "
                     f"failed {c['bad']}")
        src = snap.get("control_sources") or {}
        measured = [k for k, v in src.items() if "DroneCAN" in v]
        lines.append("- controls measured by DroneCAN actuators (latest window): "
                     + (", ".join(measured) if measured else "none (no [[can_actuator]] map, or no actuator "
                        "in the data: commanded PWM used)"))
    if "samples_learned" in snap:
        lines.append(f"- samples learned: {snap['samples_learned']} in {snap['steps']} steps; "
                     f"model: `{snap.get('model', 'none (too few samples)')}`")
        ar = snap.get("air_roll") or {}
        if ar.get("state", "off") != "off":
            lines.append(f"- the air-rate pair (Cl's target at the air-relative roll rate, `--air-roll on`): "
                         f"{ar['state']}" + (f"; {ar['rows_moved']} rows learned with a moved Cl"
                                            if ar.get("rows_moved") is not None else "")
                         + (f" ({ar['note']})" if ar.get("note") else ""))
        ll = snap.get("lift_line") or {}
        if ll.get("state", "off") != "off":
            lines.append(f"- the lift line carried across windows (`--lift-line on`): {ll['state']}"
                         + (f" ({ll['note']})" if ll.get("note") else ""))
        ap = snap.get("air_pitch") or {}
        if ap.get("state", "off") != "off":
            lines.append(f"- the air-relative pitch rate (`--air-pitch`, on by default): {ap.get('applied', 0)} of "
                         f"{ap.get('windows', 0)} windows moved" + (f" ({ap['note']})" if ap.get("note") else ""))
        se = snap.get("stated_errors") or {}
        if se.get("note"):
            lines.append(f"- the model's band at exact conditions (`gcs-sysid predict`): {se['note']}")
        if snap.get("steps_coalesced") or snap.get("map_refreshes_deferred"):
            lines.append(f"- the learner fell behind: {snap.get('steps_coalesced', 0)} steps coalesced, "
                         f"{snap.get('map_refreshes_deferred', 0)} map refreshes deferred (to replay `raw.tlog` on the "
                         "same schedule pass `coalesced_at_us` to `learn_from_tlog`)")
    lines += ["", "## Rates", "", "| message | mean received Hz | asked Hz | request | short at check |",
              "|---|---|---|---|---|"]
    asked, mean = snap.get("asked", {}), snap.get("mean_rates", {})
    short = snap.get("shortfalls", {})
    for n in sorted(set(asked) | set(mean)):
        s = f"{short[n][1]:.1f} Hz" if n in short else ""
        lines.append(f"| {n} | {mean.get(n, 0.0):.1f} | {asked.get(n, '')} | {snap['requests'].get(n, '')} | {s} |")
    if snap.get("costs"):
        lines += ["", "What the rates cost:", ""] + [f"- {c}" for c in snap["costs"]]
    if snap.get("confidence"):
        lines += ["", "## Confidence", "", "| coefficient | score |", "|---|---|"]
        lines += [f"| {k} | {v:.2f} |" for k, v in snap["confidence"].items() if v is not None]
    if snap.get("top_suggestion"):
        lines += ["", "## Next maneuver", "", snap["top_suggestion"]]
    notes = list(snap.get("events", [])) + list(snap.get("learner_notes", []))
    if notes:
        lines += ["", "## What happened", ""] + [f"- {n}" for n in notes]
    return "\n".join(lines) + "\n"


def write_session_report(snap: dict, out_dir: str | Path) -> None:
    """Write ``session.json`` and ``report.md`` into ``out_dir``."""
    out = Path(out_dir)
    clean = _clean(snap)
    (out / "session.json").write_text(json.dumps(clean, indent=1, default=str))
    (out / "report.md").write_text(render_markdown(clean))
