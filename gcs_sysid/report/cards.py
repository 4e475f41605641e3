"""Fly-next test cards: one card per suggested test point (report head, printable HTML / Markdown),
the limits and quality gate around them, and the plan file that flies them.

A card holds what a flight-test engineer briefs: the condition (V, altitude band, 1-g trim alpha),
the input (kind, surfaces, amplitude in deg, pulse / period and total duration), the expected
response (peak p q r in deg/s, alpha, bank, load factor), why it is flown and what it will reduce.
"""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import Any

from ..result import ReplayResult

__all__ = ["context_of", "card_fields", "limit_rows", "gate_rows", "group_rows", "cards_markdown", "cards_html",
           "render_testcards_md", "render_testcards_html", "write_flynext_plan", "CARDS_CSS"]


def context_of(r: ReplayResult) -> dict[str, Any]:
    """The suggestion list's context (limits, gated, out_of_reach, groups, modes), or {}."""
    return dict(getattr(r.suggestions, "context", {}) or {})


def _kind(s) -> str:
    return {"doublet": "doublet", "3211": "3-2-1-1", "multisine": "orthogonal multisine"}.get(s.kind, s.kind)


def card_fields(s) -> list[tuple[str, str]]:
    """(label, text) lines of one card for suggestion ``s`` (:class:`gcs_sysid.maneuvers.Suggestion`)."""
    fc, ex = s.flight_condition, s.expected
    band = fc.get("altitude_band_m")
    cond = f"V {fc['V']:.1f} m/s, 1-g trim alpha {fc.get('alpha_deg', math.degrees(fc.get('alpha', 0))):.1f} deg"
    if band:
        cond += f", density altitude {band[0]:.0f}-{band[1]:.0f} m"
    amps = ", ".join(f"{n} {math.degrees(a):.1f} deg" for n, a in
                     zip(s.surfaces if hasattr(s, "surfaces") else s.controls, s.amplitudes_rad.values()))
    if s.kind == "multisine":
        shape = (f"period {s.input_s:.1f} s, band {s.band_hz[0]:.2f}-{s.band_hz[1]:.2f} Hz, each surface its own "
                 f"harmonics")
    else:
        shape = f"pulse {s.pulse_width_s:.2f} s, input {s.input_s:.2f} s"
    out = [("condition", cond), ("input", f"{_kind(s)} on {' + '.join(s.surfaces)}"), ("amplitude", amps),
           ("durations", f"{shape}; {s.lead_s:.0f} s trim before, {s.duration_s:.1f} s in all")]
    if ex:
        out.append(("expected", f"p {ex['p_max_dps']:.0f} deg/s, q {ex['q_max_dps']:.0f} deg/s, "
                                f"r {ex['r_max_dps']:.0f} deg/s; alpha {ex['alpha_min_deg']:.1f} to "
                                f"{ex['alpha_max_deg']:.1f} deg; bank "
                                f"{ex['bank_max_deg']:.0f} deg; load factor {ex['n_min']:.2f} to {ex['n_max']:.2f} g"))
    region = s.region.get("description") or ", ".join(s.region.get("axes", []))
    out.append(("why", f"{', '.join(s.coefficients)} poorly known at {region} "
                       f"(sigma {s.region.get('mean_rel_sigma', float('nan')):.2f} x spread)"))
    pct = lambda v: f"{100 * v:.2g} %" if v < 0.1 else f"{100 * v:.0f} %"  # noqa: E731
    out.append(("will reduce", ", ".join(f"{c} variance by {pct(v)}" for c, v in s.reductions.items())
                + " in that region (model's own estimate)"))
    for n in s.notes:
        out.append(("note", n))
    return out


def limit_rows(ctx: dict[str, Any]) -> list[dict[str, str]]:
    """The limits in force and where each came from."""
    lim = ctx.get("limits")
    if not lim:
        return []
    src = lim.get("source", {})
    rows = [{"limit": "airspeed", "value": f"{lim['V_min_mps']:.1f}-{lim['V_max_mps']:.1f} m/s",
             "from": src.get("V_min", "?") if src.get("V_min") == src.get("V_max") else
             f"{src.get('V_min', '?')}; {src.get('V_max', '?')}"},
            {"limit": "load factor", "value": f"{lim['n_min']:.2f} to {lim['n_max']:.2f} g",
             "from": src.get("n_max", "?")},
            {"limit": "alpha_max", "value": f"{lim['alpha_max_deg']:.1f} deg", "from": src.get("alpha_max", "?")}]
    for c, v in lim.get("throw_deg", {}).items():
        rows.append({"limit": f"{c} throw / rate",
                     "value": f"{v:.1f} deg, {lim.get('rate_dps', {}).get(c, float('nan')):.0f} deg/s",
                     "from": src.get(f"throw.{c}", "?") if src.get(f"throw.{c}") == src.get(f"rate.{c}") else
                     f"{src.get(f'throw.{c}', '?')}; {src.get(f'rate.{c}', '?')}"})
    return rows


def gate_rows(ctx: dict[str, Any]) -> list[dict[str, str]]:
    """Coefficients not ranked (quality gate), why, and what to fix first."""
    return [{"coefficient": c, "why not ranked": v["why"], "fix first": v["fix"]}
            for c, v in ctx.get("gated", {}).items()]


def group_rows(ctx: dict[str, Any]) -> list[dict[str, str]]:
    """Flagged regions grouped by what would fix them."""
    rows = []
    for g in ctx.get("groups", []):
        rows.append({"fix": g["fix"], "coefficients": ", ".join(g["coefficients"]),
                     "regions": str(g["regions"]), "slices": ", ".join(g["slices"]),
                     "worst sigma/spread": f"{g['worst_rel_sigma']:.2f}",
                     "where (e.g.)": "; ".join(g["where"][:2]),
                     "suggestions": ", ".join(f"#{k}" for k in g.get("suggestions", [])) or "-"})
    return rows


