"""Turbulence the flight-path reconstruction cannot see: profile it out of the equation error.

Alpha and beta reconstructed from GPS velocity, attitude and a windowed wind
(``gcs_sysid.estimation``) miss the gusts: with calm-morning Dryden turbulence
(W20 = 1.5 m/s) the vertical gust alone moves the true alpha by about 0.01 rad
RMS, as much as a sysid maneuver's alpha excitation. The measured coefficients
(from the accelerometers and gyros) do respond to the gusts, so every
coefficient's residual carries the same two unknown angle errors,

    r_t = g_alpha,t e_alpha,t + g_beta,t e_beta,t + n_t,

with loadings ``g = d model / d alpha`` and ``d model / d beta`` (the model's own
sensitivities: CZ, Cm and CX for alpha; CY, Cl and Cn for beta). Treating
``e_t`` as a nuisance parameter per sample and eliminating it by weighted least
squares across the six coefficients is the errors-in-variables remedy of
Morelli and Klein (*Aircraft System Identification*, 2nd ed., sec. 5.3 and
ch. 10: the force equations are the most accurate alpha/beta "sensor" in
turbulence): the residual is replaced by its projection

    P r_t = r_t - G_t ê_t,   ê_t = (G_t' W G_t)^-1 G_t' W r_t,

``W = diag(1 / sigma_c^2)`` the noise weights of the projected residuals
(iterated, with the leverage correction). (``keep_mean=True`` subtracts only
``ê_t - mean(ê)``; it is off because the reconstruction's own mean angle errors,
e.g. a 0.1 deg sideslip offset from the wind fit, would then pose as constant
aero terms.) The operator is linear, so candidate corrections are projected
with the same ``P`` and the held-out scores stay
consistent. It is switched on only when the angle errors fluctuate more than the
measurement noise alone would make them (``active``): a constant offset (a biased
alpha regressor) is not turbulence and is left to the catalogue causes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..aero.table import REGRESSORS
from .context import DiagContext

__all__ = ["GustProjector", "gust_projector"]

_IA, _IB = REGRESSORS.index("alpha"), REGRESSORS.index("beta")


@dataclass
class GustProjector:
    """The linear operator ``P`` above (apply with ``__call__`` to (T, 6) arrays).

    Attributes:
        G: (T, 6, k) loadings (k = 1 or 2: alpha, beta).
        H: (T, k, 6) ``(G' W G)^-1 G' W`` per row.
        mean_rows: (T,) rows whose mean of ``ê`` is kept (training rows).
        sigma: (6,) noise RMS of each coefficient after projection (the weights are ``1/sigma^2``).
        active: False when the data show no angle error beyond noise (``P`` is then the identity).
        angle_rms: (k,) standard deviation of the angle errors ``ê`` over the training rows (rad).
        noise_rms: (k,) RMS the measurement noise alone would give them (rad).
        names: ("alpha", "beta") or a subset.
    """

    G: np.ndarray
    H: np.ndarray
    mean_rows: np.ndarray
    active: bool
    sigma: np.ndarray
    angle_rms: np.ndarray
    noise_rms: np.ndarray
    names: tuple[str, ...]
    keep_mean: bool = False

    def angles(self, D: np.ndarray) -> np.ndarray:
        """(T, k) fluctuating angle errors ``ê_t - mean`` that explain ``D`` (T, 6) best."""
        e = np.einsum("tkc,tc->tk", self.H, np.nan_to_num(D))
        return e - e[self.mean_rows].mean(axis=0) if self.keep_mean else e

    def __call__(self, D: np.ndarray) -> np.ndarray:
        if not self.active:
            return D
        return D - np.einsum("tck,tk->tc", self.G, self.angles(D))

    def rows(self, D: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Per-row projection of ``D`` (N, 6) given on the rows ``mask`` (T,), without keeping the mean.

        Used inside fits (the kept mean is a constant that the fitted parameters absorb).
        """
        if not self.active:
            return D
        G, H = self.G[mask], self.H[mask]
        return D - np.einsum("tck,tk->tc", G, np.einsum("tkc,tc->tk", H, D))

    def summary(self) -> dict:
        """JSON-able facts for ``diagnosis.json``."""
        return {"active": bool(self.active), "angles": list(self.names),
                "angle_error_rms_rad": [float(x) for x in self.angle_rms],
                "noise_only_rms_rad": [float(x) for x in self.noise_rms]}


def _loadings(ctx: DiagContext, h: float = 1e-3) -> np.ndarray:
    out = []
    for i in (_IA, _IB):
        Xp, Xm = ctx.X.copy(), ctx.X.copy()
        Xp[:, i] += h
        Xm[:, i] -= h
        out.append((ctx.model_values(Xp) - ctx.model_values(Xm)) / (2 * h))
    return np.stack(out, axis=2)                              # (T, 6, 2)


def gust_projector(ctx: DiagContext, R: np.ndarray, iters: int = 4, min_ratio: float = 2.0) -> GustProjector:
    """Build the projector from the baseline residual ``R`` (T, 6).

    Args:
        ctx: the diagnosis context (model, regressors, training rows, active coefficients).
        R: residual measured - model, (T, 6).
        iters: reweighting iterations (the weights are the RMS of the projected residual).
        min_ratio: the projector is active when the fluctuating angle error has at least this
            many times the RMS that the measurement noise alone would give it.

    Returns:
        :class:`GustProjector`.
    """
    G = _loadings(ctx)
    act = ctx.active.astype(float)
    keep = [k for k in range(2) if np.sum(act * np.mean(G[ctx.valid, :, k] ** 2, axis=0)) > 0]
    names = tuple(("alpha", "beta")[k] for k in keep)
    G = G[:, :, keep]
    T, k = len(ctx.t), len(keep)
    tr = ctx.train
    Rn = np.nan_to_num(R)
    sig = np.sqrt(np.mean(Rn[tr] ** 2, axis=0))
    sig = np.where(sig > 0, sig, 1.0)
    H = np.zeros((T, k, 6))
    if k == 0:
        return GustProjector(G, H, tr, False, sig, np.zeros(0), np.zeros(0), names)
    for _ in range(iters):
        w = act / sig**2
        GW = G * w[None, :, None]                                 # (T, 6, k)
        A = np.einsum("tck,tcl->tkl", GW, G)
        A = np.where(np.isfinite(A), A, 0.0)
        # relative ridge: rows where the loadings are (nearly) collinear or zero stay invertible
        scale = np.trace(A, axis1=1, axis2=2)[:, None, None] / k
        Ainv = np.linalg.inv(A + (1e-9 * scale + 1e-12) * np.eye(k))
        H = np.einsum("tkl,tcl->tkc", Ainv, GW)
        P = GustProjector(G, H, tr, True, sig, np.zeros(k), np.zeros(k), names)
        Rp = P(Rn)
        # a projected channel keeps (1 - leverage) of its noise variance
        lev = np.minimum(np.einsum("tck,tkc->tc", G[tr], H[tr]).mean(axis=0), 0.95)
        s_new = np.sqrt(np.mean(Rp[tr] ** 2, axis=0) / (1.0 - lev))
        sig = np.where(s_new > 1e-12, s_new, sig)
    e = P.angles(Rn)[tr]
    angle_rms = np.std(e, axis=0)                 # fluctuation: a constant offset is not turbulence
    noise_rms = np.sqrt(np.mean(np.diagonal(Ainv[tr], axis1=1, axis2=2), axis=0))
    active = bool(np.any(angle_rms > min_ratio * noise_rms))
    return GustProjector(G, H, tr, active, sig, angle_rms, noise_rms, names)
