"""The report's figures, drawn with matplotlib's object API on the Agg canvas (no pyplot state).

Every function takes plain data (the parts of a :class:`~gcs_sysid.result.ReplayResult` it
draws) and returns PNG bytes, which the HTML renderer embeds as base64. Taking the parts rather
than the whole result lets the pipeline draw each figure in its worker process as soon as its
data exist (:mod:`gcs_sysid.parallel`); :func:`all_figures` draws them all from a result.
"""

from __future__ import annotations

import io
import math

import numpy as np
from contourpy import contour_generator
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.patches import PathPatch
from matplotlib.path import Path
from matplotlib.ticker import FuncFormatter, NullFormatter

from ..aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from ..envelope import EnvelopeMap, EnvelopeSlice
from ..estimation.states import FlightStates
from ..result import ReplayResult
from ..telemetry.types import StreamSummary
from .tables import ANGLES, correlation_of

__all__ = ["png", "streams_figure", "states_figure", "coefficients_figure", "correlation_figure",
           "envelope_figure", "envelope_figures", "suggestions_figure", "figure", "all_figures", "FIGURES"]

#: Names of the figures :func:`all_figures` returns (``"envelope"`` is a list, one PNG per slice).
FIGURES = ("streams", "states", "coefficients", "correlation", "envelope", "suggestions")

_MAX_POINTS = 4000
#: Training samples drawn over an envelope panel (decimated evenly; the counts panel shows them all).
_MAX_SCATTER = 800
_HELD = "#f4d03f"


def png(fig: Figure, dpi: int = 96) -> bytes:
    """Render a figure to PNG bytes."""
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    # zlib level 1: the figures are flat colours, so files grow a little and encoding is ~3x faster
    fig.savefig(buf, format="png", dpi=dpi, pil_kwargs={"compress_level": 1})
    return buf.getvalue()


def _grid_kw(extent) -> dict:
    """imshow settings for a uniform (ny, nx) cell grid spanning ``extent`` (row 0 at the bottom)."""
    return {"extent": extent, "origin": "lower", "aspect": "auto", "interpolation": "nearest"}


def _stride(n: int) -> int:
    return max(1, int(math.ceil(n / _MAX_POINTS)))


def _shade(ax, t: np.ndarray, mask: np.ndarray, label: str | None = None) -> None:
    """Shade the spans of t where mask is True."""
    if not mask.any():
        return
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    for k, (a, b) in enumerate(zip(edges[::2], edges[1::2])):
        ax.axvspan(t[a], t[b - 1], color=_HELD, alpha=0.25, lw=0, label=label if k == 0 else None)


def _one_path(pts: list, codes: list) -> Path:
    """One matplotlib ``Path`` from contourpy's per-polygon point ``(n_i, 2)`` and code ``(n_i,)`` arrays."""
    return Path(np.concatenate(pts), np.concatenate(codes))


def _flag_marks(ax, xc: np.ndarray, yc: np.ndarray, flag: np.ndarray) -> list:
    """Hatch ``///`` and outline (cyan) over the flagged cells of ``flag (ny, nx)`` (1.0 flagged, 0.0 not) on the
    cell centres ``xc (nx,)``, ``yc (ny,)``: the regions matplotlib's ``contourf(levels=[0.5, 1.5])`` and
    ``contour(levels=[0.5])`` give (contourpy's ``mpl2014`` generator with corner masking, matplotlib's defaults),
    drawn as two patches instead of two contour sets, whose set-up cost more than their drawing. The patches are
    added as plain artists (``add_artist``: clipped to the axes, no data-limit update, which walks every Bezier
    segment of the path; the caller sets the limits). Returns the artists added (to be removed before the next
    slice)."""
    gen = contour_generator(x=xc, y=yc, z=flag, name="mpl2014", corner_mask=True)
    marks = []
    pts, codes = gen.filled(0.5, 1.5)
    if pts:
        marks.append(ax.add_artist(PathPatch(_one_path(pts, codes), facecolor="none",
                                             edgecolor="black", linewidth=0.0, hatch="///")))
    if not flag.all():
        pts, codes = gen.lines(0.5)
        if pts:
            # joins, caps and z-order as a contour set's lines (round, butt, 2): the same pixels
            marks.append(ax.add_artist(PathPatch(_one_path(pts, codes), fill=False,
                                                 edgecolor="#00bcd4", linewidth=1.0, joinstyle="round",
                                                 capstyle="butt", zorder=2)))
    return marks


