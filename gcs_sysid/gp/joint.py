"""Joint vs independent outputs: what the coupling contributes, what the truth's correlation is,
and sharing chosen per output by blocked cross-validation (issue 8, item 3).

The global layer couples the six coefficients in two places: the signal's coregionalisation ``B``
(``cov(f_p(x), f_q(x')) = B_pq k(x, x')``) and, with ``GPConfig.noise_correlation``, the noise
covariance ``Sigma``. With every output observed on every row (isotopic data) and a shared kernel,
the posterior mean of a multi-output GP reduces to one-output predictions when the noise is absent
or proportional to ``B`` (autokrigeability; Alvarez, Rosasco and Lawrence 2012, "Kernels for
vector-valued functions: a review", Found. Trends Mach. Learn. 4(3), sec. 4.2, arXiv:1106.6251;
Bonilla, Chai and Williams 2008, "Multi-task Gaussian process prediction", NIPS 20). The linear
mean behaves the same way: for seemingly unrelated regressions with one design matrix shared by all
equations, generalised least squares with any noise covariance equals least squares per equation
(Zellner 1962, "An efficient method of estimating seemingly unrelated regressions", JASA 57:348-368).
What is left to a joint model on such data is (a) the noise covariance where the outputs' signals
differ in their spectral content (a rough component of one output that is pure noise in another),
(b) outputs missing on some rows, (c) hyperparameters learned from the pooled rows.

This module measures that, on data:

* :func:`decoupled` removes the coupling (``B_j -> diag``, ``Sigma -> diag``) while keeping every
  other hyperparameter, so ``predict`` of the coupled and the decoupled model differ by what the
  coupling contributes to the mean, and nothing else;
* :func:`nonlinear_part` and :func:`correlation` define an output correlation of a set of function
  values over flown rows in the sense of ``LocalGlobalGP.output_correlation`` (the correlation of the
  parts that are *not* linear in the regressors), and :func:`truth_correlation` applies it to an
  exact truth (a quadratic response surface of the true coefficients on the true regressors);
* :func:`blocked_errors` scores a fitted model's global layer per output on contiguous held-back
  blocks of the time-ordered training rows (exact for fixed hyperparameters, as
  :mod:`gcs_sysid.gp.validation`), and :class:`SelectedOutputs` predicts each output with the joint
  model or with that output's own independent GP, whichever the blocked error prefers
  (Rasmussen and Williams 2006, sec. 5.3; Roberts et al. 2017, Ecography 40(8):913-929).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import jax
import jax.numpy as jnp
import numpy as np

from .batching import global_stats
from .model import LocalGlobalGP
from .sparse import GlobalParams
from .validation import _design_u, _mean_weights, _sub, block_folds

__all__ = ["COUPLING_MARGIN", "decoupled", "decoupled_model", "couple_only", "gate_coupling", "gap_errors", "nonlinear_part", "correlation", "quadratic_features",
           "truth_correlation", "blocked_errors", "SelectedOutputs", "select_outputs"]


def decoupled(params: GlobalParams) -> GlobalParams:
    """``params`` without cross-output coupling: every ``B_j`` and ``Sigma`` made diagonal.

    The factors become ``diag(sqrt(diag(B_j)))`` (still lower-triangular, same per-output latent
    variances) and the noise correlation the identity (same per-output noise variances); length-
    scales, inducing inputs and the linear mean's prior are unchanged.
    """
    def diag_factor(A):
        if A.shape[-1] == A.shape[-2]:
            return jnp.sqrt(jnp.sum(A * A, axis=-1))[..., :, None] * jnp.eye(A.shape[-1], dtype=A.dtype)
        # per-group kernels (``(P, Rg)`` factors, GPConfig.output_groups="kernels"): output p's latent
        # variance on the column of its own diagonal entry, the last non-zero of its row
        A = np.asarray(A)
        col = np.where(A != 0.0, np.arange(A.shape[-1]), 0).max(-1)
        for Ak, ck in zip(A.reshape(-1, *A.shape[-2:]), col.reshape(-1, A.shape[-2])):
            used = ck[np.any(Ak != 0.0, -1)]
            if len(set(used.tolist())) < len(used):
                raise ValueError("decoupled: factors with free loadings (output_groups='kernels-free') have no "
                                 "one latent per output to keep")
        out = np.sqrt(np.sum(A * A, -1))[..., None] * (col[..., None] == np.arange(A.shape[-1]))
        return jnp.asarray(out)

    return replace(params, A=diag_factor(params.A),
                   lmc_A=None if params.lmc_A is None else diag_factor(params.lmc_A),
                   noise_chol=None)


#: An output keeps its coupling to the others when the coupled model's blocked squared error for it is
#: below this share of the decoupled model's (the same 1 % margin as the local layer's gate).
COUPLING_MARGIN = 0.99


def couple_only(params: GlobalParams, coupled, noise_coupled=None) -> GlobalParams:
    """``params`` with the cross-output coupling of the signal kept only among the outputs where
    ``coupled (P,)`` is True, and that of the noise among those where ``noise_coupled (P,)`` is True
    (default: ``coupled``). Each ``B_j`` (and ``Sigma``) keeps its diagonal and the entries
    ``(p, q)`` with both ``p`` and ``q`` coupled; the rest is set to 0 (a principal block and a
    diagonal: positive definite). All True returns ``params``; all False is :func:`decoupled`."""
    coupled = np.asarray(coupled, bool)
    noise_coupled = coupled if noise_coupled is None else np.asarray(noise_coupled, bool)
    if coupled.all() and noise_coupled.all():
        return params
    eye = np.eye(len(coupled), dtype=bool)
    F = np.asarray(params.factors)
    A = np.linalg.cholesky(np.einsum("jpr,jqr->jpq", F, F) * (np.outer(coupled, coupled) | eye))
    R = None
    if params.noise_chol is not None and noise_coupled.any():
        Rn = np.asarray(params.noise_chol)
        R = jnp.asarray(np.linalg.cholesky((Rn @ Rn.T) * (np.outer(noise_coupled, noise_coupled) | eye)))
    return replace(params, A=jnp.asarray(A[0]), lmc_A=None if params.lmc_A is None else jnp.asarray(A[1:]),
                   noise_chol=R)


def gate_coupling(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, folds: int, batch: int,
                  margin: float = COUPLING_MARGIN) -> tuple[GlobalParams, dict]:
    """Keep the cross-output coupling of the noise (``Sigma``) and of the signal (``B``) only among
    the outputs that need it to lower their blocked cross-validation error.

    The time-ordered standardised rows ``Xs (N, D)``, ``Ys (N, P)`` are cut into ``folds``
    contiguous blocks; each block is predicted by the global posterior of the other blocks (exact
    for fixed hyperparameters; the statistics do not depend on ``B`` or ``Sigma``, so one set serves
    every candidate). Two gates, in turn:

    1. noise: output ``p`` *benefits* when its squared error with the learned ``Sigma`` (and ``B``
       diagonal) is below ``margin`` times that with both diagonal;
    2. signal: output ``p`` benefits when its error with the learned ``B`` (and the gated
       ``Sigma``) is below ``margin`` times that with ``B`` diagonal.

    With missing outputs (NaN in ``Ys``: heterotopic rows) the error of each output is its *gap*
    error instead: in every block only that output's entries are held back, the other outputs of
    the block stay in the statistics (the question a missing output poses: its value where the
    others were measured; :func:`gap_errors`). There the coupling does move the prediction (the
    observed outputs of the same rows inform the missing one through ``B``), for better or worse.

    In each, the coupled group starts as the outputs that benefit; while one of those no longer
    benefits within the group (its partner, e.g. the output whose noise it borrows, was left out)
    the output most strongly correlated with the group in that component joins it (a partner need
    not benefit itself). On isotopic data with a shared kernel the coupling leaves the mean
    (nearly) unchanged (autokrigeability, module docstring), and a learned correlation that changes
    no prediction is no evidence of a correlation: the gated model reports coupling only where it
    earns its place on held-back time.

    Returns:
        ``(params_gated, info)``: ``info["noise_coupled"]``, ``info["coupled"]`` ``(P,)`` bool (signal),
        ``info["noise_ratio"]``, ``info["ratio"]`` ``(P,)`` the coupled over the uncoupled blocked
        squared error per output in each gate (< 1: the coupling helps).
    """
    n, P = Ys.shape
    blocks = block_folds(n, folds)
    if not np.all(np.isfinite(Ys)):
        sse = gap_errors(params, Xs, Ys, blocks, batch)
    else:
        parts = [global_stats(params, Xs[a:b], Ys[a:b], batch) for a, b in blocks]
        total = parts[0]
        for st in parts[1:]:
            total = jax.tree_util.tree_map(jnp.add, total, st)
        rests = [_sub(total, st) for st in parts]
        U = [np.asarray(_design_u(params, Xs[a:b])) for a, b in blocks]

        def sse(pk: GlobalParams) -> np.ndarray:
            out = np.zeros(P)
            for (a, b), rest, u in zip(blocks, rests, U):
                out += np.sum((Ys[a:b] - u @ np.asarray(_mean_weights(pk, rest))) ** 2, 0)
            return out

    none, every = np.zeros(P, bool), np.ones(P, bool)

    def gate(make, strength):
        """``make(group) -> params``; returns ``(group, ratio)``."""
        base = sse(make(none))
        ratio = sse(make(every)) / np.maximum(base, 1e-300)
        seeds = ratio < margin
        group = seeds.copy()
        strength = np.abs(strength)
        np.fill_diagonal(strength, 0.0)
        while group.any() and not group.all():
            within = sse(make(group)) / np.maximum(base, 1e-300)
            if np.all(within[seeds] < margin):
                break
            group = group.copy()
            group[int(np.argmax(np.where(group, -1.0, strength[group].max(0))))] = True
        return group, ratio

    if params.noise_chol is not None:
        noise_group, noise_ratio = gate(lambda g: couple_only(params, none, g), _corr(np.asarray(params.noise_cov())))
    else:
        noise_group, noise_ratio = none, np.ones(P)
    group, ratio = gate(lambda g: couple_only(params, g, noise_group), _corr(np.asarray(params.B)))
    info = {"noise_coupled": noise_group, "coupled": group, "noise_ratio": noise_ratio, "ratio": ratio}
    return couple_only(params, group, noise_group), info


def gap_errors(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, blocks: list[tuple[int, int]], batch: int):
    """The gap error of heterotopic rows: a function ``sse(params_k) -> (P,)``.

    For every block ``[a, b)`` and output ``p`` the entries of output ``p`` in the block are held back
    alone (the statistics of all rows minus that block's output-``p`` entries, per-output form; the
    other outputs of the block stay), and output ``p`` is predicted there by the global posterior
    mean; ``sse`` sums the squared errors over the observed entries (standardised units). The
    statistics do not depend on ``B`` or ``Sigma``, so the candidates ``params_k`` (``B`` and
    ``Sigma`` changed only) share them; each candidate costs ``k P`` posteriors.

    Args:
        params: learned global hyperparameters. Xs: ``(N, D)``, Ys: ``(N, P)`` standardised rows in
            time order, NaN where an output is missing. blocks: ``(start, stop)`` row ranges.
        batch: rows per compiled chunk of the statistics.
    """
    P = Ys.shape[1]
    total = global_stats(params, Xs, Ys, batch)
    U = [np.asarray(_design_u(params, Xs[a:b])) for a, b in blocks]
    rests = []
    for a, b in blocks:
        row = []
        for p in range(P):
            only = np.full_like(Ys[a:b], np.nan)
            only[:, p] = Ys[a:b, p]
            obs = np.isfinite(only[:, p])
            row.append(None if not obs.any() else _sub(total, global_stats(params, Xs[a:b], only, batch)))
        rests.append(row)

    def sse(pk: GlobalParams) -> np.ndarray:
        out = np.zeros(P)
        for (a, b), row, u in zip(blocks, rests, U):
            for p, rest in enumerate(row):
                if rest is not None:
                    out[p] += np.nansum((Ys[a:b, p] - u @ np.asarray(_mean_weights(pk, rest))[:, p]) ** 2)
        return out

    return sse


def _corr(S: np.ndarray) -> np.ndarray:
    d = np.sqrt(np.clip(np.diag(S), 1e-300, None))
    return S / np.outer(d, d)


def decoupled_model(model: LocalGlobalGP) -> LocalGlobalGP:
    """The fitted ``model`` with :func:`decoupled` parameters (posterior and local residuals rebuilt
    from the same statistics and rows): the same model with the outputs made independent."""
    return replace(model, params=decoupled(model.params), _post=None, _store=None)


def nonlinear_part(X: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``F`` minus its least-squares projection on ``[1, X]`` over the rows.

    Args:
        X: ``(N, D)`` regressors (any units; constant columns are harmless).
        F: ``(N, P)`` function values at those rows (a model's mean, a truth).

    Returns:
        ``(N, P)``: the part of each column that no affine function of the regressors explains
        on these rows (what the latent GP, not the linear mean, has to carry).
    """
    X = np.asarray(X, float)
    F = np.asarray(F, float)
    sd = X.std(0)
    Xs = (X - X.mean(0)) / np.where(sd > 0, sd, 1.0)
    A = np.column_stack([np.ones(len(X)), Xs])
    W, *_ = np.linalg.lstsq(A, F, rcond=None)
    return F - A @ W


