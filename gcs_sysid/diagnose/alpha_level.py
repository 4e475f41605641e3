"""The level of the reconstructed angle of attack, fixed by a lift curve pooled over flights.

The aided alpha (:mod:`gcs_sysid.estimation.airangles`) carries an error common to the whole flight: the
flight-mean vertical wind of the turbulence's slow part over the airspeed, ``mean(w_d) cos(theta) / V``
(``FlightStates.offsets["alpha"]``). One flight cannot observe it: a constant in alpha goes into ``CZ0``.
On slow aircraft it dominates alpha's error (JSBSim Eternity at 17 m/s: 1.7-2.5 deg RMS on a 0.8-deg signal;
c172p about 1 deg; ``docs/benchmarks.md``, "Twenty-first session, i8-aid"), and a diagnosis that compares two
flights reads the two levels' difference as a change of every alpha term.

The flight-test remedy is to pool the lift curve over flights (Jategaonkar, *Flight Vehicle System
Identification*, 2nd ed., 2015, sec. 10.4, flight-path reconstruction with several manoeuvres analysed together
and common aerodynamic parameters; Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016, sec. 10.2,
bias parameters per manoeuvre): the aerodynamics are common to all flights, each flight has its own angle offset,
and only the offsets' mean is unobservable. Here

1. the model's lift curve (its ``CZ``, fitted on the first reference flight) fixes each flight's alpha offset
   against that reference, :func:`level_offset`: the ``d`` that makes the flight's measured ``CZ`` agree with
   ``CZ_model(alpha - d, ...)`` (Gauss-Newton on every valid row; standard error by batch means over blocks,
   since the residual is turbulence-coloured);
2. over ``K`` level flights (the reference flights) the pooled level is ``L = mean_k d_k`` (``d_1 = 0`` for the
   reference the model was fitted on), :func:`pool_levels`: the frame in which the flights' mean vertical wind
   averages out. The remaining error of the frame is the mean of the ``K`` flights' own levels, about
   ``sd(d_k) / sqrt(K)``, which no data from these flights can reduce;
3. every flight is moved into that frame (``alpha - d + L``) and the model with it (:func:`shift_model_alpha`,
   exact for the model's terms of degree <= 2), :func:`align_alpha_levels`.

With one reference (``mode="reference"``) ``L = 0``: the flight under test is moved into the reference flight's
alpha frame, and the reference's own level error stays (on the Eternity's reference flight +3.3 deg).

What an offset cannot be told from, and how the diagnosis keeps it visible: anything that changes the normal
force by a constant at a given alpha. A real ``CZ0`` change (flap, icing, a lift-curve shift) is read as an alpha
offset ``-dCZ0 / CZ_alpha``; a pitot scale error (``bias:airspeed``) scales the measured ``CZ`` and partly reads
as one too. A centre-of-gravity change moves ``Cm0`` and the trim, not the lift curve at a given alpha and
elevator, so it is not absorbed. The offset found is reported (``data["alpha_level"]``: offset, standard error,
the pooled level and its remaining error), and beside it the ``Cm`` residual level the offset implies through
the model's pitch curve (``cm_level_implied``) beside the ``Cm`` residual level measured before the shift
(``cm_level_measured``): a true alpha offset moves both, a ``CZ0`` change moves only ``CZ`` (a ``Cm0`` change of
its own, e.g. the cg, also moves the measured one, so this is evidence to read, not a test). The option is off by
default (:data:`gcs_sysid.diagnose.run.ALPHA_LEVEL`).
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from ..errors import InputError
from .context import ModelDict, evaluate_model, model_as_dict
from .terms import canonical_term, term_factors

__all__ = ["ALPHA_LEVEL_MODES", "SHIFT_KEY", "level_offset", "pool_levels", "shift_model_alpha", "shift_alpha",
           "align_alpha_levels"]

#: The accepted modes: ``"reference"`` (the test flight in the first reference flight's alpha frame) and
#: ``"pooled"`` (every flight in the frame of the reference flights' mean level).
ALPHA_LEVEL_MODES = ("reference", "pooled")

_IA = REGRESSORS.index("alpha")
_JZ = COEFFICIENTS.index("CZ")
_JM = COEFFICIENTS.index("Cm")


def level_offset(t: np.ndarray, X: np.ndarray, Y: np.ndarray, valid: np.ndarray, model: ModelDict,
                 block_s: float = 8.0, min_slope: float = 0.5, iterations: int = 4) -> dict:
    """The alpha offset of a flight against a model's lift curve.

    Solves ``min_d sum_rows (CZ_meas - CZ_model(alpha - d, ...))^2`` by Gauss-Newton (exact in one step for a
    lift curve linear in alpha). Its standard error is from batch means: the rows' contributions
    ``g r`` are summed over ``block_s`` blocks and the blocks treated as independent (the residual is
    turbulence-coloured over a second or two; Flyvbjerg and Petersen, J. Chem. Phys. 91, 461, 1989).

    Args:
        t: (T,) time, s. X: (T, 10) regressors (:data:`REGRESSORS`, alpha in rad). Y: (T, 6) measured
            coefficients (:data:`COEFFICIENTS`). valid: (T,) rows to use.
        model: ``{coef: {term: value}}`` (:func:`gcs_sysid.diagnose.context.model_as_dict`).
        block_s: batch-means block length, s.
        min_slope: the model's ``|dCZ/dalpha|`` (1/rad) below which no offset is estimated.
        iterations: Gauss-Newton steps.

    Returns:
        ``{"offset_rad", "std_error_rad", "n_rows", "slope_per_rad", "cz_rms"}``; ``offset_rad`` is NaN when fewer
        than 50 usable rows or the lift curve is flat (then the flight is left as it is).
    """
    X = np.asarray(X, float)
    ok = np.asarray(valid, bool) & np.all(np.isfinite(X), axis=1) & np.isfinite(np.asarray(Y, float)[:, _JZ])
    out = {"offset_rad": float("nan"), "std_error_rad": float("nan"), "n_rows": int(ok.sum()),
           "slope_per_rad": float("nan"), "cz_rms": float("nan")}
    if ok.sum() < 50 or not model.get("CZ"):
        return out
    Xo, y, to = X[ok], np.asarray(Y, float)[ok, _JZ], np.asarray(t, float)[ok]
    d, h = 0.0, 1e-4
    for _ in range(iterations):
        Xs = Xo.copy()
        Xs[:, _IA] -= d
        cz = evaluate_model(model, Xs)[:, _JZ]
        Xp = Xs.copy()
        Xp[:, _IA] += h
        g = (evaluate_model(model, Xp)[:, _JZ] - cz) / h           # dCZ/dalpha at the shifted alpha, 1/rad
        if abs(np.mean(g)) < min_slope:
            return out
        r = y - cz
        # CZ(alpha - d - dd) ~ CZ(alpha - d) - g dd: the step that removes the residual's projection on -g
        dd = -float(np.dot(g, r) / np.dot(g, g))
        d += dd
        if abs(dd) < 1e-7:
            break
    Xs = Xo.copy()
    Xs[:, _IA] -= d
    cz = evaluate_model(model, Xs)[:, _JZ]
    r = y - cz
    blk = np.floor((to - to[0]) / block_s).astype(int)
    contrib = np.bincount(blk, weights=g * r)
    nb = int(np.count_nonzero(np.bincount(blk)))
    se = float(np.sqrt(nb / max(nb - 1, 1) * np.sum(contrib ** 2)) / np.dot(g, g)) if nb > 1 else float("nan")
    out.update(offset_rad=float(d), std_error_rad=se, slope_per_rad=float(np.mean(g)),
               cz_rms=float(np.sqrt(np.mean(r ** 2))))
    return out


def pool_levels(offsets) -> dict:
    """The pooled level of ``K`` flights' offsets against one lift curve.

    Args:
        offsets: ``K`` offsets, rad (the first is the reference's own, ~0).

    Returns:
        ``{"level_rad": mean, "frame_error_rad": sd / sqrt(K)`` (the remaining error of the pooled frame if the
        flights' levels are independent draws; NaN for ``K = 1``: one flight's own level is not observable),
        ``"between_flight_sd_rad", "k"}``.
    """
    d = np.asarray([o for o in offsets if np.isfinite(o)], float)
    if d.size == 0:
        return {"level_rad": 0.0, "frame_error_rad": float("nan"), "between_flight_sd_rad": float("nan"), "k": 0}
    sd = float(np.std(d, ddof=1)) if d.size > 1 else float("nan")
    return {"level_rad": float(np.mean(d)), "frame_error_rad": sd / np.sqrt(d.size) if d.size > 1 else float("nan"),
            "between_flight_sd_rad": sd, "k": int(d.size)}


def shift_model_alpha(model, level: float) -> ModelDict:
    """The model re-expressed for an alpha frame moved by ``level``: ``M'(alpha, ...) = M(alpha - level, ...)``.

    Exact for the model's vocabulary (monomials of degree <= 2, :mod:`gcs_sysid.diagnose.terms`):
    ``alpha -> alpha - L``, ``alpha^2 -> alpha^2 - 2 L alpha + L^2``, ``alpha*x -> alpha*x - L x``.

    Args:
        model: the model (anything :func:`model_as_dict` accepts). level: ``L``, rad.

    Returns:
        a new ``{coef: {term: value}}``.
    """
    m = model_as_dict(model)
    if level == 0.0:
        return {c: dict(v) for c, v in m.items()}
    out: ModelDict = {c: {} for c in m}

    def add(coef, term, val):
        term = canonical_term(term)
        out[coef][term] = out[coef].get(term, 0.0) + val

    for coef, terms in m.items():
        for term, val in terms.items():
            f = term_factors(term)
            add(coef, term, val)
            n_alpha = f.count(_IA)
            if n_alpha == 1 and len(f) == 1:
                add(coef, "1", -level * val)
            elif n_alpha == 1:
                other = REGRESSORS[f[0] if f[1] == _IA else f[1]]
                add(coef, other, -level * val)
            elif n_alpha == 2:
                add(coef, "alpha", -2.0 * level * val)
                add(coef, "1", level * level * val)
    return out


#: The ``FlightStates.data`` key under which :func:`shift_alpha` records the shift it applied, rad, (T,) constant:
#: a flight reduced again from its log (the pitot's exact re-fit,
#: :func:`gcs_sysid.diagnose.pitot._unit_delta_rereduced`) comes back in the log's own alpha frame and must be brought
#: into the common one before it is compared.
SHIFT_KEY = "alpha_level_shift"


def shift_alpha(table, states, shift: float):
    """Copies of a flight's coefficient table and states with alpha moved by ``shift`` (rad; new = old + shift).

    Only the alpha column of ``table.X`` and ``states.data["alpha"]`` change, and the shift is recorded as
    ``states.data[SHIFT_KEY]`` (T,) (added to what an earlier shift recorded); the arrays are copied, the inputs
    are left as they were. ``states`` may be None.
    """
    X = np.array(table.X, float, copy=True)
    X[:, _IA] += shift
    tab = replace(table, X=X)
    if states is None or "alpha" not in getattr(states, "data", {}):
        return tab, states
    st = copy.copy(states)
    st.data = dict(states.data)
    st.data["alpha"] = np.asarray(states.data["alpha"], float) + shift
    st.data[SHIFT_KEY] = np.asarray(states.data.get(SHIFT_KEY, 0.0), float) + np.full(len(st.data["alpha"]), shift)
    return tab, st


def _level_of(table, model) -> dict:
    return level_offset(table.t, table.X, table.Y, table.valid, model)


def align_alpha_levels(mode: str, model, table, states, references=(), level_tables=()):
    """Move the flight under test, its reference flights and the model into one alpha frame.

    Args:
        mode: ``"reference"`` (the frame of the first reference, the one the model was fitted on) or
            ``"pooled"`` (the mean level of the first reference and the ``level_tables``' flights).
        model: the model under test (fitted on ``references[0]``).
        table, states: the flight under test (:class:`~gcs_sysid.aero.table.CoefficientTable`, FlightStates).
        references: :class:`gcs_sysid.diagnose.differential.Reference` objects (moved too; new objects).
        level_tables: more flights' coefficient tables of the same aircraft, used only for the pooled level.

    Returns:
        ``(model', table', states', references', info)``; ``info`` (JSON-able, degrees where named ``_deg``)
        is what ``data["alpha_level"]`` reports. Where the flight's offset cannot be estimated everything is
        returned unchanged, with the reason in ``info["why"]``.

    Raises:
        InputError: an unknown mode.
    """
    if mode not in ALPHA_LEVEL_MODES:
        raise InputError(f"alpha level: unknown mode '{mode}' (expected one of {', '.join(ALPHA_LEVEL_MODES)})")
    m0 = model_as_dict(model)
    refs = list(references or ())
    own = _level_of(table, m0)
    info = {"mode": mode, "offset_deg": float(np.degrees(own["offset_rad"])),
            "std_error_deg": float(np.degrees(own["std_error_rad"])), "n_rows": own["n_rows"],
            "cz_slope_per_rad": own["slope_per_rad"]}
    if not np.isfinite(own["offset_rad"]):
        info["why"] = "no offset estimated (too few rows, or no lift slope in the model's CZ): alpha left as it is"
        return m0, table, states, refs, info
    ref_offsets = [_level_of(r.table, m0)["offset_rad"] for r in refs]
    if mode == "pooled":
        pool_in = ref_offsets[:1] + [_level_of(t, m0)["offset_rad"] for t in level_tables]
    else:
        pool_in = ref_offsets[:1] or [0.0]
    pool = pool_levels(pool_in) if mode == "pooled" else {"level_rad": 0.0, "frame_error_rad": float("nan"),
                                                             "between_flight_sd_rad": float("nan"), "k": 1}
    L = pool["level_rad"]
    # the Cm level the offset implies through the model's pitch curve, against the measured change of Cm's level
    Xc = np.nan_to_num(np.asarray(table.X, float))
    ok = np.asarray(table.valid, bool) & np.isfinite(np.asarray(table.Y, float)[:, _JM])
    Xs = Xc.copy()
    Xs[:, _IA] -= own["offset_rad"]
    dcz = evaluate_model(m0, Xs)[ok] - evaluate_model(m0, Xc)[ok]
    rm = np.asarray(table.Y, float)[ok, _JM] - evaluate_model(m0, Xc)[ok, _JM]
    info.update(level_deg=float(np.degrees(L)), frame_error_deg=float(np.degrees(pool["frame_error_rad"])),
                between_flight_sd_deg=float(np.degrees(pool["between_flight_sd_rad"])), level_flights=pool["k"],
                reference_offsets_deg=[float(np.degrees(o)) for o in ref_offsets],
                level_flight_offsets_deg=[float(np.degrees(o)) for o in pool_in],
                shift_deg=float(np.degrees(L - own["offset_rad"])),
                cm_level_implied=float(np.mean(dcz[:, _JM])) if ok.any() else float("nan"),
                cm_level_measured=float(np.mean(rm)) if ok.any() else float("nan"))
    model1 = shift_model_alpha(m0, L)
    tab1, st1 = shift_alpha(table, states, L - own["offset_rad"])
    refs1 = []
    for r, d in zip(refs, ref_offsets):
        if not np.isfinite(d):
            d = 0.0
        rt, rs = shift_alpha(r.table, r.states, L - d)
        refs1.append(replace(r, table=rt, states=rs))
    return model1, tab1, st1, refs1, info