def _scale(name: str) -> tuple[float, str]:
    return (180 / math.pi, "deg") if name in ANGLES else (1.0, "m/s" if name == "V" else "-")


def streams_figure(summaries: dict[str, StreamSummary]) -> bytes:
    """Timeline of each stream: coverage, gaps in red, rate in the label."""
    ss = sorted(summaries.values(), key=lambda s: s.name)
    h = 0.35 * max(len(ss), 3) + 1.0
    fig = Figure(figsize=(10, h))   # fixed margins: constrained layout costs more than the drawing
    fig.subplots_adjust(left=0.2, right=0.98, bottom=0.55 / h, top=1 - 0.35 / h)
    ax = fig.add_subplot()
    for i, s in enumerate(ss):
        if math.isfinite(s.t_start):
            ax.plot([s.t_start, s.t_end], [i, i], color="#2c7fb8", lw=6, solid_capstyle="butt")
        for a, b in s.gaps:
            ax.plot([a, b], [i, i], color="#d7301f", lw=6, solid_capstyle="butt")
    ax.set_yticks(range(len(ss)), [f"{s.name} ({s.rate_hz:.1f} Hz)" for s in ss])
    ax.invert_yaxis()
    ax.set_xlabel("vehicle time since boot (s)")
    ax.set_title("Streams: coverage (blue) and gaps (red)", loc="left", fontsize=10)
    ax.grid(axis="x", alpha=0.3)
    return png(fig)


def states_figure(states: FlightStates, held_out: np.ndarray) -> bytes:
    """Attitude, rates, air data and controls over time (held-out segment, ``(T,)`` bool, shaded)."""
    st = states
    k = _stride(len(st.t))
    t = st.t[::k]
    held = held_out[::k] if len(held_out) == len(st.t) else np.zeros(len(t), bool)
    panels = [("Attitude (deg)", [("phi", "roll"), ("theta", "pitch"), ("psi", "yaw")], 180 / math.pi),
              ("Body rates (deg/s)", [("p", "p"), ("q", "q"), ("r", "r")], 180 / math.pi),
              ("Airspeed (m/s)", [("V", "V true")], 1.0),
              ("Air angles (deg)", [("alpha", "alpha"), ("beta", "beta")], 180 / math.pi),
              ("Controls (deg)", [("delta_e", "delta_e"), ("delta_a", "delta_a"), ("delta_r", "delta_r")],
               180 / math.pi)]
    fig = Figure(figsize=(10, 9.5))
    fig.subplots_adjust(left=0.08, right=0.93, bottom=0.055, top=0.99, hspace=0.12)
    axes = fig.subplots(len(panels), 1, sharex=True)
    for ax, (title, keys, sc) in zip(axes, panels):
        for key, lab in keys:
            if key in st.data:
                ax.plot(t, np.asarray(st.data[key])[::k] * sc, lw=0.9, label=lab)
            else:
                ax.plot([], [], label=f"{lab} (missing)")
        if title.startswith("Controls") and "delta_t" in st.data:
            tw = ax.twinx()
            tw.plot(t, np.asarray(st.data["delta_t"])[::k] * 100, lw=0.8, color="0.5", ls="--", label="throttle")
            tw.set_ylabel("throttle (%)", fontsize=8)
            tw.set_ylim(-5, 105)
        _shade(ax, t, held)
        ax.set_ylabel(title, fontsize=8)
        ax.legend(loc="upper right", fontsize=7, ncol=3)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("vehicle time since boot (s)")
    return png(fig)


