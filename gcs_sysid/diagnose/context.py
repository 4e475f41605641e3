"""What the diagnosis works on: the measured table, extra states, the model and the split.

:class:`DiagContext` bundles the coefficient table, the states the physical
candidates need (Euler angles, rate derivatives), the airframe, the model under
test as ``{coef: {term: value}}``, the training / held-out masks and the weights
of the six coefficients. Helpers evaluate the model and the rigid-body moment
equations the estimation layer used, so a candidate can recompute "what the
coefficients would have been" under a hypothesised cause.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from ..airframe import Airframe
from ..errors import InputError
from .terms import canonical_term, term_matrix

__all__ = ["DiagContext", "model_as_dict", "evaluate_model", "euler_moments", "held_out_blocks", "ModelDict"]

ModelDict = dict[str, dict[str, float]]


def model_as_dict(model) -> ModelDict:
    """The model under test as ``{coef: {canonical term: value}}``.

    Accepts a plain mapping or a :class:`gcs_sysid.sim.model_file.AeroModel`
    (anything with ``as_dict()``, ``to_dict()``, ``coefficients`` or ``terms``).

    Raises:
        InputError: unknown coefficient or term, or a non-numeric value.
    """
    raw = None
    for attr in ("as_dict", "to_dict"):
        if hasattr(model, attr):
            raw = getattr(model, attr)()
            break
    if raw is None:
        for attr in ("coefficients", "terms"):
            if hasattr(model, attr) and isinstance(getattr(model, attr), dict):
                raw = getattr(model, attr)
                break
    if raw is None:
        raw = model
    if not isinstance(raw, dict):
        raise InputError(f"model: expected a mapping coefficient -> {{term: value}}, got {type(model).__name__}")
    out: ModelDict = {c: {} for c in COEFFICIENTS}
    for coef, terms in raw.items():
        if coef not in COEFFICIENTS:
            if coef in ("meta", "name", "notes", "source", "effects", "model", "description", "version"):
                continue
            raise InputError(f"model: unknown coefficient '{coef}' (expected one of {', '.join(COEFFICIENTS)})")
        if not isinstance(terms, dict):
            raise InputError(f"model: [{coef}] must map terms to numbers")
        for term, val in terms.items():
            if isinstance(val, bool) or not isinstance(val, (int, float, np.floating)):
                raise InputError(f"model: {coef} term '{term}' must be a number, got {val!r}")
            ct = canonical_term(term)
            out[coef][ct] = out[coef].get(ct, 0.0) + float(val)
    return out


def evaluate_model(model: ModelDict, X: np.ndarray) -> np.ndarray:
    """Model coefficients on regressors ``X`` (T, 10) -> (T, 6) (columns COEFFICIENTS)."""
    out = np.zeros((X.shape[0], len(COEFFICIENTS)))
    for j, coef in enumerate(COEFFICIENTS):
        terms = model.get(coef, {})
        if terms:
            names = list(terms)
            out[:, j] = term_matrix(X, names) @ np.array([terms[t] for t in names])
    return out


def euler_moments(I: np.ndarray, pqr: np.ndarray, pqr_dot: np.ndarray) -> np.ndarray:
    """Aerodynamic moments from Euler's equations, ``M = I w_dot + w x (I w)``.

    Args:
        I: inertia tensor (3, 3), kg m^2 (``[[Ixx,0,-Ixz],[0,Iyy,0],[-Ixz,0,Izz]]``).
        pqr, pqr_dot: body rates (T, 3) rad/s and their derivatives (T, 3) rad/s^2.

    Returns:
        moments (T, 3) in N m (L, M, N). Source: Stevens, Lewis and Johnson,
        *Aircraft Control and Simulation*, 3rd ed., eq. 1.7-18.
    """
    return pqr_dot @ I.T + np.cross(pqr, pqr @ I.T)


def held_out_blocks(t: np.ndarray, valid: np.ndarray, block_s: float = 8.0, every: int = 3,
                    guard_s: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Split into training and held-out rows by interleaved time blocks.

    Every ``every``-th block of ``block_s`` seconds (starting with the second) is
    held out, so both parts see the same maneuvers; ``guard_s`` either side of a
    held-out block belongs to neither (residuals are coloured).

    Returns:
        (train, test) boolean masks of shape (T,).
    """
    t = np.asarray(t, float)
    k = np.floor((t - t[0]) / block_s).astype(int)
    test = (k % every) == 1
    edges = t[1:][test[1:] != test[:-1]]          # times where the label changes
    guard = np.zeros(t.shape, bool)
    if edges.size:
        idx = np.searchsorted(edges, t)
        d_next = np.abs(edges[np.minimum(idx, edges.size - 1)] - t)
        d_prev = np.abs(t - edges[np.maximum(idx - 1, 0)])
        guard = np.minimum(d_next, d_prev) < guard_s
    train = valid & ~test & ~guard
    test = valid & test & ~guard
    return train, test


