"""report.html: one self-contained page (inline CSS, figures as base64 PNG, no external assets)."""

from __future__ import annotations

import base64
import html
from pathlib import Path

from ..result import ReplayResult
from . import tables
from .cards import CARDS_CSS, cards_html, context_of, group_rows

__all__ = ["render_html", "SECTIONS"]

#: (anchor, title) of the page's sections, in order.
SECTIONS = (("flynext", "Fly next"), ("summary", "Summary"), ("notes", "What is missing / notes"), ("data", "Data"),
            ("states", "States"), ("coefficients", "Coefficients"), ("errors", "Held-out error"),
            ("model", "GP model"), ("envelope", "Envelope confidence"), ("regions", "Flagged regions, grouped by fix"),
            ("suggestions", "Maneuver suggestions"))

_CSS = """
body{font-family:-apple-system,'Segoe UI',Helvetica,Arial,sans-serif;margin:0;color:#1d2733;background:#f5f7fa}
header{background:#1d3557;color:#fff;padding:18px 32px}header h1{margin:0;font-size:22px}
header p{margin:4px 0 0;opacity:.85;font-size:13px}
nav{background:#fff;border-bottom:1px solid #d8dee6;padding:8px 32px;position:sticky;top:0;z-index:2}
nav a{color:#1d3557;margin-right:16px;font-size:13px;text-decoration:none}nav a:hover{text-decoration:underline}
main{max-width:1280px;margin:0 auto;padding:8px 32px 48px}
section{background:#fff;border:1px solid #d8dee6;border-radius:6px;padding:16px 22px;margin:18px 0}
h2{font-size:18px;margin:0 0 12px;color:#1d3557}h3{font-size:15px;margin:18px 0 8px}
table{border-collapse:collapse;font-size:13px;margin:6px 0 10px}\
th,td{border-bottom:1px solid #e3e8ee;padding:4px 10px;text-align:left;vertical-align:top}
th{background:#eef2f7;font-weight:600}tr:hover td{background:#fafbfd}
td.num{text-align:right;font-variant-numeric:tabular-nums}
img{max-width:100%;height:auto;display:block;margin:8px 0}
.callout{border-left:5px solid #e63946;background:#fff1f2;padding:10px 14px;margin:8px 0;border-radius:3px}
.callout.info{border-color:#457b9d;background:#eef6fb}
.callout ul{margin:4px 0;padding-left:20px}.muted{color:#6b7785;font-size:12px}
.bad{color:#b30000;font-weight:600}.good{color:#1b7a3a;font-weight:600}
ol.reasons li{margin:6px 0;font-size:13px}
"""
_CSS += CARDS_CSS