def coefficients_figure(table: CoefficientTable, pred_mean: np.ndarray, pred_sigma: np.ndarray,
                        held_out: np.ndarray, identifiable: dict[str, tuple[bool, str]]) -> bytes:
    """Measured coefficients vs model mean with 2-sigma bands; held-out segment shaded.

    Args:
        table: measured coefficients. pred_mean, pred_sigma: ``(T, 6)`` model mean and 1-sigma (the report
            passes the band for a new measurement, ``ReplayResult.pred_sigma_obs``: the points are measurements).
        held_out: ``(T,)`` bool. identifiable: coefficient -> (bool, reason), shown where there is no model.
    """
    tb = table
    k = _stride(len(tb.t))
    t = tb.t[::k]
    held = held_out[::k]
    fig = Figure(figsize=(10, 10))
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.05, top=0.955, hspace=0.12)
    axes = fig.subplots(6, 1, sharex=True)
    for j, (ax, c) in enumerate(zip(axes, COEFFICIENTS)):
        y = np.where(tb.valid, tb.Y[:, j], np.nan)[::k]
        mu, sd = pred_mean[::k, j], pred_sigma[::k, j]
        if np.isfinite(mu).any():
            ax.fill_between(t, mu - 2 * sd, mu + 2 * sd, color="#3182bd", alpha=0.25, lw=0, label="model 2 sigma")
            ax.plot(t, mu, lw=1.0, color="#08519c", label="model mean")
        else:
            ax.text(0.5, 0.5, "no model for " + c + ": " + identifiable.get(c, (True, "not fitted"))[1],
                    transform=ax.transAxes, ha="center", va="center", fontsize=8, color="#b30000")
        ax.plot(t, y, lw=0.7, color="#d95f02", label="measured", zorder=3)
        _shade(ax, t, held, "held out" if j == 0 else None)
        ax.set_ylabel(c)
        ax.grid(alpha=0.3)
        fin = y[np.isfinite(y)]
        if fin.size:   # robust limits: a few spikes must not flatten the plot
            lo, hi = np.quantile(fin, [0.005, 0.995])
            pad = 0.25 * (hi - lo) + 1e-9
            ax.set_ylim(lo - pad, hi + pad)
    h, lab = axes[0].get_legend_handles_labels()
    fig.legend(h, lab, loc="upper right", bbox_to_anchor=(0.98, 1.0), fontsize=8, ncol=4, frameon=False)
    axes[-1].set_xlabel("vehicle time since boot (s)")
    return png(fig)


def correlation_figure(matrix: np.ndarray, names: list[str]) -> bytes:
    """Output correlation matrix of the multi-output GP."""
    m = np.asarray(matrix, float)
    fig = Figure(figsize=(4.2, 3.6))
    fig.subplots_adjust(left=0.1, right=0.95, bottom=0.08, top=0.92)
    ax = fig.add_subplot()
    im = ax.imshow(m, vmin=-1, vmax=1, cmap="RdBu_r")
    ax.set_xticks(range(len(names)), names)
    ax.set_yticks(range(len(names)), names)
    for i in range(m.shape[0]):
        for j in range(m.shape[1]):
            ax.text(j, i, f"{m[i, j]:.2f}", ha="center", va="center", fontsize=7,
                    color="white" if abs(m[i, j]) > 0.6 else "black")
    fig.colorbar(im, ax=ax, shrink=0.8)
    ax.set_title("GP output correlation", fontsize=10)
    return png(fig)


def envelope_figure(envelope: EnvelopeMap, X_train: np.ndarray, sl: EnvelopeSlice) -> bytes:
    """One slice: data coverage, then per coefficient sigma/spread with flagged cells hatched and outlined."""
    return envelope_figures(envelope, X_train, [sl])[0]