@dataclass
class DiagContext:
    """Inputs of the diagnosis, on the table's time grid.

    Attributes:
        t: (T,) vehicle time, s. X: (T, 10) regressors. Y: (T, 6) measured coefficients.
        qbar: (T,) Pa. valid: (T,) rows usable at all.
        states: key -> (T,) extra states (``phi theta psi p_dot q_dot r_dot``...), may be partial.
        airframe: the airframe the coefficients were computed with.
        model: the model under test, ``{coef: {term: value}}``.
        train, test: (T,) masks (training and held-out rows).
        weight: (6,) per-coefficient weights ``1 / sigma_c^2`` from the baseline residual (0 if inactive).
        active: (6,) coefficients taking part (False where the table's notes say "not identifiable").
        notes: remarks collected on the way.
    """

    t: np.ndarray
    X: np.ndarray
    Y: np.ndarray
    qbar: np.ndarray
    valid: np.ndarray
    states: dict[str, np.ndarray]
    airframe: Airframe
    model: ModelDict
    train: np.ndarray
    test: np.ndarray
    weight: np.ndarray = field(default_factory=lambda: np.ones(6))
    notes: list[str] = field(default_factory=list)
    active: np.ndarray = field(default_factory=lambda: np.ones(6, bool))

    @staticmethod
    def build(table: CoefficientTable, airframe: Airframe, model, states=None, train=None, test=None,
              block_s: float = 8.0) -> "DiagContext":
        """Assemble a context from a table (and optionally its FlightStates on the same grid)."""
        md = model_as_dict(model)
        valid = np.asarray(table.valid, bool) & np.all(np.isfinite(table.X), axis=1) \
            & np.all(np.isfinite(table.Y), axis=1) & np.isfinite(table.qbar) & (table.qbar > 0)
        st: dict[str, np.ndarray] = {}
        if states is not None:
            if len(states) == len(table.t) and np.allclose(states.t, table.t):
                st = {k: np.asarray(v, float) for k, v in states.data.items()}
            else:
                st = {k: np.interp(table.t, states.t, np.asarray(v, float)) for k, v in states.data.items()}
        if train is None or test is None:
            train, test = held_out_blocks(table.t, valid, block_s=block_s)
        ctx = DiagContext(np.asarray(table.t, float), np.asarray(table.X, float), np.asarray(table.Y, float),
                          np.asarray(table.qbar, float), valid, st, airframe, md, train & valid, test & valid)
        R = ctx.Y - ctx.model_values()
        sig = np.sqrt(np.mean(R[ctx.train] ** 2, axis=0)) if ctx.train.any() else np.ones(6)
        sig = np.where(np.isfinite(sig) & (sig > 0), sig, 1.0)
        ctx.weight = 1.0 / sig**2
        # coefficients the estimation layer says the data cannot support take no part
        for note in getattr(table, "notes", []):
            if "not identifiable" in note:
                head = note.split("not identifiable")[0]
                for j, c in enumerate(COEFFICIENTS):
                    if c in head.split():
                        ctx.active[j] = False
        if not ctx.active.all():
            ctx.weight = np.where(ctx.active, ctx.weight, 0.0)
            ctx.notes.append("left out of the diagnosis (not identifiable from these data): "
                             + ", ".join(c for c, a in zip(COEFFICIENTS, ctx.active) if not a))
        return ctx

    def rows(self, mask: np.ndarray) -> "DiagContext":
        """A context restricted to the rows where ``mask`` (T,) is True (for fitting)."""
        return DiagContext(self.t[mask], self.X[mask], self.Y[mask], self.qbar[mask], self.valid[mask],
                           {k: v[mask] for k, v in self.states.items()}, self.airframe, self.model,
                           self.train[mask], self.test[mask], self.weight, self.notes, self.active)

    def x(self, name: str) -> np.ndarray:
        """Regressor column by name, (T,)."""
        return self.X[:, REGRESSORS.index(name)]

    def model_values(self, X: np.ndarray | None = None, model: ModelDict | None = None) -> np.ndarray:
        """Model coefficients (T, 6) on ``X`` (default the table's)."""
        return evaluate_model(self.model if model is None else model, self.X if X is None else X)

    def has(self, *keys: str) -> bool:
        """True if all the given state keys are available and finite on the valid rows."""
        return all(k in self.states and np.all(np.isfinite(self.states[k][self.valid])) for k in keys)

    @property
    def rho(self) -> np.ndarray:
        """Air density (T,) kg/m^3 from qbar and V."""
        V = self.x("V")
        return 2.0 * self.qbar / np.maximum(V, 1e-3) ** 2

    def thrust(self, V: np.ndarray | None = None, delta_t: np.ndarray | None = None) -> np.ndarray:
        """Thrust (T,) N from the airframe's thrust model (0 without one)."""
        if self.airframe.thrust is None:
            return np.zeros_like(self.t)
        V = self.x("V") if V is None else V
        dt = self.x("delta_t") if delta_t is None else delta_t
        return np.asarray(self.airframe.thrust.thrust(np.nan_to_num(dt), V), float)

    def rates(self) -> np.ndarray:
        """Body rates (T, 3) rad/s from p_hat, q_hat, r_hat (or the states)."""
        if self.has("p", "q", "r"):
            return np.column_stack([self.states[k] for k in ("p", "q", "r")])
        V = np.maximum(self.x("V"), 1e-3)
        a = self.airframe
        return np.column_stack([self.x("p_hat") * 2 * V / a.b, self.x("q_hat") * 2 * V / a.c,
                                self.x("r_hat") * 2 * V / a.b])

    def moment_scale(self) -> np.ndarray:
        """(T, 3) divisors ``qbar S b``, ``qbar S c``, ``qbar S b`` of L, M, N."""
        a = self.airframe
        return self.qbar[:, None] * a.S * np.array([a.b, a.c, a.b])[None, :]
