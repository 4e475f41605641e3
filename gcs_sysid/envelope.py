"""Confidence map of the learned aerodynamic model over the flight envelope.

For each 2-D slice of the envelope that a flight-test engineer reads (alpha x V,
beta x V, alpha x delta_e, beta x delta_r, p_hat x delta_a, q_hat x delta_e,
r_hat x delta_r) the model's predictive standard deviation is evaluated on a grid
that extends somewhat beyond the flown range, with the other regressors held at
their median (trim) values. Per coefficient the sigma is divided by the
coefficient's measured RMS spread (the standard deviation of the training
samples), so the six coefficients share one scale: a relative sigma of 1 means
the model knows the coefficient no better than its flight-wide variation.

Cells are flagged where the relative sigma exceeds a threshold or where no
training sample falls; connected flagged cells (4-connectivity,
``scipy.ndimage.label``) form a :class:`FlaggedRegion`. This is the "where to fly
next" map of active-learning / optimal-input-design practice (Morelli and Klein,
*Aircraft System Identification*, 2nd ed., 2016, ch. 9: data information content
over the envelope; Rasmussen and Williams, *Gaussian Processes for Machine
Learning*, 2006, sec. 2.2: the predictive variance does not depend on the
targets, only on where data lie).

Confidence score (per coefficient, in [0, 1])::

    score = 1 - mean over all envelope cells of min(relative sigma, 1)

1 means the model is sure everywhere in the envelope of interest; 0 means its
sigma is at least the coefficient's whole spread everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from scipy import ndimage

from .aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from .errors import DataError, InputError

__all__ = [
    "model_variance",
    "variance_in_chunks",
    "MAP_CHUNK",
    "ENVELOPE_AXES",
    "DEFAULT_SLICES",
    "EnvelopeConfig",
    "EnvelopeSlice",
    "FlaggedRegion",
    "EnvelopeMap",
    "confidence_map",
]

#: Regressors that span the flight envelope (delta_t is held at its median).
ENVELOPE_AXES = ("alpha", "beta", "V", "delta_e", "delta_a", "delta_r", "p_hat", "q_hat", "r_hat")

#: The 2-D slices shown by default, (x axis, y axis).
DEFAULT_SLICES = (
    ("alpha", "V"),
    ("beta", "V"),
    ("alpha", "delta_e"),
    ("beta", "delta_r"),
    ("p_hat", "delta_a"),
    ("q_hat", "delta_e"),
    ("r_hat", "delta_r"),
)

#: Rows per model call of the confidence map (the last call padded to a multiple of a quarter of it),
#: so JAX compiles few shapes and the working arrays stay bounded (``docs/benchmarks.md``, soak
#: memory: one call on all ~4,400 map points held ~70 MiB of temporaries at once).
MAP_CHUNK = 1024


#: Smallest half-span of the grid around the median per axis (SI), used when the flight barely
#: moved an axis (a rudder never deflected still gets a +-3 deg grid).
_MIN_HALF_SPAN = {
    "alpha": np.radians(3.0), "beta": np.radians(3.0), "V": 2.0,
    "delta_e": np.radians(3.0), "delta_a": np.radians(3.0), "delta_r": np.radians(3.0),
    "p_hat": 0.02, "q_hat": 0.01, "r_hat": 0.01,
}


@dataclass(frozen=True)
class EnvelopeConfig:
    """Settings of :func:`confidence_map`.

    Attributes:
        slices: (x, y) regressor pairs, names from :data:`ENVELOPE_AXES`.
        n_grid: cells per axis.
        quantiles: the flown range of an axis is taken between these quantiles of the
            training samples (robust to outliers).
        margin: the grid extends this fraction of the flown span beyond each end.
        limits: optional explicit envelope of interest, axis -> (lo, hi) in SI; overrides
            the flown range plus margin for that axis.
        rel_sigma_threshold: flag cells whose relative sigma exceeds this.
        floor_factor: ... or exceeds ``floor_factor`` times the median relative sigma at the
            training points, whichever is larger (keeps noise-dominated coefficients, whose
            sigma never falls below the noise, from being flagged everywhere).
        min_points: a cell holding fewer training samples counts as "no data".
        min_region_cells: connected flagged areas smaller than this are ignored (None: 2 % of the
            slice's cells, at least 3).
        chunk: grid and training points given to the model per call (:func:`variance_in_chunks`).
    """

    slices: tuple[tuple[str, str], ...] = DEFAULT_SLICES
    n_grid: int = 24
    quantiles: tuple[float, float] = (0.005, 0.995)
    margin: float = 0.25
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)
    rel_sigma_threshold: float = 0.5
    floor_factor: float = 2.0
    min_points: int = 1
    min_region_cells: int | None = None
    chunk: int = MAP_CHUNK


@dataclass
class FlaggedRegion:
    """A connected area of one slice where one coefficient is poorly known.

    Attributes:
        coefficient: e.g. ``"Cm"``.
        axes: (x, y) regressor names of the slice.
        bounds: axis -> (lo, hi), SI, the bounding box of the region's cells.
        center: regressor -> value, SI: the region's sigma-weighted centroid on its two axes and
            the reference (median) values of the other regressors.
        mean_rel_sigma: mean relative sigma over the region's cells.
        max_rel_sigma: largest relative sigma in the region.
        n_points: training samples inside the region's cells (projected onto the slice).
        n_cells: grid cells in the region.
        label: the region's label in its slice's ``labels[coefficient]``.
        reason: one line, e.g. ``"no training data in 18 of 20 cells; mean sigma 0.9 x spread"``.
        points: (K, 10) regressor vectors of the region's cell centres (columns REGRESSORS),
            the query points for the expected variance reduction.
    """

    coefficient: str
    axes: tuple[str, str]
    bounds: dict[str, tuple[float, float]]
    center: dict[str, float]
    mean_rel_sigma: float
    max_rel_sigma: float
    n_points: int
    n_cells: int
    label: int
    reason: str
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, len(REGRESSORS))))

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict (``points`` left out; :meth:`EnvelopeMap.from_dict` rebuilds them)."""
        return {
            "coefficient": self.coefficient, "axes": list(self.axes),
            "bounds": {k: [float(a), float(b)] for k, (a, b) in self.bounds.items()},
            "center": {k: float(v) for k, v in self.center.items()},
            "mean_rel_sigma": _f(self.mean_rel_sigma), "max_rel_sigma": _f(self.max_rel_sigma),
            "n_points": int(self.n_points), "n_cells": int(self.n_cells), "label": int(self.label),
            "reason": self.reason,
        }

    @staticmethod
    def from_dict(d: dict[str, Any], points: np.ndarray | None = None) -> "FlaggedRegion":
        """Inverse of :meth:`to_dict`; ``points`` (K, 10) as rebuilt by the caller."""
        pts = np.zeros((0, len(REGRESSORS))) if points is None else np.asarray(points, float)
        return FlaggedRegion(d["coefficient"], tuple(d["axes"]),
                             {k: (float(v[0]), float(v[1])) for k, v in d["bounds"].items()},
                             {k: float(v) for k, v in d["center"].items()}, _nan(d["mean_rel_sigma"]),
                             _nan(d["max_rel_sigma"]), int(d["n_points"]), int(d["n_cells"]), int(d["label"]),
                             d["reason"], pts)


@dataclass
class EnvelopeSlice:
    """One 2-D slice of the envelope.

    Attributes:
        axes: (x, y) regressor names.
        x_edges, y_edges: cell edges, SI, shapes (nx+1,), (ny+1,).
        counts: training samples per cell, shape (ny, nx) (row = y index).
        sigma: coefficient -> predictive sigma at the cell centres, shape (ny, nx).
        rel_sigma: coefficient -> sigma / RMS spread, shape (ny, nx).
        labels: coefficient -> region labels of the cells, shape (ny, nx): 0 not flagged, k > 0 the
            cell belongs to this slice's k-th region of that coefficient (``FlaggedRegion.label``).
    """

    axes: tuple[str, str]
    x_edges: np.ndarray
    y_edges: np.ndarray
    counts: np.ndarray
    sigma: dict[str, np.ndarray]
    rel_sigma: dict[str, np.ndarray]
    labels: dict[str, np.ndarray]

    def flagged(self, coefficient: str) -> np.ndarray:
        """Bool mask (ny, nx) of the flagged cells of one coefficient."""
        lab = self.labels.get(coefficient)
        return np.zeros(self.counts.shape, bool) if lab is None else lab > 0

    @property
    def x_centers(self) -> np.ndarray:
        """Cell centres on the x axis, shape (nx,)."""
        return 0.5 * (self.x_edges[1:] + self.x_edges[:-1])

    @property
    def y_centers(self) -> np.ndarray:
        """Cell centres on the y axis, shape (ny,)."""
        return 0.5 * (self.y_edges[1:] + self.y_edges[:-1])

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict (``sigma`` is left out: it is ``rel_sigma`` times the map's spread)."""
        return {
            "axes": list(self.axes), "x_edges": _lst(self.x_edges), "y_edges": _lst(self.y_edges),
            "counts": self.counts.astype(int).tolist(),
            "rel_sigma": {k: _lst(np.round(v, 5)) for k, v in self.rel_sigma.items()},
            "labels": {k: v.astype(int).tolist() for k, v in self.labels.items()},
        }

    @staticmethod
    def from_dict(d: dict[str, Any], spread: dict[str, float] | None = None) -> "EnvelopeSlice":
        """Inverse of :meth:`to_dict`; ``spread`` (coefficient -> RMS spread) restores ``sigma``."""
        arr = lambda v: np.asarray(v, float)  # noqa: E731
        rel = {k: arr(v) for k, v in d["rel_sigma"].items()}
        sig = {k: v * (spread or {}).get(k, np.nan) for k, v in rel.items()}
        return EnvelopeSlice(tuple(d["axes"]), arr(d["x_edges"]), arr(d["y_edges"]),
                             np.asarray(d["counts"], int), sig, rel,
                             {k: np.asarray(v, int) for k, v in d["labels"].items()})


@dataclass
class EnvelopeMap:
    """The confidence map: slices, flagged regions and per-coefficient scores.

    Attributes:
        outputs: coefficients the model predicts (columns of its mean/var), subset of COEFFICIENTS.
        slices: the 2-D slices.
        regions: flagged regions, most uncertain first.
        scores: coefficient -> confidence score in [0, 1] (module docstring).
        spread: coefficient -> RMS spread (std) of the measured training samples.
        thresholds: coefficient -> relative-sigma threshold used for flagging.
        reference: regressor -> value held for the axes not in a slice (training medians), SI.
        flown: axis -> (lo, hi) flown range (quantiles of the training samples), SI.
        limits: axis -> (lo, hi) grid range (the envelope of interest), SI.
        n_train: training samples used for the counts.
    """

    outputs: tuple[str, ...]
    slices: list[EnvelopeSlice]
    regions: list[FlaggedRegion]
    scores: dict[str, float]
    spread: dict[str, float]
    thresholds: dict[str, float]
    reference: dict[str, float]
    flown: dict[str, tuple[float, float]]
    limits: dict[str, tuple[float, float]]
    n_train: int

    def weakest(self) -> list[str]:
        """Coefficients ordered from the lowest confidence score to the highest."""
        return sorted(self.scores, key=lambda k: (self.scores[k], k))

    def regions_of(self, coefficient: str) -> list[FlaggedRegion]:
        """Flagged regions of one coefficient."""
        return [r for r in self.regions if r.coefficient == coefficient]

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict (all arrays as nested lists)."""
        pair = lambda d: {k: [float(a), float(b)] for k, (a, b) in d.items()}  # noqa: E731
        return {
            "outputs": list(self.outputs), "slices": [s.to_dict() for s in self.slices],
            "regions": [r.to_dict() for r in self.regions],
            "scores": {k: _f(v) for k, v in self.scores.items()},
            "spread": {k: _f(v) for k, v in self.spread.items()},
            "thresholds": {k: _f(v) for k, v in self.thresholds.items()},
            "reference": {k: _f(v) for k, v in self.reference.items()},
            "flown": pair(self.flown), "limits": pair(self.limits), "n_train": int(self.n_train),
        }

    @staticmethod
    def from_dict(d: dict[str, Any]) -> "EnvelopeMap":
        """Inverse of :meth:`to_dict`."""
        pair = lambda m: {k: (float(a), float(b)) for k, (a, b) in m.items()}  # noqa: E731
        fl = lambda m: {k: _nan(v) for k, v in m.items()}  # noqa: E731
        spread, reference = fl(d["spread"]), fl(d["reference"])
        slices = [EnvelopeSlice.from_dict(s, spread) for s in d["slices"]]
        by_axes = {s.axes: s for s in slices}
        ref_vec = np.array([reference.get(r, np.nan) for r in REGRESSORS])
        regions = []
        for rd in d["regions"]:
            sl = by_axes.get(tuple(rd["axes"]))
            pts = None if sl is None else _cells_points(sl, rd["coefficient"], int(rd["label"]), ref_vec)
            regions.append(FlaggedRegion.from_dict(rd, pts))
        return EnvelopeMap(tuple(d["outputs"]), slices, regions, fl(d["scores"]), spread, fl(d["thresholds"]),
                           reference, pair(d["flown"]), pair(d["limits"]), int(d["n_train"]))


# ----------------------------------------------------------------------------- helpers


def model_variance(fn: Any, *args: Any) -> np.ndarray:
    """Call ``model.predict`` (returns the variance) or ``model.variance_after`` without the noise term.

    The map and the variance-reduction ranking are about what the model does not know, so the
    latent (epistemic) variance is used where the model offers ``include_noise=False``
    (``gcs_sysid.gp``); a model without that option gives its predictive variance.
    """
    import inspect

    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        params = {}
    kw = {k: False for k in ("include_noise", "input_noise") if k in params}   # epistemic only (docs/gp.md)
    out = fn(*args, **kw)
    return np.asarray(out[1] if isinstance(out, tuple) else out, float)


def variance_in_chunks(fn: Any, X: np.ndarray, chunk: int = MAP_CHUNK) -> np.ndarray:
    """:func:`model_variance` of ``fn`` at ``X (N, D)``, evaluated ``chunk`` rows at a time.

    When ``N > chunk`` each call gets ``chunk`` rows, the last one a multiple of ``chunk / 4`` (padded
    by repeating its last row, the padding's outputs dropped), so a compiled model sees at most four
    input shapes (for a given ``N``, two), and at most one chunk's temporaries are alive at once. Rows are predicted
    independently, so the result equals one call on all rows (to rounding; a test checks 1e-9).

    Args:
        fn: ``model.predict`` (or any callable accepted by :func:`model_variance`).
        X: ``(N, D)`` query rows.
        chunk: rows per call (>= 1).

    Returns:
        ``(N, P)`` variance (``(0, 0)`` for ``N = 0``).

    Raises:
        InputError: ``chunk`` < 1.
    """
    if int(chunk) < 1:
        raise InputError(f"variance_in_chunks: chunk must be >= 1, got {chunk}")
    X = np.asarray(X, float)
    n, chunk = len(X), int(chunk)
    if n == 0:
        return np.zeros((0, 0))
    parts = []
    for a in range(0, n, chunk):
        block = X[a:a + chunk]
        m = len(block)
        if m < chunk and n > chunk:   # few shapes: the last chunk padded to a multiple of chunk / 4
            q = max(chunk // 4, 1)
            block = np.vstack([block, np.repeat(block[-1:], -m % q, axis=0)])
        parts.append(model_variance(fn, block)[:m])
    return np.concatenate(parts, axis=0)


def _f(v: float) -> float | None:
    v = float(v)
    return v if np.isfinite(v) else None


def _nan(v: Any) -> float:
    return float("nan") if v is None else float(v)


def _lst(a: np.ndarray) -> list:
    """Nested lists with non-finite values as None (strict JSON)."""
    a = np.asarray(a, float)
    out = a.round(10).astype(object)
    out[~np.isfinite(a)] = None
    return out.tolist()


def _cells_points(sl: EnvelopeSlice, coef: str, label: int, ref_vec: np.ndarray) -> np.ndarray:
    """Regressor vectors (K, 10) of the cells of region ``label`` of ``coef`` on slice ``sl``."""
    sx, sy = sl.axes
    gx, gy = np.meshgrid(sl.x_centers, sl.y_centers)
    inside = sl.labels.get(coef, np.zeros(gx.shape, int)) == label
    P = np.tile(ref_vec, (int(inside.sum()), 1))
    P[:, REGRESSORS.index(sx)] = gx[inside]
    P[:, REGRESSORS.index(sy)] = gy[inside]
    return P


def _axis_ranges(Xt: np.ndarray, cfg: EnvelopeConfig) -> tuple[dict, dict, dict]:
    flown, limits, ref = {}, {}, {}
    for name in REGRESSORS:
        col = Xt[:, REGRESSORS.index(name)]
        ref[name] = float(np.median(col))
    for name in ENVELOPE_AXES:
        col = Xt[:, REGRESSORS.index(name)]
        lo, hi = (float(v) for v in np.quantile(col, cfg.quantiles))
        flown[name] = (lo, hi)
        if name in cfg.limits:
            a, b = (float(v) for v in cfg.limits[name])
            if not (np.isfinite(a) and np.isfinite(b) and a < b):
                raise InputError(f"envelope limits for '{name}' must be finite (lo, hi) with lo < hi, got {a}, {b}")
            limits[name] = (a, b)
            continue
        span = hi - lo
        a, b = lo - cfg.margin * span, hi + cfg.margin * span
        h = _MIN_HALF_SPAN[name]
        mid = ref[name]
        a, b = min(a, mid - h), max(b, mid + h)
        if name == "V":
            a = max(a, 0.5 * lo, 1.0)
        limits[name] = (a, b)
    return flown, limits, ref


def _slice_reason(n_empty: int, n_cells: int, mean_rel: float, thr: float) -> str:
    parts = []
    if n_empty:
        parts.append(f"no training data in {n_empty} of {n_cells} cells")
    if mean_rel > thr:
        parts.append(f"mean predictive sigma {mean_rel:.2f} x spread (threshold {thr:.2f})")
    else:
        parts.append(f"mean predictive sigma {mean_rel:.2f} x spread")
    return "; ".join(parts)


# ----------------------------------------------------------------------------- main entry


def confidence_map(model: Any, table: CoefficientTable, train_mask: np.ndarray,
                   config: EnvelopeConfig | None = None, outputs: Sequence[str] | None = None) -> EnvelopeMap:
    """Map the model's predictive uncertainty and the data density over the flight envelope.

    Args:
        model: fitted model with ``predict(X) -> (mean (N, P), var (N, P))``, X of shape
            (N, 10) in :data:`~gcs_sysid.aero.table.REGRESSORS` order; the latent variance is used
            where ``predict`` takes ``include_noise`` (:func:`model_variance`).
        table: the coefficient table the model was fitted on, T rows.
        train_mask: (T,) bool, the rows used for fitting.
        config: grid and flagging settings (defaults: :class:`EnvelopeConfig`).
        outputs: coefficient names of the model's P output columns (default all six).

    Returns:
        The :class:`EnvelopeMap`; regions sorted by mean relative sigma, largest first.

    Raises:
        InputError: a slice names an unknown axis, bad limits, or outputs not coefficients.
        DataError: fewer than 2 finite training rows.

    Source: relative predictive sigma over envelope slices, as in Morelli and Klein (2016)
    ch. 9 (input design where information is missing); module docstring.
    """
    cfg = config or EnvelopeConfig()
    outs = tuple(outputs) if outputs is not None else COEFFICIENTS
    for o in outs:
        if o not in COEFFICIENTS:
            raise InputError(f"confidence_map: output '{o}' is not one of {', '.join(COEFFICIENTS)}")
    for sx, sy in cfg.slices:
        for a in (sx, sy):
            if a not in ENVELOPE_AXES:
                raise InputError(f"confidence_map: slice axis '{a}' is not one of {', '.join(ENVELOPE_AXES)}")
    if cfg.n_grid < 2:
        raise InputError(f"confidence_map: n_grid must be >= 2, got {cfg.n_grid}")
    mask = np.asarray(train_mask, bool) & np.all(np.isfinite(table.X), axis=1)
    Xt = table.X[mask]
    if len(Xt) < 2:
        raise DataError(f"confidence_map: only {len(Xt)} finite training rows, need at least 2")
    Yt = table.Y[mask]
    flown, limits, ref = _axis_ranges(Xt, cfg)
    spread = {}
    for o in outs:
        y = Yt[:, COEFFICIENTS.index(o)]
        y = y[np.isfinite(y)]
        spread[o] = float(np.std(y)) if len(y) > 1 else float("nan")

    n = cfg.n_grid
    min_cells = cfg.min_region_cells if cfg.min_region_cells is not None else max(3, int(0.02 * n * n))
    ref_vec = np.array([ref[r] for r in REGRESSORS])
    grids, edges = [], []
    for sx, sy in cfg.slices:
        xe = np.linspace(*limits[sx], n + 1)
        ye = np.linspace(*limits[sy], n + 1)
        xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
        gx, gy = np.meshgrid(xc, yc)  # (ny, nx)
        G = np.tile(ref_vec, (n * n, 1))
        G[:, REGRESSORS.index(sx)] = gx.ravel()
        G[:, REGRESSORS.index(sy)] = gy.ravel()
        grids.append(G)
        edges.append((xe, ye))
    # all grid points and the training points (the sigma floor), in fixed-size chunks
    sub = Xt[np.linspace(0, len(Xt) - 1, min(len(Xt), 400)).astype(int)]
    var = variance_in_chunks(model.predict, np.vstack(grids + [sub]), cfg.chunk)
    sd = np.sqrt(np.maximum(var, 0.0))
    if sd.ndim != 2 or sd.shape[1] != len(outs):
        raise InputError(f"confidence_map: model variance has shape {sd.shape}, expected (N, {len(outs)})")
    sd_train = sd[n * n * len(grids):]
    thresholds = {}
    for j, o in enumerate(outs):
        floor = float(np.median(sd_train[:, j])) / spread[o] if spread[o] > 0 else np.nan
        thresholds[o] = float(max(cfg.rel_sigma_threshold, cfg.floor_factor * floor)) if np.isfinite(floor) \
            else cfg.rel_sigma_threshold

    slices: list[EnvelopeSlice] = []
    regions: list[FlaggedRegion] = []
    rel_all: dict[str, list[np.ndarray]] = {o: [] for o in outs}
    for k, (sx, sy) in enumerate(cfg.slices):
        xe, ye = edges[k]
        ix, iy = REGRESSORS.index(sx), REGRESSORS.index(sy)
        counts, _, _ = np.histogram2d(Xt[:, iy], Xt[:, ix], bins=[ye, xe])
        counts = counts.astype(int)
        block = sd[k * n * n:(k + 1) * n * n]
        sl = EnvelopeSlice((sx, sy), xe, ye, counts, {}, {}, {})
        # "no data": no training sample in the cell nor its 8 neighbours (holes inside the cloud are
        # interpolated by the model, the sigma test covers them)
        near = ndimage.convolve(counts, np.ones((3, 3), int), mode="constant")
        empty = near < cfg.min_points
        for j, o in enumerate(outs):
            s = block[:, j].reshape(n, n)
            rel = s / spread[o] if spread[o] > 0 else np.full_like(s, np.nan)
            sl.sigma[o], sl.rel_sigma[o] = s, rel
            if not np.isfinite(rel).any():
                sl.labels[o] = np.zeros((n, n), int)
                continue
            rel_all[o].append(rel)
            thr = thresholds[o]
            flag = (rel > thr) | empty
            labels, nlab = _label_by_quadrant(flag, sl, ref[sx], ref[sy])
            keep = np.zeros((n, n), int)
            for lab in range(1, nlab + 1):
                cells = labels == lab
                if cells.sum() < min_cells:
                    continue
                keep[cells] = int(keep.max()) + 1
                regions.append(_region(o, sl, cells, int(keep.max()), rel, thr, ref, grids[k].reshape(n, n, -1)))
            sl.labels[o] = keep
        slices.append(sl)
    scores = {o: (float(1.0 - np.mean(np.minimum(np.concatenate([r.ravel() for r in rel_all[o]]), 1.0)))
                  if rel_all[o] else float("nan")) for o in outs}
    regions.sort(key=lambda r: (-r.mean_rel_sigma, r.coefficient, r.axes))
    return EnvelopeMap(outs, slices, regions, scores, spread, thresholds, ref, flown, limits, int(len(Xt)))


def _label_by_quadrant(flag: np.ndarray, sl: EnvelopeSlice, x0: float, y0: float) -> tuple[np.ndarray, int]:
    """Connected components of ``flag`` (ny, nx), split at the reference point into quadrants.

    The unflown margin around the data is one ring-shaped component; split into quadrants it
    becomes "high alpha, low V"-like corners whose centroids lie where the data are missing.
    """
    right = (sl.x_centers >= x0)[None, :]
    up = (sl.y_centers >= y0)[:, None]
    labels = np.zeros(flag.shape, int)
    total = 0
    for qx in (False, True):
        for qy in (False, True):
            lab, n = ndimage.label(flag & (right == qx) & (up == qy))
            labels[lab > 0] = lab[lab > 0] + total
            total += n
    return labels, total


def _region(coef: str, sl: EnvelopeSlice, cells: np.ndarray, label: int, rel: np.ndarray, thr: float,
            ref: dict[str, float], grid: np.ndarray) -> FlaggedRegion:
    sx, sy = sl.axes
    iy, ix = np.nonzero(cells)
    xe, ye = sl.x_edges, sl.y_edges
    bounds = {sx: (float(xe[ix.min()]), float(xe[ix.max() + 1])), sy: (float(ye[iy.min()]), float(ye[iy.max() + 1]))}
    r = rel[cells]
    w = np.where(np.isfinite(r), r, 0.0) + 1e-12
    center = dict(ref)
    center[sx] = float(np.sum(w * sl.x_centers[ix]) / w.sum())
    center[sy] = float(np.sum(w * sl.y_centers[iy]) / w.sum())
    n_empty = int((sl.counts[cells] == 0).sum())
    mean_rel = float(np.nanmean(r))
    return FlaggedRegion(coef, (sx, sy), bounds, center, mean_rel, float(np.nanmax(r)),
                         int(sl.counts[cells].sum()), int(cells.sum()), label,
                         _slice_reason(n_empty, int(cells.sum()), mean_rel, thr), grid[cells].copy())