def correlation(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Correlation ``(P, P)`` of the columns of ``G (N, P)`` over the rows, and their std ``(P,)``.

    A column with zero variance gets correlation 0 with the others (1 on the diagonal).
    """
    G = np.asarray(G, float) - np.mean(G, 0)
    S = G.T @ G / max(len(G) - 1, 1)
    s = np.sqrt(np.clip(np.diag(S), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        C = np.where(np.outer(s, s) > 0, S / np.outer(s, s), 0.0)
    np.fill_diagonal(C, 1.0)
    return C, s


def quadratic_features(X: np.ndarray) -> np.ndarray:
    """``[1, x_d, x_d x_e (d <= e)]`` of the standardised ``X (N, D)``: ``(N, 1 + D + D (D+1)/2)``
    (a second-order response surface, the classical polynomial aerodynamic model class;
    Morelli and Klein 2016, *Aircraft System Identification*, ch. 5)."""
    X = np.asarray(X, float)
    sd = X.std(0)
    Xs = (X - X.mean(0)) / np.where(sd > 0, sd, 1.0)
    i, j = np.triu_indices(X.shape[1])
    return np.column_stack([np.ones(len(X)), Xs, Xs[:, i] * Xs[:, j]])


def truth_correlation(X_true: np.ndarray, Y_true: np.ndarray) -> dict[str, np.ndarray]:
    """Output correlation of an exact truth, in the sense of ``output_correlation`` (issue 8).

    The true coefficient function is approximated by a quadratic response surface of the exact
    coefficients on the exact regressors over the flown rows (:func:`quadratic_features`, least
    squares). Its part that is not linear in the regressors (:func:`nonlinear_part`) is what a
    latent GP on these regressors should carry; its correlation across outputs is the truth's
    counterpart of ``B`` normalised. What the surface leaves (the truth's variation that is no
    function of the logged regressors: turbulence rates, ``alpha_dot``) is noise to any model of
    these regressors; its correlation is the truth's counterpart of ``noise_correlation``.

    Args:
        X_true: ``(N, D)`` exact regressors; Y_true: ``(N, P)`` exact coefficients (finite rows).

    Returns:
        ``signal_corr (P, P)``, ``signal_std (P,)`` of the nonlinear part, ``rest_corr (P, P)``,
        ``rest_std (P,)`` of what the surface leaves, and ``linear_std (P,)`` of the affine part.
    """
    Q = quadratic_features(X_true)
    W, *_ = np.linalg.lstsq(Q, Y_true, rcond=None)
    fit = Q @ W
    nl = nonlinear_part(X_true, fit)
    sc, ss = correlation(nl)
    rc, rs = correlation(Y_true - fit)
    _, ls = correlation(fit - nl)
    return {"signal_corr": sc, "signal_std": ss, "rest_corr": rc, "rest_std": rs, "linear_std": ls}


def blocked_errors(model: LocalGlobalGP, X: np.ndarray, Y: np.ndarray, folds: int = 5) -> np.ndarray:
    """Blocked cross-validation squared error per output of the model's global layer, data units.

    The time-ordered rows are cut into ``folds`` contiguous blocks; each block is predicted by the
    global posterior conditioned on the other blocks, with the model's hyperparameters fixed (the
    statistics are sums over rows, so this is exact and costs one posterior per block). The local
    layer is left out (it is kept for few outputs on flight data, ``docs/gp.md``).

    Args:
        model: a fitted model; X: ``(N, D)``, Y: ``(N, P_model)`` its training rows in time order
            (rows with a non-finite value are dropped).
        folds: number of blocks (at least 2).

    Returns:
        ``(P_model,)`` mean squared error per output over all rows, in the outputs' units squared.

    Raises:
        ValueError: fewer than 2 folds or fewer rows than folds.
    """
    ok = np.isfinite(X).all(1) & np.isfinite(Y).all(1)
    Xs, Ys = model.scaler.x(np.asarray(X)[ok]), model.scaler.y(np.asarray(Y)[ok])
    n = len(Xs)
    if folds < 2 or n < folds:
        raise ValueError(f"blocked_errors: need at least 2 folds and as many rows, got {folds} folds, {n} rows")
    params, batch = model.params, model.config.batch_size
    blocks = block_folds(n, folds)
    parts = [global_stats(params, Xs[a:b], Ys[a:b], batch) for a, b in blocks]
    total = parts[0]
    for st in parts[1:]:
        total = jax.tree_util.tree_map(jnp.add, total, st)
    sse = np.zeros(Ys.shape[1])
    for (a, b), st in zip(blocks, parts):
        W = np.asarray(_mean_weights(params, _sub(total, st)))
        U = np.asarray(_design_u(params, Xs[a:b]))
        sse += np.sum((Ys[a:b] - U @ W) ** 2, 0)
    return sse / n * model.scaler.y_std**2


@dataclass(frozen=True)
class SelectedOutputs:
    """Per output, the joint model's prediction or that output's own independent GP's.

    Attributes:
        joint: the multi-output model (``P`` outputs).
        independent: ``P`` one-output models, same training rows.
        use_joint: ``(P,)`` bool, True where the joint model's blocked error was lower.
        err_joint, err_indep: ``(P,)`` blocked mean squared errors (data units squared).
    """

    joint: LocalGlobalGP
    independent: tuple[LocalGlobalGP, ...]
    use_joint: np.ndarray
    err_joint: np.ndarray
    err_indep: np.ndarray

    def predict(self, X, include_noise: bool = True, input_noise: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance ``(N, P)`` as ``LocalGlobalGP.predict``, each output from its chosen model."""
        mean, var = self.joint.predict(X, include_noise, input_noise)
        for p, m in enumerate(self.independent):
            if not self.use_joint[p]:
                mp, vp = m.predict(X, include_noise, input_noise)
                mean[:, p], var[:, p] = mp[:, 0], vp[:, 0]
        return mean, var