def _modes_line(ctx: dict[str, Any]) -> str:
    m = ctx.get("modes") or {}
    if not m:
        return ""
    return (f"Modes of the identified model at {m['V_mps']:.1f} m/s: short period {m['short_period_hz']:.2f} Hz, "
            f"Dutch roll {m['dutch_roll_hz']:.2f} Hz, roll subsidence time constant {m['roll_tau_s']:.2f} s.")


def cards_markdown(r: ReplayResult, level: int = 2) -> list[str]:
    """Markdown lines of the fly-next block: cards, limits, gate, out-of-reach notes."""
    h = "#" * level
    ctx = context_of(r)
    L = []
    if not r.suggestions:
        L += ["_No suggestion: nothing flagged, no model fitted, or every flagged coefficient failed the quality "
              "gate._", ""]
    for s in r.suggestions:
        L += [f"{h}# Card {s.rank}: {_kind(s)} on {' + '.join(s.surfaces)} for {', '.join(s.coefficients)}", ""]
        L += [f"- **{k}**: {v}" for k, v in card_fields(s)] + [""]
    gate = gate_rows(ctx)
    if gate:
        L += [f"{h}# Not ranked (quality gate)", ""] + [f"- **{g['coefficient']}**: {g['why not ranked']}. Fix first: "
                                                       f"{g['fix first']}" for g in gate] + [""]
    lim = limit_rows(ctx)
    if lim:
        L += [f"{h}# Limits respected by every card", ""] + [f"- {x['limit']}: {x['value']} ({x['from']})" for x in lim]
        if ctx["limits"].get("source") and any(v != "airframe file" for v in ctx["limits"]["source"].values()):
            L += ["", "_Some limits were not in the airframe file and were taken from the flown envelope: add a "
                      "[limits] table (docs/airframe.md)._"]
        L += [""]
    if ctx.get("out_of_reach"):
        L += [f"{h}# Out of reach as flagged", ""] + [f"- {x}" for x in ctx["out_of_reach"][:12]] + [""]
    line = _modes_line(ctx)
    if line:
        L += [line, ""]
    return L


CARDS_CSS = """
.card{border:1px solid #1d3557;border-radius:6px;padding:10px 16px;margin:10px 0;background:#fff;\
page-break-inside:avoid}
.card h3{margin:0 0 6px;font-size:15px;color:#1d3557}.card table{margin:0}.card th{width:110px;background:#eef2f7}
"""


def cards_html(r: ReplayResult) -> str:
    """HTML of the fly-next block (cards first, then gate, limits, out-of-reach, modes)."""
    e = html.escape
    ctx = context_of(r)
    out = []
    if not r.suggestions:
        out.append('<p class="muted">No suggestion: nothing flagged, no model fitted, or every flagged coefficient '
                   'failed the quality gate.</p>')
    for s in r.suggestions:
        rows = "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in card_fields(s))
        out.append(f'<div class="card"><h3>Card {s.rank}: {e(_kind(s))} on {e(" + ".join(s.surfaces))} for '
                   f'{e(", ".join(s.coefficients))}</h3><table>{rows}</table></div>')
    gate = gate_rows(ctx)
    if gate:
        items = "".join(f"<li><strong>{e(g['coefficient'])}</strong>: {e(g['why not ranked'])}. Fix first: "
                        f"{e(g['fix first'])}</li>" for g in gate)
        out.append(f'<div class="callout"><strong>Not ranked (quality gate)</strong><ul>{items}</ul></div>')
    lim = limit_rows(ctx)
    if lim:
        items = "".join(f"<li>{e(x['limit'])}: {e(x['value'])} <span class=\"muted\">({e(x['from'])})</span></li>"
                        for x in lim)
        out.append(f'<div class="callout info"><strong>Limits respected by every card</strong><ul>{items}</ul></div>')
    if ctx.get("out_of_reach"):
        items = "".join(f"<li>{e(x)}</li>" for x in ctx["out_of_reach"][:12])
        out.append(f'<div class="callout info"><strong>Out of reach as flagged</strong><ul>{items}</ul></div>')
    line = _modes_line(ctx)
    if line:
        out.append(f'<p class="muted">{e(line)}</p>')
    return "".join(out)


def render_testcards_md(r: ReplayResult, path: Path) -> Path:
    """testcards.md: the printable cards in Markdown."""
    L = [f"# Test cards: {Path(r.log_path).name} ({r.airframe_name})", ""] + cards_markdown(r, level=1)
    path.write_text("\n".join(L) + "\n", encoding="utf-8")
    return path


def render_testcards_html(r: ReplayResult, path: Path) -> Path:
    """testcards.html: the printable cards, one page, no scripts."""
    from .html import _CSS

    title = f"Test cards: {Path(r.log_path).name} ({r.airframe_name})"
    page = (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
            f"<style>{_CSS}{CARDS_CSS}@media print{{body{{background:#fff}}}}</style></head><body><main>"
            f"<h1>{html.escape(title)}</h1>{cards_html(r)}</main></body></html>")
    path.write_text(page, encoding="utf-8")
    return path


def write_flynext_plan(r: ReplayResult, path: Path) -> Path | None:
    """flynext_plan.toml: the suggestions as a plan ``gcs-sysid simulate`` flies; None when there are none."""
    if not r.suggestions:
        return None
    from ..maneuvers.flyplan import write_plan

    return write_plan(list(r.suggestions), path, name=f"fly-next-{r.airframe_name}")
