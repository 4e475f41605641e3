"""Render a :class:`~gcs_sysid.diagnose.core.Diagnosis` as one self-contained HTML page.

Plots (matplotlib, embedded as base64 PNG): equation-error residual of each
coefficient over time before and after the findings (held-out blocks shaded),
the residual over the envelope (alpha vs V), and the output-error windows
(simulated vs measured states, before and after).
"""

from __future__ import annotations

import base64
import html
import io
import json
from pathlib import Path

import numpy as np

from ..aero.table import COEFFICIENTS

__all__ = ["write_report", "render_html", "pitot_console_lines"]

_CSS = """body{font-family:sans-serif;max-width:1100px;margin:1em auto;color:#222}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:3px 8px;font-size:90%}
th{background:#eee}.warn{color:#a40}.ok{color:#070}img{max-width:100%}code{background:#f4f4f4}"""


def _png(fig) -> str:
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=72, bbox_inches="tight")
    plt.close(fig)
    return f'<img src="data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}">'


def _thin(mask: np.ndarray, n: int) -> np.ndarray:
    """At most ``n`` evenly spread True entries of ``mask`` (plots stay light)."""
    idx = np.nonzero(mask)[0]
    out = np.zeros_like(mask)
    out[idx[:: max(1, len(idx) // n)]] = True
    return out


def _fig_time(d) -> str:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(6, 1, figsize=(11, 12), sharex=True)
    t = d.t
    v = _thin(d.train | d.test, 4000)
    for j, (ax, c) in enumerate(zip(axs, COEFFICIENTS)):
        ax.plot(t[v], d.residual_before[v, j], ".", ms=1.5, color="tab:red", label="before")
        ax.plot(t[v], d.residual_after[v, j], ".", ms=1.5, color="tab:blue", label="after")
        lo, hi = np.nanmin(d.residual_before[v, j]), np.nanmax(d.residual_before[v, j])
        ax.fill_between(t[::5], lo, hi, where=d.test[::5], color="0.9", step="mid", zorder=0)
        ax.set_ylabel(f"{c} residual")
    axs[0].legend(loc="upper right", markerscale=8)
    axs[-1].set_xlabel("vehicle time (s); shaded: held out")
    return _png(fig)


def _fig_envelope(d) -> str:
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(2, 6, figsize=(15, 5), sharex=True, sharey=True)
    v = _thin(d.train | d.test, 1500)
    a = np.degrees(d.X[v, 0])
    V = d.X[v, 9]
    for j, c in enumerate(COEFFICIENTS):
        for i, (R, lab) in enumerate(((d.residual_before, "before"), (d.residual_after, "after"))):
            r = R[v, j]
            lim = np.nanpercentile(np.abs(d.residual_before[v, j]), 98) or 1.0
            sc = axs[i, j].scatter(a, V, c=r, s=2, cmap="coolwarm", vmin=-lim, vmax=lim)
            axs[i, j].set_title(f"{c} {lab}", fontsize=9)
        fig.colorbar(sc, ax=axs[:, j], shrink=0.6)
    for ax in axs[1]:
        ax.set_xlabel("alpha (deg)")
    for ax in axs[:, 0]:
        ax.set_ylabel("V (m/s)")
    return _png(fig)


def _fig_output_error(oe: dict) -> str:
    import matplotlib.pyplot as plt

    wins = oe.get("windows_plot") or []
    if not wins:
        return ""
    keys = oe.get("states", [])
    fig, axs = plt.subplots(len(keys), len(wins), figsize=(4 * len(wins), 1.6 * len(keys)), squeeze=False)
    for i, w in enumerate(wins):
        for k, key in enumerate(keys):
            ax = axs[k, i]
            ax.plot(w["t"], w["measured"][key], "k", lw=1, label="measured")
            ax.plot(w["t"], w["before"][key], "tab:red", lw=1, label="model")
            if "after" in w:
                ax.plot(w["t"], w["after"][key], "tab:blue", lw=1, label="extended")
            if i == 0:
                ax.set_ylabel(key)
    axs[0, 0].legend(fontsize=7)
    return _png(fig)


def _table(rows, cols) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in cols)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in r) + "</tr>" for r in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _f(x, fmt="{:.4g}"):
    if x is None:
        return ""
    return fmt.format(x) if isinstance(x, (int, float)) else str(x)


def _faults_section(findings: list[dict], summary: dict | None) -> str:
    """Actuator and engine faults read from the telemetry: what was found, every frozen run looked at."""
    out = ["<h2>Actuator and engine faults (servo outputs against the autopilot's demand)</h2>"]
    if summary is None:
        return out[0] + "<p>Not looked for (no decoded flight given).</p>"
    faults = [f for f in findings if f.get("kind") == "fault"]
    if faults:
        out.append(_table([[f["cause"], ", ".join(map(str, f["evidence"].get("channels", []))),
                            _f(f["onset_s"], "{:.2f}"), f.get("summary", "")] for f in faults],
                          ["cause", "servo channel(s)", "onset (s)", "evidence"]))
    else:
        out.append("<p class='ok'>No servo output froze while the autopilot kept demanding.</p>")
    if summary.get("checked"):
        out.append("<p>Frozen runs looked at:</p>" + _table(
            [[c["control"], c["channel"], _f(c.get("pwm_frozen_us"), "{:.0f}"), _f(c["frozen_from_s"], "{:.1f}"),
              _f(c["frozen_to_s"], "{:.1f}"), "yes" if c["accepted"] else "no", c["why"]] for c in summary["checked"]],
            ["control", "channel", "PWM (us)", "from (s)", "to (s)", "fault", "why"]))
    for r in summary.get("coefficient_stuck_rejected", []):
        out.append(f"<p>Set aside: {html.escape(r['cause'])} from {r['onset_s']:.1f} s in the coefficients: "
                   f"{html.escape(r['why'])}.</p>")
    for m in summary.get("missing", []):
        out.append(f"<p class='warn'>Missing: {html.escape(m)}</p>")
    return "\n".join(out)


def _pm(x, se, fmt="{:+.2f}") -> str:
    return "" if x is None else fmt.format(x) + ("" if se is None else f" +- {se:.2f}")


def _pitot_named(findings) -> str | None:
    """The pitot cause among the findings (either path: the wind triangle's or the coefficients' signature), or None."""
    from .pitot import PITOT_CAUSES

    return next((f["cause"] for f in findings or () if f.get("cause") in PITOT_CAUSES), None)


def _pitot_section(pitot: dict | None, findings=()) -> str:
    """The airspeed check: the wind triangle and the coefficients' qbar signature against the reference flight(s),
    what was decided and why, and the smallest change this flight resolves (:func:`gcs_sysid.diagnose.pitot.
    pitot_resolution`) with the flight that would resolve more."""
    head = "<h2>Airspeed (pitot) check: wind triangle and coefficients against the reference flight(s)</h2>"
    wt = (pitot or {}).get("wind_triangle")
    if not wt:
        return head + "<p>Not judged (no pitot bias candidate was fitted).</p>"
    ch, fl, fu = wt.get("change") or {}, wt.get("flight") or {}, wt.get("fused") or {}
    if not ch:
        return head + f"<p>Not judged: {html.escape(str(wt.get('why', 'no wind triangle')))}.</p>"
    refs = wt.get("references") or []
    rows = [["wind triangle, this flight", _pm(ch.get("flight_mps"), fl.get("std_error")),
             _f(fl.get("heading_span_deg"), "{:.0f}"), fl.get("wind", "")]]
    rows += [[f"wind triangle, {r.get('label', 'reference')}", _pm(r.get("bias_mps"), r.get("std_error")),
              _f(r.get("heading_span_deg"), "{:.0f}"), r.get("wind", "")] for r in refs]
    rows.append(["change since the reference(s)", _pm(ch.get("change_mps"), ch.get("std_error")), "", ""])
    if fu:
        rows.append(["coefficients' qbar signature (change)",
                     _pm(fu.get("coefficients_mps"), fu.get("coefficients_se")), "",
                     "exact re-fit" if wt.get("coefficients_rereduced") else "closed form"])
        rows.append(["fused", _pm(fu.get("estimate"), fu.get("std_error")), "",
                     f"t = {fu['t_statistic']:.1f}, {'agree' if fu.get('agree') else 'disagree'}"])
    out = [head, _table(rows, ["measurement", "pitot bias (m/s)", "heading span (deg)", "note"])]
    named = _pitot_named(findings)
    if named:
        out.append(f"<p class='warn'>Named: {named} (see Findings).</p>")
    else:
        out.append(f"<p class='ok'>Not named: {html.escape(str(wt.get('why', '')))}.</p>")
    res = wt.get("resolution")
    if res:
        out.append(f"<p>Resolution: {html.escape(res['summary'])}.</p>")
        if res.get("advice"):
            out.append(f"<p class='warn'>{html.escape(res['advice'])}.</p>")
    return "\n".join(out)


def pitot_console_lines(data: dict, findings=()) -> list[str]:
    """The airspeed check's resolution as the CLI prints it after a diagnosis: ``[]`` without one, else the summary
    and, where one share limits the flight, the advice (:func:`gcs_sysid.diagnose.pitot.pitot_resolution`).

    Args:
        data: ``Diagnosis.data`` (reads ``data["pitot"]["wind_triangle"]["resolution"]``).
        findings: the diagnosis's findings (a pitot cause among them is said first).
    """
    wt = (data.get("pitot") or {}).get("wind_triangle") or {}
    res = wt.get("resolution")
    if not res:
        return []
    named = _pitot_named(findings)
    head = f"airspeed (pitot) check: {named} named; " if named else "airspeed (pitot) check: "
    return [head + res["summary"]] + ([f"airspeed (pitot) check: {res['advice']}"] if res.get("advice") else [])


def _floor_section(sparse: dict | None) -> str:
    """The sparse search's naming floor per coefficient (:func:`gcs_sysid.diagnose.sparse.naming_floor`): the
    smallest term its share gates let it name, in coefficient units and as the change of common terms."""
    from .sparse import FLOOR_TERMS

    rows = [(e["coefficient"], e["naming_floor"]) for e in (sparse or {}).get("coefficients") or []
            if e.get("naming_floor")]
    if not rows:
        return ""
    terms = [t for t in FLOOR_TERMS if any(t in fl["min_change"] for _, fl in rows)]
    out = ["<h2>What this flight could name: the sparse search's floor per coefficient</h2>",
           "<p>A term is named only if it takes a large enough share of the residual (block PRESS drop and held-out "
           f"gain), however significant: no term whose RMS is below {rows[0][1]['factor']:.2f} times the residual "
           "left on the untouched rows is named. Below, that floor and the smallest change of common terms it means "
           "on this flight (a term above it must still pass the other checks).</p>",
           _table([[c, _f(fl["residual_rms"]), _f(fl["term_rms_min"])] + [_f(fl["min_change"].get(t)) for t in terms]
                   for c, fl in rows], ["coefficient", "residual RMS (untouched)", "smallest term named (RMS)"]
                  + [f"smallest {t} change" for t in terms])]
    return "\n".join(out)


def _search_section(search: list[dict]) -> str:
    """What the wide-library search adds to each coefficient (terms by block PRESS, gain held out)."""
    out = ["<h2>Beyond the catalogue: wide-library search (block PRESS on training rows, gain held out)</h2>"]
    rows = [[e["coefficient"], ", ".join(f"{x['term']} = {x['estimate']:.4g} +- {x['std_error']:.2g}"
                                         for x in e["terms"])
             or "nothing", _f(e["held_out"]["percent"], "{:.0f} %"), e["n_candidates"]] for e in search]
    out.append(_table(rows, ["coefficient", "terms selected", "held-out gain", "candidates"]))
    return "\n".join(out)


def _region(r: dict) -> str:
    return ", ".join(f"{k} {v[0]:.3g}..{v[1]:.3g}" for k, v in (r or {}).items())


def _differential_section(diff: dict) -> str:
    """Model inadequacy (also in the reference flights) against changes (only in this flight)."""
    out = ["<h2>Against the reference flight(s): model inadequacy or a change</h2>",
           "<p>References: " + html.escape(", ".join(r["label"] for r in diff["references"])) + "</p>"]
    if diff["model_inadequacy"]:
        out.append(_table([[m["cause"], _f(m["extension"]["value"]), _f(m["extension"]["std_error"]),
                            _region(m.get("where")), _f(m.get("rms_contribution")), html.escape(m["summary"])]
                           for m in diff["model_inadequacy"]],
                          ["never captured (in the references too)", "extension: value", "std error", "where",
                           "RMS of the term", "summary"]))
    out.append(_table([[c["cause"], _f(c.get("onset_s")) if c.get("onset_s") is not None else "from the start"]
                       for c in diff["changed"]] or [["nothing", ""]], ["changed since the reference", "onset (s)"]))
    for coef, u in diff.get("unexplained", {}).items():
        out.append(f"<p>{coef}: structure no term explains, {html.escape(u['verdict'])} "
                   f"({u['structured_percent']:.0f} % of the held-out residual; region {_region(u['region'])}).</p>")
    return "\n".join(out)


def render_html(d) -> str:
    """The report as an HTML string (all images inline)."""
    data = d.data
    parts = [f"<html><head><meta charset='utf-8'><title>gcs-sysid diagnosis</title><style>{_CSS}</style></head><body>",
             "<h1>Simulation diagnosis</h1>",
             f"<p>Log <code>{html.escape(str(data.get('log', '')))}</code>, model "
             f"<code>{html.escape(str(data.get('model', '')))}</code>; {data['n_valid']} valid samples at "
             f"{data['rate_hz']:.0f} Hz ({data['n_train']} training, {data['n_held_out']} held out in interleaved "
             f"blocks), t = {data['t_range_s'][0]:.1f}..{data['t_range_s'][1]:.1f} s.</p>",
             "<h2>Findings</h2>"]
    if d.findings:
        parts.append(_table([[f["cause"], f["coefficient"], _f(f["estimate"]), _f(f["std_error"]),
                              f.get("onset_s", ""), _f(f["gain"].get("rms_before")), _f(f["gain"].get("rms_after")),
                              _f(f["gain"].get("percent"), "{:.0f} %"),
                              "NO" if not f["evidence"].get("separable", True)
                              else "aliased" if f.get("aliases") else "yes"] for f in d.findings],
                            ["cause", "coefficient", "estimate", "std error", "onset (s)", "held-out RMS before",
                             "after", "gain", "separable"]))
    else:
        parts.append("<p class='ok'>No cause from the catalogue explains the residual better than noise on held-out "
                     "data: no finding.</p>")
    for f in d.findings:                  # candidates the flight cannot tell apart from the named one (aliases.py)
        for a in f.get("aliases") or []:
            parts.append(f"<p class='warn'>{html.escape(a['cannot_tell_apart'])}; read as {html.escape(a['cause'])}: "
                         f"estimate {_f(a['estimate'])} (model {_f(a['model_value'])}), held-out gain "
                         f"{_f(a['gain'].get('percent'), '{:.0f} %')}. To separate them: "
                         f"{html.escape(a['separate_with'])}.</p>")
    for s in data.get("separation", []):
        parts.append(f"<p class='warn'>{html.escape(s)}</p>")
    parts.append(_faults_section(d.findings, data.get("faults")))
    parts.append(_pitot_section(data.get("pitot"), d.findings))
    if "coefficient_diagnosis" in data:
        parts.append(f"<p class='warn'>Coefficient-level diagnosis {html.escape(data['coefficient_diagnosis'])}</p>"
                     "<h2>diagnosis.json</h2><pre>"
                     + html.escape(json.dumps(d.to_json(), indent=1, default=str)[:20000])
                     + "</pre></body></html>")
        return "\n".join(parts)
    if data.get("differential") is not None:
        parts.append(_differential_section(data["differential"]))
    if data.get("search") is not None:
        parts.append(_search_section(data["search"]))
    parts.append(_floor_section(data.get("sparse")))
    parts.append("<h2>Equation error on held-out data (per coefficient)</h2>")
    ee = data["equation_error"]
    parts.append(_table([[c, _f(ee[c]["rms_before"]), _f(ee[c]["rms_after"]), _f(ee[c]["percent"], "{:.0f} %")]
                         for c in COEFFICIENTS], ["coefficient", "RMS before", "RMS after", "gain"]))
    parts.append("<h2>Unexplained residual</h2>")
    parts.append(_table([[u["coefficient"], _f(u["rms"]), _f(u["percent_of_measured"], "{:.1f} %"),
                          _f(u["structured_percent"], "{:.0f} %"), "YES" if u["above_threshold"] else "no",
                          u["where"].get("correlated_with"), u["where"].get("alpha_deg"), u["where"].get("V_mps"),
                          u["where"].get("time_s"),
                          (f"{u['gp']['structured_percent']:.0f} %: " + _region(u["gp"]["region"]))
                          if u.get("gp", {}).get("structured") else "no"] for u in d.unexplained],
                        ["coefficient", "RMS", "of measured", "structured", "above threshold", "most correlated with",
                         "worst alpha bin (deg)", "worst V bin (m/s)", "worst 5 s", "residual GP: structure, region"]))
    oe = d.output_error or {}
    parts.append("<h2>Output error (simulation driven by the measured controls)</h2>")
    if oe.get("available"):
        rows = [[k, _f(v["rms_before"]), _f(v.get("rms_after")), _f(v.get("percent"), "{:.0f} %")]
                for k, v in oe["states_rms"].items()]
        parts.append(f"<p>{oe['n_windows']} windows of {oe['window_s']:.1f} s from measured initial states; "
                     "RMS of simulated minus measured over all held-out windows.</p>")
        parts.append(_table(rows, ["state", "RMS before", "RMS after", "gain"]))
        parts.append(_fig_output_error(oe))
    else:
        parts.append(f"<p>Not available: {html.escape(str(oe.get('reason', 'not run')))}</p>")
    parts.append("<h2>Equation-error residual over time</h2>" + _fig_time(d))
    parts.append("<h2>Residual over the envelope</h2>" + _fig_envelope(d))
    parts.append("<h2>Candidates, best first, per round</h2>")
    for i, r in enumerate(data.get("candidate_rounds", [])):
        parts.append(f"<p>Round {i + 1}</p>" + _table([[c["cause"], _f(c["score"], "{:.1f}"),
                                                          _f(c["gain_percent"], "{:.1f} %")] for c in r],
                                                       ["cause", "held-out score", "gain"]))
    parts.append("<h2>diagnosis.json</h2><pre>" + html.escape(json.dumps(d.to_json(), indent=1, default=str)[:20000])
                 + "</pre></body></html>")
    return "\n".join(parts)


def write_report(d, path) -> None:
    """Write the report to ``path``."""
    Path(path).write_text(render_html(d), encoding="utf-8")