def select_outputs(joint: LocalGlobalGP, independent, X: np.ndarray, Y: np.ndarray, folds: int = 5,
                   margin: float = 1.0) -> SelectedOutputs:
    """Choose per output between the joint model and its independent GP by blocked cross-validation.

    Args:
        joint: fitted multi-output model; independent: ``P`` fitted one-output models (output ``p``
            of ``Y`` each), all on the rows ``X (N, D)``, ``Y (N, P)`` in time order.
        folds: contiguous blocks (:func:`blocked_errors`).
        margin: the joint model is used for output ``p`` when its blocked error is below ``margin``
            times the independent one's (1: whichever is lower).

    Returns:
        :class:`SelectedOutputs`.

    Raises:
        ValueError: ``independent`` does not hold one model per output of ``joint``.
    """
    independent = tuple(independent)
    P = joint.n_outputs
    if len(independent) != P or any(m.n_outputs != 1 for m in independent):
        raise ValueError(f"select_outputs: need {P} one-output models, got {len(independent)}")
    ej = blocked_errors(joint, X, Y, folds)
    ei = np.array([blocked_errors(m, X, np.asarray(Y)[:, [p]], folds)[0] for p, m in enumerate(independent)])
    return SelectedOutputs(joint, independent, ej < margin * ei, ej, ei)