def envelope_figures(envelope: EnvelopeMap, X_train: np.ndarray, slices: list[EnvelopeSlice] | None = None
                     ) -> list[bytes]:
    """:func:`envelope_figure` of each slice, drawn on one reused figure.

    Each slice is one strip: training-sample counts per cell, then sigma/spread of each
    coefficient, all on the slice's axes. Building panels with colorbars costs more than drawing
    them, and tick labels dominate the drawing, so the panels, colorbars and labels are made once
    (tick labels on the first panel's y axis only: the panels share their axes), and each slice
    only swaps the images' data and extent, the decimated scatter of training samples, the
    flagged-cell contours and the axis labels.
    """
    env = envelope
    slices = list(env.slices) if slices is None else list(slices)
    if not slices:
        return []
    outs = list(env.outputs)
    n = 1 + len(outs)
    w = 1.72 * n + 1.2   # figure width (in); margins below in inches, so any number of panels fits
    fig = Figure(figsize=(w, 2.55))
    fig.subplots_adjust(left=1.0 / w, right=1 - 0.86 / w, bottom=0.2, top=0.8, wspace=0.08)
    axes = list(np.atleast_1d(fig.subplots(1, n, sharex=True, sharey=True)).ravel())
    blank = np.full(slices[0].counts.shape, np.nan)
    im0 = axes[0].imshow(blank, cmap="Greens", norm=LogNorm(vmin=1, vmax=2.0), **_grid_kw((0, 1, 0, 1)))
    dots0, = axes[0].plot([], [], ".", ms=1.2, color="0.2", alpha=0.5)
    axes[0].set_title("samples per cell", fontsize=8)
    cax0 = fig.add_axes((0.066 / w, 0.2, 0.08 / w, 0.6))   # counts bar at the far left
    cax0.yaxis.set_ticks_position("left")
    cax0.yaxis.set_label_position("left")
    cb = fig.colorbar(im0, cax=cax0)
    cb.formatter = FuncFormatter(lambda v, _: f"{v:g}")   # plain labels: no mathtext parsing
    cb.minorformatter = NullFormatter()
    cb.ax.tick_params(labelsize=6)
    cb.set_label("samples", fontsize=7)
    vmax = max(1.0, 1.5 * max(env.thresholds.get(c, 0.5) for c in outs))
    ims, dots = [], []
    for ax, c in zip(axes[1:], outs):
        ims.append(ax.imshow(blank, cmap="magma_r", vmin=0, vmax=vmax, **_grid_kw((0, 1, 0, 1))))
        dots.append(ax.plot([], [], ".", ms=0.8, color="#1f78b4", alpha=0.35)[0])
        ax.set_title(f"{c} (score {env.scores.get(c, float('nan')):.2f})", fontsize=8)
        ax.yaxis.set_visible(False)   # shared with the first panel; not drawing it saves its ticks
    if ims:
        cax = fig.add_axes((1 - 0.70 / w, 0.2, 0.093 / w, 0.6))   # sigma bar at the right
        cb = fig.colorbar(ims[-1], cax=cax)
        cb.ax.tick_params(labelsize=6)
        cb.set_label("sigma / spread", fontsize=7)
    for ax in axes:
        ax.tick_params(labelsize=6, length=2, pad=1)
        ax.locator_params(nbins=3)
    title = fig.text(0.5, 0.97, "", ha="center", va="top", fontsize=8)
    Xt = X_train
    k = max(1, len(Xt) // _MAX_SCATTER)
    pngs, marks = [], []
    for sl in slices:
        for m in marks:
            m.remove()
        marks = []
        sx, sy = sl.axes
        fx, ux = _scale(sx)
        fy, uy = _scale(sy)
        xe, ye = sl.x_edges * fx, sl.y_edges * fy
        xc, yc = sl.x_centers * fx, sl.y_centers * fy
        px, py = Xt[::k, REGRESSORS.index(sx)] * fx, Xt[::k, REGRESSORS.index(sy)] * fy
        extent = (xe[0], xe[-1], ye[0], ye[-1])   # the grid is uniform: imshow draws it faster than pcolormesh
        cnt = np.where(sl.counts > 0, sl.counts, np.nan)
        cmax = float(np.nanmax(cnt)) if np.isfinite(cnt).any() else 2.0
        im0.set_data(cnt)
        im0.set_extent(extent)
        im0.set_clim(1, max(2.0, cmax))
        dots0.set_data(px, py)
        for ax, c, im, dt in zip(axes[1:], outs, ims, dots):
            im.set_data(sl.rel_sigma[c])
            im.set_extent(extent)
            dt.set_data(px, py)
            flag = sl.flagged(c).astype(float)
            if flag.any():
                marks += _flag_marks(ax, xc, yc, flag)
        axes[0].set_xlim(extent[0], extent[1])   # shared by all panels
        axes[0].set_ylim(extent[2], extent[3])
        axes[0].set_xlabel(f"{sx} ({ux})", fontsize=7, labelpad=1)
        axes[0].set_ylabel(f"{sy} ({uy})", fontsize=7, labelpad=1)
        title.set_text(f"{sx} x {sy}: other regressors at their medians; hatched + outlined = flagged "
                       "(high sigma/spread or no data)")
        pngs.append(png(fig))
    return pngs


def suggestions_figure(suggestions: list, limit: int = 6) -> bytes:
    """Input waveforms (deviation from trim, deg) of the top ``limit`` suggestions
    (:class:`~gcs_sysid.maneuvers.Suggestion`)."""
    ss = suggestions[:limit]
    n = len(ss)
    cols = 2 if n > 1 else 1
    rows = int(math.ceil(n / cols))
    h = 2.3 * rows + 0.5
    fig = Figure(figsize=(10, h))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.5 / h, top=1 - 0.35 / h, wspace=0.18, hspace=0.6)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    names = {"delta_e": "elevator", "delta_a": "aileron", "delta_r": "rudder"}
    for ax, s in zip(axes, ss):
        for c, u in s.u.items():
            ax.plot(s.t, np.degrees(u), lw=1.2, drawstyle="steps-post" if s.kind != "multisine" else "default",
                    label=names.get(c, c))
        ax.set_title(f"#{s.rank} {s.kind} for {', '.join(s.coefficients)}", fontsize=9, loc="left")
        ax.set_ylabel("deflection (deg)", fontsize=8)
        ax.set_xlabel("time (s)", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    for ax in axes[n:]:
        ax.axis("off")
    return png(fig)


def figure(r: ReplayResult, name: str) -> bytes | list[bytes] | None:
    """The report figure ``name`` (one of :data:`FIGURES`) for ``r``; None where there is nothing
    to draw (no model, no confidence map, no suggestions). ``"envelope"`` is a list, one PNG per slice.

    Raises:
        KeyError: unknown name.
    """
    if name == "streams":
        return streams_figure(r.summaries)
    if name == "states":
        return states_figure(r.states, r.held_out)
    if name == "coefficients":
        return coefficients_figure(r.table, r.pred_mean, r.pred_sigma_obs, r.held_out, r.identifiable)   # measurements
    if name == "correlation":
        corr = correlation_of(r.gp_summary, list(r.envelope.outputs) if r.envelope is not None else [])
        return correlation_figure(*corr) if corr is not None else None
    if name == "envelope":
        return envelope_figures(r.envelope, r.table.X[r.train]) if r.envelope is not None else None
    if name == "suggestions":
        return suggestions_figure(r.suggestions) if r.suggestions else None
    raise KeyError(f"unknown report figure {name!r} (expected one of {', '.join(FIGURES)})")


def all_figures(r: ReplayResult) -> dict[str, bytes | list[bytes] | None]:
    """Every figure of the report for ``r``, by the names in :data:`FIGURES`."""
    return {name: figure(r, name) for name in FIGURES}
