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

from ..jaxconfig import stored_jit
from .batching import global_stats
from .model import LocalGlobalGP
from .sparse import GlobalParams, elbo
from .validation import _design_u, _mean_weights, _sub, block_folds

__all__ = ["COUPLING_MARGIN", "COUPLING_LEVEL", "LR_LEVEL", "lr_coupling", "coupling_gain_significant", "decoupled",
           "decoupled_model", "couple_only", "gate_coupling", "gap_errors", "nonlinear_part", "correlation",
           "quadratic_features",
           "truth_correlation", "blocked_errors", "SelectedOutputs", "select_outputs", "forward_errors", "fit_selected"]


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
#: below this share of the decoupled model's (the same 1 % margin as the local layer's gate; rule ``"ratio"``).
COUPLING_MARGIN = 0.99

#: One-sided level of the paired test of rule ``"paired-t"`` (:func:`coupling_gain_significant`): the coupling is
#: kept for an output only when its blocked gain is significant at 5 % (the decoupled model is the null).
COUPLING_LEVEL = 0.05


def coupling_gain_significant(sse_coupled: np.ndarray, sse_decoupled: np.ndarray, margin: float = COUPLING_MARGIN,
                              level: float = COUPLING_LEVEL) -> np.ndarray:
    """Whether the coupled model's blocked error is lower than the decoupled one's beyond the blocks' spread.

    Per output, the paired differences ``d_k = sse_decoupled[k] - sse_coupled[k]`` over the ``K`` time blocks
    are tested one-sided, ``t = mean(d) / (std(d) / sqrt(K)) > t_{1 - level, K - 1}`` (Student's t), and
    the total ratio must also be below ``margin``. The blocks are disjoint stretches of time, so their
    differences are close to independent (Dietterich 1998, "Approximate statistical tests for comparing
    supervised classification learning algorithms", Neural Comput. 10(7):1895-1923, on paired tests over
    validation folds; Bergmeir and Benitez 2012 on blocked folds of time series). The decoupled model is
    the simpler one (Occam; Rasmussen and Williams 2006, sec. 5.2-5.3): it stays unless the data show the
    coupling better on held-back time in a way one block alone cannot give. With 5 blocks a gain that
    comes from one block has ``t ~ 1`` whatever its size (``docs/benchmarks.md``, "Sixteenth session: what
    was measured and not merged").

    Args:
        sse_coupled, sse_decoupled: ``(K, P)`` squared-error sums per block and output (``K >= 2``).
        margin: the largest total ratio ``sum sse_coupled / sum sse_decoupled`` that counts as a gain.
        level: one-sided test level.

    Returns:
        ``(P,)`` bool.
    """
    from scipy.stats import t as student_t

    c, u = np.asarray(sse_coupled, float), np.asarray(sse_decoupled, float)
    K = c.shape[0]
    ratio = c.sum(0) / np.maximum(u.sum(0), 1e-300)
    d = u - c
    sd = d.std(0, ddof=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        tstat = np.where(sd > 0, d.mean(0) / (sd / np.sqrt(K)), np.where(d.mean(0) > 0, np.inf, 0.0))
    return (ratio < margin) & (tstat > student_t.ppf(1.0 - level, K - 1))


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
        R = jax.device_put(np.linalg.cholesky((Rn @ Rn.T) * (np.outer(noise_coupled, noise_coupled) | eye)))
    # device_put, not jnp.asarray: the same array without an identity program compiled for each shape
    return replace(params, A=jax.device_put(A[0]), lmc_A=None if params.lmc_A is None else jax.device_put(A[1:]),
                   noise_chol=R)


def gate_coupling(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, folds: int, batch: int,
                  margin: float = COUPLING_MARGIN, rule: str = "ratio") -> tuple[GlobalParams, dict]:
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

    ``rule="paired-t"`` (opt-in; ``fit_gp`` uses ``"ratio"``) also asks that the gain hold across the
    blocks: the per-block differences pass a one-sided paired t-test at :data:`COUPLING_LEVEL`
    (:func:`coupling_gain_significant`). ``rule="ratio"`` is the total ratio alone (the gate before). On
    the JSBSim flights' short logs the ratio alone kept couplings whose blocked gain came from one block
    of five and that cost the held-out error against the truth (``docs/benchmarks.md``, "Sixteenth session:
    what was measured and not merged"), but it also dropped a real shared latent in ``tests/gp/test_honest.py``.

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

    Args:
        margin: see above; rule: ``"paired-t"`` or ``"ratio"``.

    Returns:
        ``(params_gated, info)``: ``info["noise_coupled"]``, ``info["coupled"]`` ``(P,)`` bool (signal),
        ``info["noise_ratio"]``, ``info["ratio"]`` ``(P,)`` the coupled over the uncoupled blocked
        squared error per output in each gate (< 1: the coupling helps).

    Raises:
        ValueError: an unknown ``rule``.
    """
    if rule not in ("paired-t", "ratio"):
        raise ValueError(f"gate_coupling: rule must be 'paired-t' or 'ratio', got {rule!r}")
    n, P = Ys.shape
    blocks = block_folds(n, folds)
    if not np.all(np.isfinite(Ys)):
        sse = gap_errors(params, Xs, Ys, blocks, batch, per_block=True)
    else:
        parts = [global_stats(params, Xs[a:b], Ys[a:b], batch) for a, b in blocks]
        total = parts[0]
        for st in parts[1:]:
            total = jax.tree_util.tree_map(jnp.add, total, st)
        rests = [_sub(total, st) for st in parts]
        U = [np.asarray(_design_u(params, Xs[a:b])) for a, b in blocks]

        def sse(pk: GlobalParams) -> np.ndarray:
            """``(K, P)`` squared-error sums per block."""
            return np.array([np.sum((Ys[a:b] - u @ np.asarray(_mean_weights(pk, rest))) ** 2, 0)
                             for (a, b), rest, u in zip(blocks, rests, U)])

    none, every = np.zeros(P, bool), np.ones(P, bool)

    def gains(coupled: np.ndarray, base: np.ndarray) -> np.ndarray:
        if rule == "ratio":
            return coupled.sum(0) / np.maximum(base.sum(0), 1e-300) < margin
        return coupling_gain_significant(coupled, base, margin)

    def gate(make, strength):
        """``make(group) -> params``; returns ``(group, ratio)``."""
        base = sse(make(none))
        full = sse(make(every))
        ratio = full.sum(0) / np.maximum(base.sum(0), 1e-300)
        seeds = gains(full, base)
        group = seeds.copy()
        strength = np.abs(strength)
        np.fill_diagonal(strength, 0.0)
        while group.any() and not group.all():
            if np.all(gains(sse(make(group)), base)[seeds]):
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


#: Level of the likelihood-ratio test of :func:`lr_coupling` (``GPConfig.coupling_test = "lr"``): an output keeps
#: its coupling to the others only when removing it lowers the deflated bound beyond the chi-square quantile.
LR_LEVEL = 0.05

_elbo_jit = stored_jit(elbo)


def lr_coupling(params: GlobalParams, stats, share: float = 1.0, level: float = LR_LEVEL, df_max: int | None = None
                ) -> tuple[GlobalParams, dict]:
    """Keep the signal's cross-output coupling (the off-diagonals of ``B``) only for the outputs whose coupling the
    bound on every training row supports by a likelihood-ratio test (``GPConfig.coupling_test = "lr"``).

    The learned ``B`` comes from the bound on a subset of ``n_train_max`` rows; on a coloured 50 Hz flight an
    off-diagonal is poorly determined there (the b737's Cl-Cm 0.28-0.69 over the subset's seed, ``docs/gp.md``,
    "Coupling from every row"), and where the blocked validation shrank an output's latent part to ~0 its
    correlation with the others moves the likelihood little, yet ``output_correlation()`` (scale-free) reports it
    at full size, and the posterior mean carries it: the nonlinear parts of the model's predictions correlated
    +0.71 on that b737 flight, the truth's +0.26 (``docs/gp.md``, "Coupling the data determine"). Here the
    collapsed bound (Titsias 2009) is evaluated on the statistics of *every* row ``stats``
    (they depend on neither ``B`` nor the noise, so a candidate costs one factorisation in the feature space)
    for ``B`` as learned and with outputs decoupled (:func:`couple_only`; the noise covariance is kept as
    learned). Backward elimination: while two or more outputs are coupled, the output whose decoupling lowers the
    bound least is decoupled when ``share * 2 (l_before - l_after)`` is below the ``1 - level`` quantile of
    chi-square with ``min(k, df_max)`` degrees of freedom, ``k`` the pairs it leaves and ``df_max`` the shared
    factors' rank (an output's covariances with the others are its loadings on the ``R`` shared factors: at most
    ``R`` free parameters; Wilks 1938); otherwise the elimination stops. ``share`` deflates the statistic for rows
    that are not independent: one over the residual's long-run variance ratio
    (:func:`gcs_sysid.gp.colored.variance_inflation`; ``n`` coloured rows carry the information of ``n / c``
    independent ones, Bayley and Hammersley 1946), the first-order correction of Rao and Scott (1981, "The
    analysis of categorical data from complex sample surveys", JASA 76:221-230) for a statistic computed as if
    the rows were independent. What the data leave undetermined is left out: the simpler,
    independent model is the null (Occam; Rasmussen and Williams 2006, sec. 5.2). On isotopic rows with a shared
    kernel the signal coupling moves the predictive mean little (autokrigeability, module docstring; on 12 JSBSim
    flights the held-out errors moved by -0.42 to +0.29 points).

    Args:
        params: global hyperparameters (after the blocked validation's latent scales: the model that predicts).
        stats: the sufficient statistics of every training row (:func:`gcs_sysid.gp.batching.global_stats`).
        share: worth of one row in independent rows, in (0, 1].
        level: the test's level.
        df_max: the most degrees of freedom of one output's decoupling (the shared factors' rank; None: ``P - 1``).

    Returns:
        ``(params_tested, info)``: ``info["lr_coupled"]`` ``(P,)`` bool, ``info["lr_stat"]`` the deflated
        statistic of each output at its elimination step (NaN: never tried), ``info["lr_share"]``.
    """
    from scipy.special import chdtri          # chi-square upper-tail quantile (lighter to import than scipy.stats)

    P = np.asarray(params.B).shape[0]
    keep_noise = np.ones(P, bool)

    def bound(group: np.ndarray) -> float:
        return float(_elbo_jit(couple_only(params, group, keep_noise), stats))

    coupled = np.ones(P, bool)
    stat = np.full(P, np.nan)
    ell = bound(coupled)
    while coupled.sum() >= 2:
        trial = {}
        for p in np.flatnonzero(coupled):
            g = coupled.copy()
            g[p] = False
            trial[int(p)] = bound(g if g.sum() >= 2 else np.zeros(P, bool))
        p = max(trial, key=trial.get)
        k = int(coupled.sum()) - 1                 # the pairs its decoupling removes
        stat[p] = share * 2.0 * (ell - trial[p])
        if stat[p] > chdtri(max(1, min(k, P - 1 if df_max is None else int(df_max))), level):
            break
        coupled[p] = False
        ell = trial[p]
        if coupled.sum() == 1:
            coupled[:] = False
    return couple_only(params, coupled, keep_noise), {"lr_coupled": coupled, "lr_stat": stat,
                                                      "lr_share": np.array([share])}


def gap_errors(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, blocks: list[tuple[int, int]], batch: int,
               per_block: bool = False):
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
        per_block: ``sse`` returns ``(K, P)``, the sums per block (default: ``(P,)``, over all blocks).
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
        out = np.zeros((len(blocks), P))
        for k, ((a, b), row, u) in enumerate(zip(blocks, rests, U)):
            for p, rest in enumerate(row):
                if rest is not None:
                    out[k, p] = np.nansum((Ys[a:b, p] - u @ np.asarray(_mean_weights(pk, rest))[:, p]) ** 2)
        return out if per_block else out.sum(0)

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


def blocked_errors(model: LocalGlobalGP, X: np.ndarray, Y: np.ndarray, folds: int = 5,
                   per_block: bool = False) -> np.ndarray:
    """Blocked cross-validation squared error per output of the model's global layer, data units.

    The time-ordered rows are cut into ``folds`` contiguous blocks; each block is predicted by the
    global posterior conditioned on the other blocks, with the model's hyperparameters fixed (the
    statistics are sums over rows, so this is exact and costs one posterior per block). The local
    layer is left out (it is kept for few outputs on flight data, ``docs/gp.md``).

    Args:
        model: a fitted model; X: ``(N, D)``, Y: ``(N, P_model)`` its training rows in time order
            (rows with a non-finite value are dropped).
        folds: number of blocks (at least 2).
        per_block: return each block's mean squared error, ``(folds, P_model)``.

    Returns:
        ``(P_model,)`` mean squared error per output over all rows, in the outputs' units squared
        (``(folds, P_model)`` with ``per_block``).

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
    sse = np.zeros((len(blocks), Ys.shape[1]))
    for k, ((a, b), st) in enumerate(zip(blocks, parts)):
        W = np.asarray(_mean_weights(params, _sub(total, st)))
        U = np.asarray(_design_u(params, Xs[a:b]))
        sse[k] = np.sum((Ys[a:b] - U @ W) ** 2, 0)
    if per_block:
        return sse / np.array([b - a for a, b in blocks], float)[:, None] * model.scaler.y_std**2
    return sse.sum(0) / n * model.scaler.y_std**2


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

    def output_correlation(self) -> np.ndarray:
        """Correlation ``(P, P)`` of the outputs' latent parts as the selected model predicts them: the joint
        model's (``LocalGlobalGP.output_correlation``) between outputs that both use it, 0 between an output
        predicted by its own GP and any other (that output's prediction does not depend on the others)."""
        C = np.array(self.joint.output_correlation(), float)
        own = ~np.asarray(self.use_joint, bool)
        C[own, :] = 0.0
        C[:, own] = 0.0
        np.fill_diagonal(C, 1.0)
        return C


def select_outputs(joint: LocalGlobalGP, independent, X: np.ndarray, Y: np.ndarray, folds: int = 5,
                   margin: float = 1.0, rule: str = "min", outputs=None) -> SelectedOutputs:
    """Choose per output between the joint model and its independent GP by blocked cross-validation.

    Args:
        joint: fitted multi-output model; independent: ``P`` fitted one-output models (output ``p``
            of ``Y`` each), all on the rows ``X (N, D)``, ``Y (N, P)`` in time order.
        folds: contiguous blocks (:func:`blocked_errors`).
        margin: the joint model is used for output ``p`` when its blocked error is below ``margin``
            times the independent one's (1: whichever is lower); rule ``"min"``.
        rule: ``"min"``: the lower blocked error (with ``margin``); ``"1se"``: the joint model unless the own
            GP's blocked error is lower by more than one standard error of the per-block differences (the
            one-standard-error rule, Breiman et al. 1984, *Classification and Regression Trees*, sec. 3.4.3;
            Hastie, Tibshirani and Friedman 2009, *The Elements of Statistical Learning*, 2nd ed., sec. 7.10:
            the default structure stays unless the data show the other better beyond the validation's noise).
        outputs: indices of the outputs that may leave the joint model (default all); the others keep it.
            On the JSBSim flights the blocked errors on the training maneuvers picked the better model for
            CX and not for the moments, which the joint model's pooled length-scales predict better on a
            held-out multisine (``docs/gp.md``, "Why the joint model loses CX"): ``(0, 1, 2)`` there.

    Returns:
        :class:`SelectedOutputs`.

    Raises:
        ValueError: ``independent`` does not hold one model per output of ``joint``; an unknown ``rule``.
    """
    independent = tuple(independent)
    P = joint.n_outputs
    if len(independent) != P or any(m.n_outputs != 1 for m in independent):
        raise ValueError(f"select_outputs: need {P} one-output models, got {len(independent)}")
    if rule not in ("min", "1se"):
        raise ValueError(f"select_outputs: rule must be 'min' or '1se', got {rule!r}")
    ej = blocked_errors(joint, X, Y, folds)
    ei = np.array([blocked_errors(m, X, np.asarray(Y)[:, [p]], folds)[0] for p, m in enumerate(independent)])
    if rule == "min":
        use = ej < margin * ei
    else:
        bj = blocked_errors(joint, X, Y, folds, per_block=True)
        bi = np.column_stack([blocked_errors(m, X, np.asarray(Y)[:, [p]], folds, per_block=True)[:, 0]
                              for p, m in enumerate(independent)])
        d = bi - bj                                         # (folds, P): > 0 where the joint model is better
        se = d.std(0, ddof=1) / np.sqrt(len(d))
        use = ~(d.mean(0) + se < 0.0)
    if outputs is not None:
        may = np.zeros(P, bool)
        may[np.asarray(list(outputs), int)] = True
        use = use | ~may
    return SelectedOutputs(joint, independent, use, ej, ei)


def forward_errors(X, Y, config=None, output_names=None, folds: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """Held-forward error of the joint model and of each output's own GP, every hyperparameter learned again
    without the held-back rows: both are fitted on the first ``(folds - 1) / folds`` of the time-ordered rows
    and predict the last block (``LocalGlobalGP.predict``, the local layer included, noise-free mean).

    The blocked errors of :func:`blocked_errors` keep the hyperparameters learned on every row, so they cannot
    see hyperparameters that fit the maneuvers they were learned on and nothing else (an own GP of a moment
    learned from a few maneuvers: ``docs/gp.md``, "Why the joint model loses CX"); a forward split with the
    hyperparameters learned again is meant to (Bergmeir and Benitez 2012, "On the use of cross-validation for
    time series predictor evaluation", Inf. Sci. 191:192-213; Roberts et al. 2017). Measured on one JSBSim
    flight it did not pick the moments' better model either.

    Args:
        X: ``(N, D)``, Y: ``(N, P)`` training rows in time order (rows with a missing output are left out of
            that output's scores).
        config: :class:`GPConfig` (default ``GPConfig()``); output_names: as :func:`fit_gp`.
        folds: the last ``N // folds`` rows are held back (at least 2).

    Returns:
        ``(err_joint, err_own)``, each ``(P,)``: mean squared error on the held-back rows, data units squared.

    Raises:
        ValueError: fewer than 2 folds, or fewer than ``3 folds`` rows.
    """
    from .config import GPConfig
    from .fit import fit_gp

    cfg = GPConfig() if config is None else config
    X, Y = np.asarray(X, float), np.asarray(Y, float)
    n, P = Y.shape
    if folds < 2 or n < 3 * folds:
        raise ValueError(f"forward_errors: need at least 2 folds and 3 rows per fold, got {folds} folds, {n} rows")
    cut = n - n // folds
    names = None if output_names is None else list(output_names)
    joint, _ = fit_gp(X[:cut], Y[:cut], cfg, output_names=names)
    names = list(joint.output_names)
    mj = joint.predict(X[cut:], include_noise=False)[0]
    ej, ei = np.zeros(P), np.zeros(P)
    for p in range(P):
        rows = np.isfinite(Y[:cut, p])
        own = fit_gp(X[:cut][rows], Y[:cut][rows][:, [p]], cfg, output_names=[names[p]])[0]
        mi = own.predict(X[cut:], include_noise=False)[0][:, 0]
        ok = np.isfinite(Y[cut:, p]) & np.isfinite(mj[:, p]) & np.isfinite(mi)
        ej[p] = np.mean((mj[ok, p] - Y[cut:][ok, p]) ** 2)
        ei[p] = np.mean((mi[ok] - Y[cut:][ok, p]) ** 2)
    return ej, ei


def fit_selected(X, Y, config=None, output_names=None, folds: int | None = None, margin: float = 1.0,
                 hyper: str = "fixed", outputs=None) -> SelectedOutputs:
    """Fit the joint model and one GP per output on the same training rows, and choose per output on those
    rows: model selection inside the fit, on training data only, so an output is predicted by the joint
    model only where pooling (the shared kernel's length-scales, the coregionalisation, the noise coupling)
    lowers its error on held-back time blocks.

    Why (``docs/gp.md``, "Why the joint model loses CX, and a per-output choice"): on isotopic flight
    tables the coupling contributes nothing to the mean (autokrigeability; Alvarez, Rosasco and Lawrence
    2012, sec. 4.2; Bonilla, Chai and Williams 2008), and the one kernel all outputs share is what moves
    an output: it helps the moments of a short log (hyperparameters pooled across tasks; Lawrence and Platt
    2004) and costs an output whose own length-scales differ from the pooled ones (CX's along the lateral
    controls, where the shared kernel follows Cm's along the elevator and pitch rate). Choosing by
    validation keeps the first and not the second (Rasmussen and Williams 2006, sec. 5.3).

    Args:
        X: ``(N, D)`` regressors, Y: ``(N, P)`` coefficients, rows in time order (as :func:`fit_gp`; rows
            with a missing output are left out of that output's own GP and of its score).
        config: :class:`GPConfig` for every fit (default ``GPConfig()``).
        output_names: names of the ``P`` outputs (default as :func:`fit_gp`).
        folds: time blocks (default ``config.validation_folds``, at least 2).
        margin: the joint model is used for an output when its error is below ``margin`` times the own GP's.
        hyper: ``"fixed"`` (default): :func:`blocked_errors` with the hyperparameters of the fits on all rows
            (``P + 1`` fits); ``"refit"``: :func:`forward_errors` (every hyperparameter learned again without
            the last block; ``2 (P + 1)`` fits in all). Both were measured to prefer the own GPs of the
            moments where the joint model predicts them better on a held-out multisine (``docs/benchmarks.md``,
            "Fourteenth session, i8-jointcx").
        outputs: indices of the outputs that may leave the joint model (default all; ``(0, 1, 2)``: the forces
            CX CY CZ, the choice that won there); the others keep it.

    Returns:
        :class:`SelectedOutputs` (the ``P + 1`` models fitted on all rows and the choice).

    Raises:
        As :func:`fit_gp`; ValueError: an unknown ``hyper``, or too few rows for the folds.
    """
    from .config import GPConfig
    from .fit import fit_gp

    if hyper not in ("refit", "fixed"):
        raise ValueError(f"fit_selected: hyper must be 'refit' or 'fixed', got {hyper!r}")
    cfg = GPConfig() if config is None else config
    X, Y = np.asarray(X, float), np.asarray(Y, float)
    P = Y.shape[1]
    names = list(output_names) if output_names is not None else None
    joint, _ = fit_gp(X, Y, cfg, output_names=names)
    names = list(joint.output_names)
    own = []
    for p in range(P):
        rows = np.isfinite(Y[:, p])
        own.append(fit_gp(X[rows], Y[rows][:, [p]], cfg, output_names=[names[p]])[0])
    k = max(int(cfg.validation_folds if folds is None else folds), 2)
    if hyper == "fixed":
        return select_outputs(joint, own, X, Y, k, margin, outputs=outputs)
    ej, ei = forward_errors(X, Y, cfg, names, k)
    use = ej < margin * ei
    if outputs is not None:
        may = np.zeros(P, bool)
        may[np.asarray(list(outputs), int)] = True
        use = use | ~may
    return SelectedOutputs(joint, tuple(own), use, ej, ei)