def _img(data: bytes, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{base64.b64encode(data).decode()}">'


def _table(rows: list[dict[str, str]], empty: str = "none") -> str:
    if not rows:
        return f'<p class="muted">{html.escape(empty)}</p>'
    head = "".join(f"<th>{html.escape(k)}</th>" for k in rows[0])
    body = []
    for r in rows:
        cells = []
        for k, v in r.items():
            cls = ' class="num"' if _numeric(v) else ""
            if k == "verdict" and v.startswith(("above", "not identified")):
                cls = ' class="bad"'
            elif k == "verdict" and v.startswith("within"):
                cls = ' class="good"'
            cells.append(f"<td{cls}>{html.escape(str(v))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _numeric(v: str) -> bool:
    try:
        float(str(v).replace(",", "").replace(" %", ""))
        return True
    except ValueError:
        return False


def _kv(pairs: list[tuple[str, str]]) -> str:
    return ("<table>" + "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in pairs)
            + "</table>")


def _section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{anchor}"><h2>{html.escape(title)}</h2>{body}</section>'


def _notes(r: ReplayResult) -> str:
    bad = [f"{c}: {why}" for c, (ok, why) in r.identifiable.items() if not ok]
    parts = []
    if bad or r.missing:
        items = "".join(f"<li>{html.escape(x)}</li>" for x in
                        [f"not identifiable - {b}" for b in bad] + [f"missing: {m}" for m in r.missing])
        parts.append(f'<div class="callout"><strong>Not identified / missing</strong><ul>{items}</ul></div>')
    if r.notes:
        items = "".join(f"<li>{html.escape(n)}</li>" for n in r.notes)
        parts.append(f'<div class="callout info"><strong>Notes</strong><ul>{items}</ul></div>')
    return "".join(parts) or '<p class="muted">Nothing missing: all six coefficients identified.</p>'


def _model(r: ReplayResult, fig) -> str:
    gs = r.gp_summary
    if not gs:
        return '<p class="muted">No model was fitted.</p>'
    out = [_kv(tables.gp_rows(r))]
    corr = fig("correlation")
    if corr is not None:
        out.append(_img(corr, "output correlation"))
    ls = tables.lengthscale_rows(r)
    if ls:
        out.append("<h3>Length-scales (data units; - = input inactive)</h3>" + _table(ls))
    return "".join(out)


def _envelope(r: ReplayResult, fig) -> str:
    env = r.envelope
    if env is None:
        return '<p class="muted">No confidence map (no model was fitted).</p>'
    out = ['<p>Predictive sigma of the model divided by each coefficient\'s RMS spread in the data (so the six '
           'are comparable), on grids that extend beyond the flown range; the other regressors sit at their '
           'median values. Cells are flagged (hatched, outlined) where sigma/spread exceeds the threshold or no '
           'training sample lies nearby. Confidence score = 1 - mean(min(sigma/spread, 1)) over all cells.</p>',
           _table(tables.score_rows(r))]
    for sl, png in zip(env.slices, fig("envelope") or []):
        out.append(f"<h3>{html.escape(sl.axes[0])} x {html.escape(sl.axes[1])}</h3>")
        out.append(_img(png, f"{sl.axes[0]} x {sl.axes[1]}"))
    return "".join(out)


def _suggestions(r: ReplayResult, fig) -> str:
    if not r.suggestions:
        return '<p class="muted">No suggestions: nothing was flagged, or no model was fitted.</p>'
    reasons = "".join(f"<li><strong>#{s.rank}</strong> {html.escape(s.reason)}</li>" for s in r.suggestions)
    return (_table(tables.suggestion_rows(r)) + "<h3>Why</h3>"
            + f'<ol class="reasons" style="list-style:none;padding-left:0">{reasons}</ol>'
            + "<h3>Input waveforms (deviation from trim)</h3>" + _img(fig("suggestions"), "waveforms")
            + '<p class="muted">Amplitudes keep the response near-linear (target alpha, q, p, beta excursions) '
              'and inside the limits (alpha_max, load factor, throw, surface rate); pulse widths follow the mode '
              'frequencies (doublet 2.3/w_n, 3-2-1-1 '
              '1.6/w_n, Jategaonkar 2006 sec. 2.5). Expected reduction: predictive variance at the region\'s '
              'points after adding the simulated maneuver, relative to now.</p>')


def _regions(r: ReplayResult) -> str:
    groups = group_rows(context_of(r))
    if groups:
        return ("<p>Flagged regions (coefficient x location, the quality-gated coefficients left out) grouped by "
                "the input that would fix them; rates in deg/s at the group's airspeed.</p>" + _table(groups)
                + f'<p class="muted">{len(r.envelope.regions)} regions in all, each in suggestions.json.</p>')
    return _table(tables.region_rows(r), "no regions flagged") + (
        f'<p class="muted">{len(r.envelope.regions)} regions (coefficient x location) in all; the most uncertain '
        'locations are shown, all are in suggestions.json.</p>' if r.envelope is not None else "")


def render_html(r: ReplayResult, path: Path, figures: dict | None = None) -> Path:
    """Write report.html for ``r`` to ``path``.

    Args:
        figures: figures drawn elsewhere, by the names of :data:`~gcs_sysid.report.plots.FIGURES`:
            the value, or a job whose ``result()`` gives it (the pipeline draws them in its worker
            process, :class:`gcs_sysid.parallel.Job`); the others are drawn here.
    """
    given = figures or {}

    def fig(name: str):
        if name not in given:
            from . import plots   # matplotlib only where figures are drawn

            return plots.figure(r, name)
        v = given[name]
        return v.result() if hasattr(v, "result") else v

    title = f"gcs-sysid replay: {Path(r.log_path).name}"
    msgs = sorted(r.messages.items(), key=lambda kv: -kv[1])
    data = (_table(tables.stream_rows(r), "no streams decoded") + _img(fig("streams"), "streams")
            + "<h3>Messages in the log</h3>"
            + _table([{"message": k, "count": tables.fmt(v)} for k, v in msgs[:40]], "no messages counted"))
    body = {
        "flynext": cards_html(r),
        "summary": _kv(tables.facts(r)),
        "notes": _notes(r),
        "data": data,
        "states": _img(fig("states"), "states") + '<p class="muted">Held-out segment shaded yellow.</p>',
        "coefficients": _img(fig("coefficients"), "coefficients")
        + '<p class="muted">Measured (orange), model mean (blue) with 2-sigma band; held-out segment shaded yellow '
          '(never used for fitting).</p>',
        "errors": "<p>Error = 100 RMS(model - measured) / RMS(measured) on the held-out segment; thesis floor "
                  f"{tables.THESIS_FLOOR_PCT['forces']} % (forces), "
                  f"{tables.THESIS_FLOOR_PCT['moments']} % (moments).</p>"
                  + _table(tables.error_rows(r)),
        "model": _model(r, fig),
        "envelope": _envelope(r, fig),
        "regions": _regions(r),
        "suggestions": _suggestions(r, fig),
    }
    nav = "".join(f'<a href="#{a}">{html.escape(t)}</a>' for a, t in SECTIONS)
    sections = "".join(_section(a, t, body[a]) for a, t in SECTIONS)
    timing = ", ".join(f"{k} {v:.1f} s" for k, v in r.timings.items())
    page = (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
            f"<style>{_CSS}</style></head><body><header><h1>{html.escape(title)}</h1>"
            f"<p>airframe {html.escape(r.airframe_name)} &middot; {html.escape(timing)}</p></header>"
            f"<nav>{nav}</nav><main>{sections}</main></body></html>")
    path.write_text(page, encoding="utf-8")
    return path
