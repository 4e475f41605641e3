"""Fitting the local + global GP: hyperparameters by optax Adam on the VFE bound, then the posterior.

Steps (each one a plain function of arrays):

1. check and standardise the data (:mod:`gcs_sysid.gp.scaling`);
2. initialise ``B`` and the noise from the residual covariance of a ridge least-squares
   fit of the linear mean, length-scales ``0.5 sqrt(D)``;
3. choose the inducing inputs (greedy mutual information, :mod:`gcs_sysid.gp.selection`);
4. Adam on ``-ELBO / (n P)`` over a random subset of ``n_train_max`` rows (one compiled
   step in a Python loop, early stopping on a plateau of the bound, ``GPConfig.tol``);
   re-select the inducing inputs with the learned length-scales and continue (``reselect``);
5. the global posterior from the sufficient statistics of every row;
6. the local layer: residuals of the global mean, k-d tree, Adam on the composite
   local likelihood from a variogram start (nugget from nearest-neighbour differences);
7. (between 4 and 5, and after 6) blocked cross-validation over contiguous blocks of the
   time-ordered rows: per output, the latent GP's prior scale and whether the local layer is
   kept (:mod:`gcs_sysid.gp.validation`, ``GPConfig.validation_folds``);
8. the model discrepancy from that validation's blocked error (:mod:`gcs_sysid.gp.discrepancy`).
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
import optax

from ..jaxconfig import enable_x64, stored_jit, stored_program
from .batching import global_mean, global_posterior, global_predict, global_stats
from .config import GPConfig
from .inputnoise import fit_input_noise, mean_gradient
from .kernels import coregionalisation
from .local import LocalParams, build_store, local_objective, neighbours
from .model import LocalGlobalGP
from .rowstore import RowStore
from .scaling import Standardiser, check_training
from .selection import random_points, select_inducing
from .sparse import GlobalParams, design, elbo, stats_of
from .discrepancy import calibrate, validation_rows
from .validation import gate_global, gate_local, shared_search, store_without

__all__ = ["FitHistory", "fit_gp", "constrain_global", "learn_global", "output_groups", "factor_mask",
           "group_embedding", "group_factors", "output_kernel_mask", "fit_local",
           "noise_correlation_factor",
           "linear_prior_std", "linear_terms_of",
           "learn_input_noise", "posterior_noise", "validated_global", "validated_local", "mean_only_masks",
           "rows_without_mean_only", "MEAN_ONLY_LENGTHSCALE"]

_NOISE_FLOOR = 1e-6
#: Length-scale (standardised units) pinned on a mean-only input (``GPConfig.mean_only_inputs``): the
#: squared-exponential and Gibbs kernels then differ from 1 along it by ``(dx / l)^2 / 2 < 1e-10`` over
#: any standardised spread below 10, so no kernel, neighbour search or inducing choice sees it.
MEAN_ONLY_LENGTHSCALE = 1.0e6


@dataclass
class FitHistory:
    """What happened while fitting.

    Attributes:
        elbo: VFE bound on the hyperparameter subset after each Adam step.
        local_loss: local composite negative log likelihood per point after each step.
        timings: stage -> seconds.
        notes: one-line remarks.
        validation: what the blocked cross-validation chose (:mod:`gcs_sysid.gp.validation`):
            ``latent_scale`` ``(P,)`` list, ``local_kept`` ``(P,)`` list, ``local_ratio`` ``(P,)``
            list (blocked squared error with / without the local layer); empty when it did not run.
    """

    elbo: list[float] = field(default_factory=list)
    local_loss: list[float] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    validation: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-able copy."""
        return {"elbo": list(self.elbo), "local_loss": list(self.local_loss), "timings": dict(self.timings),
                "notes": list(self.notes), "validation": dict(self.validation)}


def constrain_global(raw: dict, fixed: dict) -> GlobalParams:
    """Map unconstrained parameters to :class:`GlobalParams` (exp for scales, Cholesky of ``B``).

    The further kernels of a linear model of coregionalisation (``lmc_log_ls (J-1, D)``,
    ``lmc_L (J-1, P, R)``, ``lmc_log_kappa (J-1, P)``) are mapped the same way, one ``B_j`` each.
    ``fixed["L_mask"]`` ``(P, R)`` (optional, :func:`factor_mask`) zeroes the loadings of each shared
    factor outside its output group (``GPConfig.output_groups = "axes"``). ``fixed["G_embed"]``
    ``(G, P, Rg)`` (optional, :func:`group_embedding`; ``output_groups = "kernels"``): kernel ``g`` (the
    ICM's parameters for ``g = 0``, ``lmc_*[g-1]`` for the others) loads on group ``g``'s outputs only,
    its factor ``(P, Rg)`` from :func:`group_factors`. ``raw["group_A"]`` ``(G, P, Rg)`` (``output_groups =
    "kernels-free"``): the factors themselves, unconstrained (started per group, free to load on any output).
    """
    ls = jnp.where(fixed["active"], jnp.exp(raw["log_ls"]), 1.0)
    kernel = fixed.get("kernel")                 # (D,) False: a mean-only input (GPConfig.mean_only_inputs)
    if kernel is not None:
        ls = jnp.where(kernel, ls, MEAN_ONLY_LENGTHSCALE)
    Z = raw["Z"] if "Z" in raw else fixed["Z"]
    lmc_ls = lmc_A = None
    if "lmc_log_ls" in raw:
        lmc_ls = jnp.where(fixed["active"][None, :], jnp.exp(raw["lmc_log_ls"]), 1.0)
        if kernel is not None:
            lmc_ls = jnp.where(kernel[None, :], lmc_ls, MEAN_ONLY_LENGTHSCALE)
    if "group_A" in raw:                         # per-group kernels, loadings free ("kernels-free"), or one
        Ag = raw["group_A"]                      # kernel per output loading on its own group ("output-kernels")
        Ag = Ag * fixed["A_mask"] if "A_mask" in fixed else Ag
        A, lmc_A = Ag[0], Ag[1:]
    else:
        mask = fixed.get("L_mask")               # (P, R) 0/1: which outputs each shared factor loads on
        L = raw["L"] if mask is None else raw["L"] * mask
        B = coregionalisation(L, jnp.exp(raw["log_kappa"]) + _NOISE_FLOOR)
        if "lmc_L" in raw:
            Lj = raw["lmc_L"] if mask is None else raw["lmc_L"] * mask[None]
            Bj = jax.vmap(coregionalisation)(Lj, jnp.exp(raw["lmc_log_kappa"]) + _NOISE_FLOOR)
            if "G_embed" not in fixed:
                lmc_A = jnp.linalg.cholesky(Bj)
        if "G_embed" in fixed:                   # per-group kernels: kernel g loads on group g's outputs only
            Ag = group_factors(fixed["G_embed"], jnp.concatenate([B[None], Bj], axis=0))
            A, lmc_A = Ag[0], Ag[1:]
        else:
            A = jnp.linalg.cholesky(B)
    return GlobalParams(lengthscale=ls, A=A, noise=jnp.exp(raw["log_noise"]) + _NOISE_FLOOR,
                        Z=Z, prior_std=fixed["prior_std"], jitter=fixed["jitter"],
                        noise_chol=noise_correlation_factor(raw["noise_off"]) if "noise_off" in raw else None,
                        lmc_lengthscale=lmc_ls, lmc_A=lmc_A)


def noise_correlation_factor(off: jax.Array) -> jax.Array:
    """Lower Cholesky factor ``R (P, P)`` of a correlation matrix from unconstrained ``off (P, P)``.

    ``R = normalise_rows(I + tril(off, -1))``: every row has unit norm, so ``R R^T`` has a unit
    diagonal and is positive definite for any ``off`` (the "unit-diagonal Cholesky" map of
    Pinheiro and Bates 1996, "Unconstrained parametrizations for variance-covariance matrices",
    Stat. Comput. 6:289-296); ``off = 0`` is independent noise.
    """
    U = jnp.eye(off.shape[0], dtype=off.dtype) + jnp.tril(off, -1)
    return U / jnp.sqrt(jnp.sum(U * U, axis=1, keepdims=True))


_constrain_global_jit = stored_jit(constrain_global)


def _adam_init_body(raw):
    """Adam's initial state for ``raw`` (zero moments, step count 0; it does not depend on the step size)."""
    return optax.adam(1.0).init(raw)


#: Adam's initial state built by one compiled call (in a fresh process every eager JAX operation first compiles
#: a small program of its own), kept on disk as a stored program (:func:`gcs_sysid.jaxconfig.stored_jit`).
_adam_init = stored_jit(_adam_init_body)


def _global_loss(raw, fixed, Xs, Ys, mask=None):
    """``-ELBO`` per observed entry; ``mask (N, P)`` of 0/1 marks the observed outputs (None: all)."""
    params = constrain_global(raw, fixed)
    n_obs = Xs.shape[0] * Ys.shape[1] if mask is None else jnp.maximum(jnp.sum(mask), 1.0)
    return -elbo(params, stats_of(params, Xs, Ys, None, mask)) / n_obs


def _local_loss(raw, Xn, zn, rn):
    return local_objective(_constrain_local(raw), Xn, zn, rn)


def _constrain_local(raw) -> LocalParams:
    return LocalParams(lengthscale=jnp.exp(raw["log_ls"]), beta=1.5 * jnp.tanh(raw["beta"]),
                       amp=jnp.exp(raw["log_amp"]) + _NOISE_FLOOR, noise=jnp.exp(raw["log_noise"]) + _NOISE_FLOOR)


_constrain_local_jit = stored_jit(_constrain_local)


def _adam_step_body(loss, raw, opt_state, lr, args):
    """One Adam step on ``loss(raw, *args)``; a step with a non-finite loss or gradient is skipped."""
    value, grads = jax.value_and_grad(loss)(raw, *args)
    updates, new_state = optax.adam(lr).update(grads, opt_state, raw)
    new_raw = optax.apply_updates(raw, updates)
    good = jnp.isfinite(value)
    for g in jax.tree_util.tree_leaves(grads):
        good = good & jnp.all(jnp.isfinite(g))
    keep = lambda new, old: jax.tree_util.tree_map(lambda a, b: jnp.where(good, a, b), new, old)  # noqa: E731
    return keep(new_raw, raw), keep(new_state, opt_state), value


_adam_step = partial(jax.jit, static_argnames=("loss",))(_adam_step_body)


def _adam_stepper(loss, raw, opt_state, lr, args):
    """The Adam step of :func:`_adam` as ``step(raw, opt_state, lr, args)``: the program stored on disk beside the
    compilation cache (:func:`gcs_sysid.jaxconfig.stored_program`: no tracing after the first run on a machine), else
    the jitted :func:`_adam_step`. Same computation either way."""
    program = stored_program(_adam_step_body, (raw, opt_state, lr, args), static=(loss,))
    return partial(_adam_step, loss) if program is None else program


def _adam(loss, raw, opt_state, lr, args, n_steps: int, tol: float = 0.0, window: int = 10):
    """Up to ``n_steps`` compiled Adam steps (a Python loop over one compiled step compiles faster
    and, on CPU, runs faster than ``lax.scan`` here). Returns ``(raw, opt_state, losses)``.

    Early stopping: every ``window`` steps the mean loss of the last window is compared with the
    window before; when it improved by less than ``tol`` (the loss is per data point, so ``tol``
    is in nats per point and output) the optimisation stops. ``tol = 0`` runs all steps.
    """
    values = []
    lr = np.float64(lr)   # one strongly typed scalar: the compiled step is reused, never re-traced
    prev = np.inf
    step = _adam_stepper(loss, raw, opt_state, lr, args) if n_steps > 0 else None
    for k in range(n_steps):
        raw, opt_state, value = step(raw, opt_state, lr, args)
        values.append(value)
        if tol > 0 and (k + 1) % window == 0 and k + 1 < n_steps:
            cur = float(np.mean(np.asarray(jax.device_get(values[-window:]))))
            if np.isfinite(cur) and np.isfinite(prev) and prev - cur < tol:
                break
            prev = cur
    return raw, opt_state, np.asarray(jax.device_get(values))


#: The body-axis output groups of ``GPConfig.output_groups = "axes"``: longitudinal and lateral-directional.
AXIS_GROUPS = (("CX", "CZ", "Cm"), ("CY", "Cl", "Cn"))


def output_groups(names, cfg: GPConfig) -> np.ndarray | None:
    """Group label per output ``(P,)`` int for ``cfg.output_groups``, or None (no split).

    ``"axes"``, ``"kernels"``, ``"kernels-free"`` and ``"output-kernels"``: 0 for CX CZ Cm, 1 for CY Cl
    Cn, when every name is one of the six coefficients and
    both groups occur; otherwise (other outputs, one axis only, ``"none"``) None.
    """
    if cfg.output_groups not in ("axes", "kernels", "kernels-free", "output-kernels") or names is None:
        return None
    label = {n: g for g, group in enumerate(AXIS_GROUPS) for n in group}
    if any(n not in label for n in names):
        return None
    g = np.array([label[n] for n in names], int)
    return g if len(set(g.tolist())) > 1 else None


def factor_mask(groups: np.ndarray | None, rank: int) -> np.ndarray | None:
    """``(P, R)`` 0/1 loadings allowed for the shared factors: factor ``r`` loads only on the outputs of
    group ``r mod G`` (``groups (P,)`` labels ``0..G-1``; None: no mask). With ``R >= G`` each group
    has its own factors and ``B`` is block diagonal between the groups."""
    if groups is None or rank < 1:
        return None
    G = int(groups.max()) + 1
    return (groups[:, None] == (np.arange(rank) % G)[None, :]).astype(float)


def group_embedding(groups: np.ndarray) -> np.ndarray:
    """``(G, P, Rg)`` 0/1 embedding of each output group's outputs (``GPConfig.output_groups =
    "kernels"``): ``E[g, p, k] = 1`` when output ``p`` is the ``k``-th output of group ``g``;
    ``Rg`` the largest group's size (a smaller group's extra columns are 0)."""
    groups = np.asarray(groups, int)
    G, P = int(groups.max()) + 1, len(groups)
    Rg = max(int(np.sum(groups == g)) for g in range(G))
    E = np.zeros((G, P, Rg))
    for g in range(G):
        for k, p in enumerate(np.flatnonzero(groups == g)):
            E[g, p, k] = 1.0
    return E


def group_factors(E: jax.Array, B: jax.Array) -> jax.Array:
    """Coregionalisation factors ``(G, P, Rg)`` of per-group kernels: ``A_g = E_g chol(E_g^T B_g E_g)``.

    ``E`` ``(G, P, Rg)`` (:func:`group_embedding`), ``B`` ``(G, P, P)`` each kernel's coregionalisation
    matrix over all outputs, of which only group ``g``'s block is used: ``A_g A_g^T`` is that block,
    0 outside it, so kernel ``g``'s ``Rg`` latent processes load on group ``g`` alone (a padded
    column of a smaller group is 0)."""
    pad = 1.0 - jnp.sum(E, axis=1)                                          # (G, Rg): 1 on padded columns
    Bg = jnp.einsum("gpk,gpq,gql->gkl", E, B, E) + jax.vmap(jnp.diag)(pad)
    return jnp.einsum("gpk,gkl->gpl", E, jnp.linalg.cholesky(Bg))


def _group_split(Bfull: np.ndarray, rows: np.ndarray, rank: int) -> tuple[np.ndarray, np.ndarray]:
    """``(L (P, rank), kappa (P,))`` of one per-group kernel: :func:`_split_B` of the block
    ``Bfull[rows, rows]`` placed in those rows (the other rows' ``L`` 0, ``kappa`` 1: not used)."""
    P = len(Bfull)
    Lg, kg = _split_B(Bfull[np.ix_(rows, rows)], rank)
    L = np.zeros((P, rank))
    L[np.ix_(rows, np.arange(Lg.shape[1]))] = Lg
    kappa = np.ones(P)
    kappa[rows] = kg
    return L, kappa


def _split_B(B: np.ndarray, rank: int, mask: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(L (P, R), kappa (P,))`` with ``L L^T + diag(kappa) ~ B``: the leading ``rank`` eigenpairs in
    ``L``, the rest of the diagonal (at least a tenth of it) in ``kappa``. With ``mask (P, R)``
    (:func:`factor_mask`) each group's factors are the leading eigenpairs of its own block of ``B``."""
    P = len(B)
    if mask is not None:
        L0 = np.zeros((P, rank))
        for cols in {tuple(np.flatnonzero(mask[p])) for p in range(P)}:
            if not cols:
                continue
            rows = np.flatnonzero(mask[:, cols[0]] > 0)
            Lg, _ = _split_B(B[np.ix_(rows, rows)], len(cols))
            L0[np.ix_(rows, list(cols[:Lg.shape[1]]))] = Lg
        return L0, np.maximum(np.diag(B) - np.sum(L0**2, 1), 0.1 * np.diag(B))
    w, V = np.linalg.eigh(B)
    r = int(min(rank, P))
    L0 = V[:, ::-1][:, :r] * np.sqrt(np.maximum(w[::-1][:r], 0.0)) if r > 0 else np.zeros((P, 0))
    return np.asarray(L0, float), np.maximum(np.diag(B) - np.sum(L0**2, 1), 0.1 * np.diag(B))


def lmc_start_factors(J: int) -> np.ndarray:
    """Starting length-scale multipliers ``(J,)`` of the latent kernels: 1, 4, 1/4, 16, 1/16, ...

    Distinct starts break the symmetry between the kernels (from equal starts they stay equal);
    the bound then moves them. The second kernel starts longer: on a synthetic pair of outputs
    with length-scales 0.33 and 1.4 a start at 1/3 collapsed the second kernel onto the first
    (its variance went to ~0.01), a start at 4 separated them (``tests/gp/test_lmc.py``).
    """
    return np.array([4.0 ** ((-1) ** (j + 1) * ((j + 1) // 2)) for j in range(J)])


def _residual_cov_missing(Xs, Ys, obs, linear_mean: bool) -> np.ndarray:
    """Residual covariance ``(P, P)`` of the ridge linear mean with missing outputs (``obs (N, P)``):
    each output fitted on its own rows; the covariance from the complete rows when there are more
    than ``2 P`` of them, else its diagonal from each output's rows."""
    P = Ys.shape[1]
    Xa = np.concatenate([np.ones((len(Xs), 1)), Xs], axis=1)
    R = np.where(obs, Ys, np.nan)
    for p in range(P):
        rows = obs[:, p]
        if linear_mean and rows.sum() > 0:
            Xp = Xa[rows]
            W = np.linalg.solve(Xp.T @ Xp + 1e-3 * np.eye(Xa.shape[1]), Xp.T @ Ys[rows, p])
            R[rows, p] = Ys[rows, p] - Xp @ W
    complete = obs.all(1)
    if complete.sum() > 2 * P:
        Cr = np.cov(R[complete].T).reshape(P, P)
    else:
        Cr = np.diag(np.nan_to_num(np.nanvar(R, 0), nan=1.0))
    return Cr + 1e-6 * np.eye(P)


def linear_prior_std(cfg: GPConfig, terms: np.ndarray | None, P: int, D: int,
                     allowed: np.ndarray | None = None) -> np.ndarray:
    """Prior std of the linear-mean weights ``(P, D+1)`` (intercept first): ``cfg.prior_std`` on the
    intercept and on the regressors ``terms (P, D)`` keeps (None: all) and ``allowed (P, D)`` allows
    (None: all; :func:`mean_only_masks`), 0 on the others (the term is not in that output's mean); all 0
    without a linear mean."""
    if not cfg.linear_mean:
        return np.zeros((P, D + 1))
    keep = np.ones((P, D), bool) if terms is None else np.asarray(terms, bool)
    if allowed is not None:
        keep = keep & np.asarray(allowed, bool)
    return float(cfg.prior_std) * np.concatenate([np.ones((P, 1)), keep.astype(float)], axis=1)


def mean_only_masks(cfg: GPConfig, input_names, output_names, Xs: np.ndarray, Ys: np.ndarray,
                    active: np.ndarray, x_std: np.ndarray | None = None
                    ) -> tuple[np.ndarray | None, np.ndarray | None, dict]:
    """Which inputs the kernels see and which linear-mean terms each output may carry
    (``GPConfig.mean_only_inputs``, ``mean_only_outputs``; ``docs/gp.md``, "Mean-only inputs").

    A mean-only input is left out of every kernel. It may enter the linear mean of the
    ``mean_only_outputs`` only, and there only when its slope keeps ``|t| >= 2`` with coloured-residual
    standard errors in the backward elimination on these rows, in time order
    (:func:`gcs_sysid.gp.colored.significant_inputs`: the data's own test, the one the ``"validated"``
    linear terms use; its other choices are not used here) and, with ``GPConfig.mean_only_sign``, when that fit's
    slope has the sign physics gives it (the pipeline: ``Cm_alpha_dot < 0``). With
    ``GPConfig.mean_only_partners`` (the pipeline: ``q_hat`` for ``alpha_dot_hat``), that fit must also keep the
    partner, with the sign ``mean_only_sign``, and the input's slope may be at most ``GPConfig.mean_only_ratio``
    times the partner's in data units (``|Cm_alpha_dot| <= |Cm_q|``, both ``< 0``): a term that pushes its
    partner out of the mean or takes more than it has split a sum the data determine only as a sum.

    Args:
        cfg: settings. input_names ``(D,)``, output_names ``(P,)``: the model's column names.
        Xs: ``(N, D)``, Ys: ``(N, P)`` standardised training rows in time order (NaN: a missing output).
        active: ``(D,)`` inputs that vary.
        x_std: ``(D,)`` the standardisation's input scales (data units per standardised unit), for the
            partner ratio; None: the ratio is taken in standardised units.

    Returns:
        ``(kernel (D,) bool, allowed (P, D) bool, info)``, ``(None, None, {})`` when no named mean-only
        input is among ``input_names``; ``info``: ``{"inputs": [names], "outputs": {output: [kept inputs]}}``
        (and ``"wrong_sign": ["output:input", ...]`` for the significant slopes of the wrong sign,
        ``"partner": ["output:input: why", ...]`` for those the partner rule took out, and
        ``"slopes": {"output:name": slope}`` of the input and its partner in that fit, per data unit of the
        input and standardised unit of the output).

    Raises:
        InputError: a mean-only input that is not among the trailing columns (a query may leave out only
            trailing columns).
    """
    from ..errors import InputError
    from .colored import significant_inputs

    names = list(input_names)
    only = [d for d, n in enumerate(names) if n in cfg.mean_only_inputs]
    if not only:
        return None, None, {}
    D, P = len(names), Ys.shape[1]
    if only != list(range(D - len(only), D)):
        raise InputError(f"gp: mean-only inputs {[names[d] for d in only]} must be the last columns of X")
    kernel = np.ones(D, bool)
    kernel[only] = False
    allowed = np.ones((P, D), bool)
    allowed[:, only] = False
    info = {"inputs": [names[d] for d in only], "outputs": {}}
    partners = dict(zip([names[d] for d in only], cfg.mean_only_partners))
    scale = np.ones(D) if x_std is None else np.asarray(x_std, float)
    for p, name in enumerate(output_names):
        if name not in cfg.mean_only_outputs or not cfg.linear_mean:
            continue
        keep = significant_inputs(Xs, Ys[:, [p]], active)[0]
        if (cfg.mean_only_sign or partners) and keep[only].any():   # the slopes in that least-squares fit
            rows = np.isfinite(Ys[:, p])
            cols = list(np.flatnonzero(keep))
            A = np.concatenate([np.ones((int(rows.sum()), 1)), Xs[rows][:, cols]], axis=1)
            w = np.linalg.lstsq(A, Ys[rows, p], rcond=None)[0][1:] / scale[cols]     # data units (x Y's scale)
            slope = dict(zip(cols, w))
            for d in only:
                if not keep[d]:
                    continue
                info.setdefault("slopes", {})[f"{name}:{names[d]}"] = float(slope[d])
                if cfg.mean_only_sign and np.sign(slope[d]) != np.sign(cfg.mean_only_sign):
                    keep[d] = False
                    info.setdefault("wrong_sign", []).append(f"{name}:{names[d]}")
                    continue
                partner = partners.get(names[d], "")
                if not partner:
                    continue
                e = names.index(partner) if partner in names else -1
                sign = cfg.mean_only_sign or np.sign(slope[d])
                why = ""
                if e < 0 or not keep[e]:
                    why = f"{partner} not in the fit"
                else:
                    info["slopes"][f"{name}:{partner}"] = float(slope[e])
                    if np.sign(slope[e]) != np.sign(sign):
                        why = f"{partner} slope of the wrong sign"
                    elif abs(slope[d]) > float(cfg.mean_only_ratio) * abs(slope[e]):
                        why = f"|slope| above {float(cfg.mean_only_ratio):g} x {partner}'s"
                if why:
                    keep[d] = False
                    info.setdefault("partner", []).append(f"{name}:{names[d]}: {why}")
        allowed[p, only] = keep[only]
        info["outputs"][name] = [names[d] for d in only if keep[d]]
    return kernel, allowed, info


def rows_without_mean_only(X, Y, cfg: GPConfig, input_names, output_names
                           ) -> tuple[np.ndarray, tuple | None, list[str]]:
    """Rows that lack only their mean-only inputs (``GPConfig.mean_only_inputs``: NaN there, every other
    input finite): they stay training rows when the pre-fit gates (:func:`mean_only_masks`, run on the rows
    that carry the inputs) put the inputs in no output's mean, as the model is then fitted without those
    columns; otherwise :func:`gcs_sysid.gp.scaling.check_training` drops them (a kept term needs its value).

    Args:
        X: ``(N, D)`` regressors, the mean-only inputs the trailing columns (NaN allowed there).
        Y: ``(N, P)`` outputs (NaN: missing). cfg: settings. input_names ``(D,)`` (None: nothing to do),
        output_names ``(P,)``.

    Returns:
        ``(X, input_names, notes)``: ``X`` ``(N, D)`` unchanged, or ``(N, D - k)`` without the ``k`` mean-only
        columns when the gates keep them nowhere and some rows lack them; one-line notes.
    """
    from .scaling import Standardiser, check_training

    if input_names is None or not cfg.mean_only_inputs or np.ndim(X) != 2 or np.ndim(Y) != 2:
        return X, input_names, []
    names = tuple(input_names)
    k = 0
    while k < len(names) and names[len(names) - 1 - k] in cfg.mean_only_inputs:
        k += 1
    X = np.asarray(X, float)
    if not k or k == len(names) or X.shape[1] != len(names) or np.shape(Y)[0] != X.shape[0]:
        return X, input_names, []
    Y = np.asarray(Y, float)
    head = np.isfinite(X[:, :-k]).all(1) & np.isfinite(Y).any(1)
    tail = np.isfinite(X[:, -k:]).all(1)
    lack = head & ~tail
    if not lack.any() or (head & tail).sum() < 3:
        return X, input_names, []
    Xf, Yf, _ = check_training(X[head & tail], Y[head & tail], min_rows=3, partial=True)
    scaler, _ = Standardiser.fit(Xf, Yf, names)
    _, _, info = mean_only_masks(cfg, names, output_names, scaler.x(Xf), scaler.y(Yf), scaler.active, scaler.x_std)
    which = ", ".join(names[-k:])
    if any(info.get("outputs", {}).values()):
        return X, input_names, [f"gp: {int(lack.sum())} of {int(head.sum())} rows without {which} left out "
                                "(the gates keep it in a mean)"]
    n_carry = int((head & tail).sum())
    return X[:, :-k], names[:-k], [f"gp: {which} in no output's linear mean (the gates on the {n_carry} rows that "
                                    f"carry it): fitted without, on all {int(head.sum())} rows"]


def linear_terms_of(Xs: np.ndarray, Ys: np.ndarray, active: np.ndarray, cfg: GPConfig) -> np.ndarray | None:
    """The regressors of each output's linear mean ``(P, D)`` bool for ``cfg.linear_terms`` (None: every
    regressor, ``"all"``): :func:`gcs_sysid.gp.colored.significant_inputs` on the rows in time order."""
    if cfg.linear_terms in ("all", "validated") or not cfg.linear_mean:
        return None
    from .colored import significant_inputs

    return significant_inputs(Xs, Ys, active)


def _init_global(Xs, Ys, active, cfg: GPConfig, Z, terms: np.ndarray | None = None,
                 groups: np.ndarray | None = None, masks=None):
    """Initial unconstrained parameters from a ridge fit of the linear mean.

    ``terms`` ``(P, D)`` bool: the regressors of each output's linear mean (None: all); the ridge fit
    of output ``p`` uses its own, and the prior std of the others' weights is 0. ``groups`` ``(P,)``
    (:func:`output_groups`): each shared factor starts on its own group's block of the residual
    covariance and stays there (``fixed["L_mask"]``). ``masks``: ``(kernel (D,), allowed (P, D))`` from
    :func:`mean_only_masks` (None: every input in the kernels and every mean).

    With ``cfg.latent_kernels = J > 1`` the residual covariance is shared equally between the
    kernels (``B_j = B0 / J``) and the length-scales start at :func:`lmc_start_factors` times the
    ICM start. ``B0`` is 0.7 of the residual covariance and each noise variance 0.3 of the residual's;
    with ``cfg.noise_correlation`` and ``cfg.noise_start = "noise"`` (complete rows, no per-group kernels)
    ``B0`` keeps only its diagonal and the noise correlation starts at the residual's, so the noise
    covariance starts at 0.3 of the residual covariance, cross-output part included.
    """
    P = Ys.shape[1]
    R = Ys
    obs = np.isfinite(Ys)
    kernel, allowed = (None, None) if masks is None else masks
    if allowed is not None and cfg.linear_mean:
        terms = np.asarray(allowed, bool) if terms is None else np.asarray(terms, bool) & allowed
    if obs.all():
        if cfg.linear_mean:
            Xa = np.concatenate([np.ones((len(Xs), 1)), Xs], axis=1)   # design(): [1, x]
            if terms is None:
                W = np.linalg.solve(Xa.T @ Xa + 1e-3 * np.eye(Xa.shape[1]), Xa.T @ Ys)
                R = Ys - Xa @ W
            else:                                                    # each output its own terms
                R = np.empty_like(Ys)
                for p in range(P):
                    Xp = Xa[:, np.r_[True, np.asarray(terms[p], bool)]]
                    R[:, p] = Ys[:, p] - Xp @ np.linalg.solve(Xp.T @ Xp + 1e-3 * np.eye(Xp.shape[1]), Xp.T @ Ys[:, p])
        Cr = np.cov(R.T).reshape(P, P) + 1e-6 * np.eye(P)
    else:
        Cr = _residual_cov_missing(Xs, Ys, obs, cfg.linear_mean)
    per_group = _per_group(cfg, groups)
    J = int(cfg.latent_kernels)
    noise_first = bool(cfg.noise_correlation and cfg.noise_start == "noise" and obs.all() and not per_group)
    n_active = max(int(active.sum()), 1)
    ls0 = np.log(0.5 * np.sqrt(n_active))
    if per_group:                      # kernel g on group g's block of the residual covariance, whole
        parts = [_group_split(0.7 * Cr, np.flatnonzero(groups == g), int(cfg.rank))
                 for g in range(int(groups.max()) + 1)]
        L0, kappa = parts[0][0], parts[0][1] + 1e-4
        mask = None
    else:
        B0 = 0.7 * Cr / J
        if noise_first:                # the cross-output part starts in the noise (GPConfig.noise_start)
            B0 = np.diag(np.diag(B0))
        mask = factor_mask(groups, int(cfg.rank))
        L0, kappa = _split_B(B0, cfg.rank, mask)
        kappa = kappa + 1e-4
    # host arrays moved once with device_put (jnp.asarray of a NumPy array compiles a program per shape)
    raw = {"log_ls": np.full(Xs.shape[1], ls0), "L": L0,
           "log_kappa": np.log(kappa), "log_noise": np.log(0.3 * np.diag(Cr) + 1e-4)}
    if per_group:                      # every kernel starts at the ICM's length-scales: their outputs differ
        raw["lmc_log_ls"] = np.full((len(parts) - 1, Xs.shape[1]), ls0)
        raw["lmc_L"] = np.stack([L for L, _ in parts[1:]])
        raw["lmc_log_kappa"] = np.stack([np.log(k + 1e-4) for _, k in parts[1:]])
    elif J > 1:
        f = lmc_start_factors(J)[1:]
        raw["lmc_log_ls"] = np.repeat((ls0 + np.log(f))[:, None], Xs.shape[1], axis=1)
        raw["lmc_L"] = np.repeat(L0[None], J - 1, axis=0)
        raw["lmc_log_kappa"] = np.repeat(np.log(kappa)[None], J - 1, axis=0)
    if cfg.noise_correlation:
        raw["noise_off"] = np.zeros((P, P))
    if noise_first:                    # the residual's correlation, as the unconstrained factor of the noise's
        d = np.sqrt(np.diag(Cr))
        Rl = np.linalg.cholesky(Cr / np.outer(d, d))      # positive definite: Cr carries + 1e-6 I
        raw["noise_off"] = np.tril(Rl / np.diag(Rl)[:, None], -1)    # inverse of noise_correlation_factor
    if cfg.train_inducing:
        raw["Z"] = np.asarray(Z, float)
    fixed = {"active": np.asarray(active, bool), "Z": np.asarray(Z, float),
             "prior_std": linear_prior_std(cfg, terms, P, Xs.shape[1], allowed), "jitter": np.float64(cfg.jitter)}
    if kernel is not None:
        fixed["kernel"] = np.asarray(kernel, bool)
    if mask is not None:
        fixed["L_mask"] = mask
    if per_group and cfg.output_groups == "kernels-free":        # the same start, loadings then free
        raw = _free_factors(raw, group_embedding(groups))
    elif per_group and cfg.output_groups == "output-kernels":    # column k of group g's factor: output (g, k)'s kernel
        raw = _free_factors(raw, group_embedding(groups))
        E = group_embedding(groups)
        A1 = np.zeros((P, P, 1))
        for p in range(P):
            g = int(groups[p])
            A1[p, :, 0] = raw["group_A"][g][:, int(np.flatnonzero(E[g, p])[0])]
        raw["group_A"] = A1
        raw["lmc_log_ls"] = np.full((P - 1, Xs.shape[1]), ls0)
        fixed["A_mask"] = output_kernel_mask(groups)
    elif per_group:
        fixed["G_embed"] = group_embedding(groups)
    return jax.device_put(raw), jax.device_put(fixed)


def output_kernel_mask(groups: np.ndarray) -> np.ndarray:
    """``(P, P, 1)`` 0/1 loadings of ``output_groups = "output-kernels"``: the latent of output ``j``'s
    kernel loads on the outputs of ``j``'s group only."""
    groups = np.asarray(groups, int)
    return (groups[:, None] == groups[None, :]).astype(float)[:, :, None]


def _free_factors(raw: dict, E: np.ndarray) -> dict:
    """``raw`` with the per-group kernels' ``L``/``kappa`` entries replaced by their factors
    ``group_A (G, P, Rg)`` (:func:`group_factors` of the same ``B_g``, in NumPy), for
    ``output_groups = "kernels-free"``."""
    raw = dict(raw)
    Ls = [np.asarray(raw.pop("L"))] + list(np.asarray(raw.pop("lmc_L")))
    ks = [np.asarray(raw.pop("log_kappa"))] + list(np.asarray(raw.pop("lmc_log_kappa")))
    out = []
    for Eg, L, lk in zip(E, Ls, ks):
        B = L @ L.T + np.diag(np.exp(lk) + _NOISE_FLOOR)
        Bg = Eg.T @ B @ Eg + np.diag(1.0 - Eg.sum(0))
        out.append(Eg @ np.linalg.cholesky(Bg))
    raw["group_A"] = np.stack(out)
    return raw


def _per_group(cfg: GPConfig, groups: np.ndarray | None) -> bool:
    """Whether the global layer has one latent kernel per output group (``output_groups = "kernels"``
    and the outputs split into groups)."""
    return cfg.output_groups in ("kernels", "kernels-free", "output-kernels") and groups is not None


def _unconstrain(p: GlobalParams, cfg: GPConfig, groups: np.ndarray | None = None) -> dict:
    """Unconstrained values near ``p`` (inverse of :func:`constrain_global`; ``B`` split as the initial
    values are: its leading ``rank`` eigenpairs in ``L``, per output group with ``groups``, the rest
    of the diagonal in ``kappa``)."""
    A = np.asarray(p.A)
    B = A @ A.T
    mask = factor_mask(groups, int(cfg.rank))
    L0, kappa = _split_B(B, cfg.rank, mask)
    out = {"log_ls": np.log(np.asarray(p.lengthscale)), "L": L0,
           "log_kappa": np.log(np.maximum(kappa - _NOISE_FLOOR, 1e-8)),
           "log_noise": np.log(np.maximum(np.asarray(p.noise) - _NOISE_FLOOR, 1e-8))}
    G = 0 if groups is None else int(np.max(groups)) + 1
    if _per_group(cfg, groups) and p.n_kernels == len(groups) and cfg.output_groups == "output-kernels":
        for k in ("L", "log_kappa"):
            out.pop(k)
        out.update(lmc_log_ls=np.log(np.asarray(p.lmc_lengthscale)), group_A=np.asarray(p.factors))
    elif _per_group(cfg, groups) and p.n_kernels == G and cfg.output_groups == "kernels-free":
        for k in ("L", "log_kappa"):
            out.pop(k)
        out.update(lmc_log_ls=np.log(np.asarray(p.lmc_lengthscale)), group_A=np.asarray(p.factors))
    elif _per_group(cfg, groups) and p.n_kernels == G:
        Bp = np.asarray(p.B_parts)
        parts = [_group_split(Bp[g], np.flatnonzero(groups == g), int(cfg.rank)) for g in range(G)]
        logk = [np.log(np.maximum(k - _NOISE_FLOOR, 1e-8)) for _, k in parts]
        out.update(L=parts[0][0], log_kappa=logk[0], lmc_log_ls=np.log(np.asarray(p.lmc_lengthscale)),
                   lmc_L=np.stack([L for L, _ in parts[1:]]), lmc_log_kappa=np.stack(logk[1:]))
    elif p.lmc_A is not None and cfg.latent_kernels == p.n_kernels:
        parts = [_split_B(Aj @ Aj.T, cfg.rank, mask) for Aj in np.asarray(p.lmc_A)]
        out["lmc_log_ls"] = np.log(np.asarray(p.lmc_lengthscale))
        out["lmc_L"] = np.stack([L for L, _ in parts])
        out["lmc_log_kappa"] = np.stack([np.log(np.maximum(k - _NOISE_FLOOR, 1e-8)) for _, k in parts])
    if cfg.noise_correlation:
        R = np.eye(len(B)) if p.noise_chol is None else np.asarray(p.noise_chol)
        out["noise_off"] = np.tril(R / np.diag(R)[:, None], -1)    # inverse of noise_correlation_factor
    return out


def fit_local(cfg: GPConfig, params: GlobalParams, Xs, resid, history: FitHistory, store=None):
    """Local layer on the rows ``Xs (N, D)`` with global residuals ``resid (N, P)`` (standardised).

    ``store``: the :class:`~gcs_sysid.gp.local.LocalStore` of these rows when already built (as
    ``build_store`` would), else built here. Returns ``(LocalParams, LocalStore)``; the loss history
    is appended to ``history``.
    """
    metric = 1.0 / np.asarray(params.metric_lengthscale())
    store = build_store(Xs, resid, metric, cfg.local_neighbours) if store is None else store
    full = store
    complete = np.isfinite(resid).all(1)
    if not complete.all() and complete.sum() >= 2:
        # missing outputs: the composite likelihood shares one eigendecomposition between the outputs,
        # so it is taken over the rows that carry all of them; the returned store keeps every row (a
        # missing residual is skipped in prediction, gp.local._one_query)
        Xs, resid = Xs[complete], resid[complete]
        store = build_store(Xs, resid, metric, cfg.local_neighbours)
    rng = np.random.default_rng(cfg.seed + 7)
    centres = rng.choice(len(Xs), min(cfg.local_batch, len(Xs)), replace=False)
    idx, _ = neighbours(store, Xs[centres])
    args = jax.device_put((Xs[idx], store.z[idx], resid[idx]))
    # start from the empirical variogram: half the mean squared residual difference between each
    # centre and its nearest stored neighbour estimates the nugget (noise), the rest of the residual
    # variance is signal (Cressie 1993, Statistics for Spatial Data, sec. 2.4)
    v = np.maximum(resid.var(0), 1e-8)
    if idx.shape[1] > 1:
        nugget = 0.5 * np.mean((resid[idx[:, 0]] - resid[idx[:, 1]]) ** 2, 0)
        noise0 = np.clip(nugget, 0.01 * v, 0.9 * v)
    else:
        noise0 = 0.5 * v
    raw = jax.device_put({"log_ls": np.log(np.maximum(0.25 * np.asarray(params.metric_lengthscale()), 1e-3)),
                          "beta": np.float64(0.0), "log_amp": np.log(np.maximum(v - noise0, 0.1 * v)),
                          "log_noise": np.log(noise0)})
    if cfg.local_steps > 0:
        opt_state = _adam_init(raw)
        raw, _, values = _adam(_local_loss, raw, opt_state, cfg.local_learning_rate, args, int(cfg.local_steps),
                               cfg.tol)
        history.local_loss.extend(np.asarray(values).tolist())
    local = _constrain_local_jit(raw)
    pinned = np.asarray(params.metric_lengthscale()) >= MEAN_ONLY_LENGTHSCALE
    if pinned.any():                             # a mean-only input: no local kernel along it either
        local = replace(local, lengthscale=jnp.where(pinned, MEAN_ONLY_LENGTHSCALE, local.lengthscale))
    return local, full


def learn_global(Xs: np.ndarray, Ys: np.ndarray, active: np.ndarray, cfg: GPConfig, M: int,
                 history: FitHistory, start: GlobalParams | None = None,
                 groups: np.ndarray | None = None, masks=None) -> GlobalParams:
    """Global hyperparameters by Adam on the VFE bound over a random subset of ``n_train_max`` rows.

    Args:
        Xs: ``(N, D)``, Ys: ``(N, P)`` standardised rows (the fit's rows, or the stored rows of a
            streaming model). active: ``(D,)`` inputs that vary.
        cfg: settings. M: inducing points of the returned parameters, chosen again by mutual
            information with the learned length-scales when larger than the ``n_inducing_hyper``
            used while learning (0: keep those).
        history: receives the bound after each step and the timings of the stage.
        start: warm start (a refresh): the length-scales, noise and coregionalisation to start
            from instead of the ridge-regression initial values.
        groups: ``(P,)`` output group labels (:func:`output_groups`; None: every factor on every output).
        masks: ``(kernel (D,), allowed (P, D))`` from :func:`mean_only_masks`, or None.

    Returns:
        :class:`GlobalParams` (constrained).
    """
    D = Xs.shape[1]
    P = Ys.shape[1]
    t0 = time.perf_counter()
    # on every row, in time order (coloured residuals); mean-only inputs are no candidates here (their own gate
    # is mean_only_masks), so they cannot take a collinear regressor's t
    kern = None if masks is None or masks[0] is None else np.asarray(masks[0], bool)
    terms = linear_terms_of(Xs, Ys, active if kern is None else np.asarray(active, bool) & kern, cfg)
    if terms is not None and kern is not None:
        terms[:, ~kern] = np.asarray(masks[1], bool)[:, ~kern]
    if terms is not None:
        history.validation["linear_terms"] = [[int(d) for d in np.flatnonzero(k)] for k in terms]
    stride = hyper_stride_of(Xs, Ys, active, cfg)
    history.validation["hyper_stride"] = stride
    if stride > 1:                     # every k-th row in time order: coloured noise decorrelates (opt-in)
        every = np.arange(0, len(Xs), stride)
        sub = every[np.sort(random_points(len(every), cfg.n_train_max, cfg.seed))]
    else:
        sub = random_points(len(Xs), cfg.n_train_max, cfg.seed)
    obs = np.isfinite(Ys[sub])
    # missing outputs (heterotopic rows): the bound over the observed entries (None: all observed)
    mask_h = None if obs.all() else jax.device_put(obs.astype(float))
    Xh, Yh = jax.device_put((Xs[sub], np.where(obs, Ys[sub], 0.0)))

    M = int(min(M, len(Xs)))
    Mh = M if cfg.train_inducing or cfg.n_inducing_hyper is None else int(min(cfg.n_inducing_hyper, M))
    if M == 0:
        Mh = int(min(cfg.n_inducing_hyper or cfg.n_inducing, len(Xs)))
    ls0 = (np.full(D, 0.5 * np.sqrt(max(int(active.sum()), 1))) * min(lmc_start_factors(int(cfg.latent_kernels)))
           if start is None else np.asarray(start.metric_lengthscale()))
    if masks is not None and masks[0] is not None:
        ls0 = np.where(masks[0], ls0, MEAN_ONLY_LENGTHSCALE)
    Z = select_inducing(Xs, Mh, ls0, cfg.inducing, cfg.mi_pool, seed=cfg.seed)
    raw, fixed = _init_global(Xs[sub], Ys[sub], active, cfg, Z, terms, groups, masks)
    if start is not None:
        raw = jax.device_put(dict(jax.device_get(raw), **_unconstrain(start, cfg, groups)))
    history.timings["init"] = time.perf_counter() - t0

    def reselect(raw, fixed, m):
        p = _constrain_global_jit(raw, fixed)
        bdiag = np.diag(np.asarray(p.B))
        nugget = float(np.mean(np.asarray(p.noise) / (bdiag + np.asarray(p.noise))))
        Z = select_inducing(Xs, m, np.asarray(p.metric_lengthscale()), cfg.inducing, cfg.mi_pool,
                            nugget=max(nugget, 1e-4), seed=cfg.seed)
        return dict(fixed, Z=jax.device_put(Z))

    first = cfg.steps // 2 if cfg.reselect else cfg.steps
    opt_state = _adam_init(raw)
    for stage, n_steps in enumerate((first, cfg.steps - first)):
        if n_steps <= 0:
            continue
        raw, opt_state, values = _adam(_global_loss, raw, opt_state, cfg.learning_rate, (fixed, Xh, Yh, mask_h),
                                       int(n_steps), cfg.tol)
        history.elbo.extend((-np.asarray(values) * (Xh.shape[0] * P if mask_h is None else obs.sum())).tolist())
        if stage == 0 and cfg.reselect and cfg.steps > first and not cfg.train_inducing:
            fixed = reselect(raw, fixed, Mh)
    if (cfg.coupling_rows == "all" and len(sub) < len(Xs) and mask_h is None and np.isfinite(Ys).all()
            and int(cfg.latent_kernels) == 1 and not _per_group(cfg, groups)):
        t1 = time.perf_counter()
        raw = coupling_on_all_rows(raw, fixed, Xs, Ys, cfg)
        history.timings["coupling_rows"] = time.perf_counter() - t1
    if Mh < M:
        fixed = reselect(raw, fixed, M)
    params = _constrain_global_jit(raw, fixed)
    if cfg.coupling == "off":          # learned with the coupling, kept without it (GPConfig.coupling)
        from .joint import decoupled

        params = decoupled(params)
    return params


def posterior_noise(params: GlobalParams, cfg: GPConfig, history: FitHistory) -> GlobalParams:
    """``params`` with the noise covariance the posterior conditions on (``GPConfig.noise_posterior``).

    ``"diagonal"`` (with ``noise_correlation``): the learned noise correlation (recorded in
    ``history.validation["noise_correlation_learned"]``, ``(P, P)`` list) is replaced by the identity, the per-output
    variances kept. Called after the likelihood's decisions (the bound, the coupling test: the full noise covariance
    keeps the gusts' shared error out of ``B``) and before the choices made by the posterior mean's blocked error (the
    validated linear terms and mean-only inputs; the latent scales and the coupling gate in :func:`validated_global`
    drop it themselves), so those see the posterior the model uses. Why: with a noise correlation ``Sigma_pq`` the
    posterior mean is a seemingly-
    unrelated-regressions GLS (Zellner 1962, JASA 57, eq. 2.8): output ``q``'s residual enters output ``p``'s
    estimate. With the same regressors and priors in every output that moves nothing (Zellner's sec. 3 equivalence
    with equation-by-equation least squares); with different ones (alpha_dot_hat a mean-only input of Cm alone, each
    output its own linear terms and latent scale) it moves ``p``'s slopes by what ``q``'s model leaves out
    (``docs/gp.md``, "Noise: learned, not conditioned on"). Otherwise ``params`` unchanged."""
    if cfg.noise_correlation and cfg.noise_posterior == "diagonal" and params.noise_chol is not None:
        R = np.asarray(params.noise_chol)
        history.validation["noise_correlation_learned"] = (R @ R.T).tolist()
        params = replace(params, noise_chol=None)
    return params


#: the hyperparameters :func:`coupling_on_all_rows` learns again (the rest of ``raw`` is held)
COUPLING_KEYS = ("L", "log_kappa", "log_noise", "noise_off")


def _coupling_loss(free, held, fixed, st):
    """``-ELBO`` per entry of the statistics ``st`` with ``free`` (``COUPLING_KEYS``) over ``held``."""
    params = constrain_global(dict(held, **free), fixed)
    return -elbo(params, st) / (st.n * params.noise.shape[0])


def coupling_on_all_rows(raw: dict, fixed: dict, Xs: np.ndarray, Ys: np.ndarray, cfg: GPConfig) -> dict:
    """The coregionalisation ``B`` and the noise covariance learned again on every row (``GPConfig.coupling_rows``).

    The bound of :func:`learn_global` sees ``n_train_max`` random rows; on a coloured 50 Hz flight those
    determine an off-diagonal of ``B`` poorly (``docs/gp.md``, "Coupling from every row"). Here the
    kernel (length-scales) and the inducing inputs ``fixed["Z"]`` are held, the sufficient statistics of
    all rows are accumulated once (:func:`gcs_sysid.gp.batching.global_stats`; they depend on neither
    ``B`` nor the noise), and Adam climbs the same collapsed bound (Titsias 2009) in ``B``'s factor
    ``L``, its independent part ``kappa``, the noise variances and, with ``noise_correlation``, the
    noise correlation, from where the subset left them. The model is the multi-task GP with a free
    noise covariance, ``B kron K + Sigma kron I`` (Bonilla, Chai and Williams 2008, "Multi-task Gaussian
    process prediction", NIPS 20, sec. 2; Alvarez, Rosasco and Lawrence 2012, "Kernels for vector-valued
    functions: a review", Found. Trends Mach. Learn. 4(3), sec. 4.2 and 6.1): with every row the signal's
    and the noise's cross-output covariances are separated by the same data the posterior conditions on.

    Args:
        raw, fixed: unconstrained and fixed parameters of :func:`learn_global` (complete rows, one kernel).
        Xs: ``(N, D)``, Ys: ``(N, P)`` standardised rows, every entry finite.
        cfg: settings (``steps // 2`` steps at most, ``learning_rate``, ``tol``, ``batch_size``).

    Returns:
        ``raw`` with the ``COUPLING_KEYS`` entries learned again.
    """
    params = _constrain_global_jit(raw, fixed)
    st = global_stats(params, Xs, Ys, int(cfg.batch_size))
    free = {k: raw[k] for k in COUPLING_KEYS if k in raw}
    held = {k: v for k, v in raw.items() if k not in free}
    free, _, _ = _adam(_coupling_loss, free, _adam_init(free), cfg.learning_rate, (held, fixed, st),
                       max(int(cfg.steps) // 2, 1), cfg.tol)
    return dict(held, **free)


def hyper_stride_of(Xs: np.ndarray, Ys: np.ndarray, active: np.ndarray, cfg: GPConfig) -> int:
    """The stride between the rows the global hyperparameters are learned on (``GPConfig.hyper_stride``).

    ``cfg.hyper_stride >= 1``: that number. 0: the training residual's decorrelation time in rows, the median
    over outputs of :func:`gcs_sysid.gp.colored.decorrelation_lag` (first lag with autocorrelation below 1/e)
    of :func:`gcs_sysid.gp.colored.linear_residual` (ridge fit on the ``active`` columns), rounded up; at most
    ``N // 20`` so that at least ~20 rows remain. Rows in time order: ``Xs (N, D)``, ``Ys (N, P)``
    standardised.
    """
    if int(cfg.hyper_stride) >= 1:
        return int(cfg.hyper_stride)
    from .colored import decorrelation_lag, linear_residual

    act = np.asarray(active, bool)
    lag = decorrelation_lag(linear_residual(Xs[:, act], Ys))
    return int(max(1, min(int(np.ceil(np.median(lag))), len(Xs) // 20)))


def fit_gp(X, Y, config: GPConfig = GPConfig(), input_names=None, output_names=None
           ) -> tuple[LocalGlobalGP, FitHistory]:
    """Fit the local + global approximated dependent GP to ``Y (N, P)`` at ``X (N, D)``.

    Args:
        X: ``(N, D)`` regressors (for the pipeline ``REGRESSORS``: alpha, beta, p_hat, q_hat,
            r_hat, delta_e, delta_a, delta_r, delta_t, V in rad, -, m/s).
        Y: ``(N, P)`` coefficients (``COEFFICIENTS``: CX CY CZ Cl Cm Cn). A NaN marks a missing
            output of that row (heterotopic rows, e.g. moments rejected where the forces are kept):
            each output is conditioned on the rows that carry it (``docs/gp.md``, "Missing outputs").
        config: :class:`GPConfig`.
        input_names, output_names: column names for the summary (default: the
            regressors and coefficients when the widths match, else ``x0..``, ``y0..``).

    Returns:
        ``(model, history)``.

    Raises:
        InputError: wrong shapes. DataError: fewer than 3 finite rows, or an output with fewer
        than 3 finite values.

    Sources: Titsias (2009) for the bound; Alvarez, Rosasco and Lawrence (2012) for the
    coregionalisation; Krause, Singh and Guestrin (2008) for the selection; Paciorek and
    Schervish (2004) for the local covariance.
    """
    from ..aero.table import COEFFICIENTS, REGRESSORS
    from ..errors import DataError

    enable_x64()
    cfg, history, t0 = config, FitHistory(), time.perf_counter()
    Y_names = None if output_names is None else list(output_names)
    if np.ndim(Y) == 2 and (Y_names is None or len(Y_names) != np.shape(Y)[1]):     # the summary's default names
        Y_names = (list(COEFFICIENTS) if np.shape(Y)[1] == len(COEFFICIENTS)
                   else [f"y{p}" for p in range(np.shape(Y)[1])])
    X, input_names, notes = rows_without_mean_only(X, Y, cfg, input_names, Y_names)
    X, Y, more = check_training(X, Y, min_rows=3, partial=True, output_names=Y_names)
    notes += more
    D, P = X.shape[1], Y.shape[1]
    if not np.all(np.isfinite(Y)):
        few = [Y_names[p] for p in range(P) if np.isfinite(Y[:, p]).sum() < 3]
        if few:
            raise DataError(f"gp: {', '.join(few)}: fewer than 3 finite values; fit only the outputs the data carry")
        if cfg.noise_correlation:
            cfg = replace(cfg, noise_correlation=False)
            notes.append("gp: rows miss some outputs: the noise is taken as independent between outputs "
                         "(noise_correlation needs complete rows)")
    input_names = tuple(input_names or (REGRESSORS if D == len(REGRESSORS) else [f"x{d}" for d in range(D)]))
    output_names = tuple(output_names or (COEFFICIENTS if P == len(COEFFICIENTS) else [f"y{p}" for p in range(P)]))
    scaler, more = Standardiser.fit(X, Y, input_names)
    notes += more
    Xs, Ys = scaler.x(X), scaler.y(Y)
    M = int(min(cfg.n_inducing, len(Xs)))
    if M < cfg.n_inducing:
        notes.append(f"gp: only {len(Xs)} rows; using {M} inducing points instead of {cfg.n_inducing}")
    t1 = time.perf_counter()
    kernel, allowed, info = mean_only_masks(cfg, input_names, output_names, Xs, Ys, scaler.active, scaler.x_std)
    if info and not any(info["outputs"].values()):
        # no output's mean may carry them: the model is fitted without the columns, exactly as it would be
        # without them (a query with them is refused: the caller checks n_inputs)
        k = len(info["inputs"])
        notes.append(f"gp: {', '.join(info['inputs'])} in no output's linear mean (the gates on the training rows): "
                     "fitted without")
        X, input_names, D = X[:, :-k], input_names[:-k], D - k
        scaler, _ = Standardiser.fit(X, Y, input_names)
        Xs = scaler.x(X)
        kernel = allowed = None
    if info:
        history.validation["mean_only"] = info
    params = learn_global(Xs, Ys, scaler.active, cfg, M, history, groups=output_groups(output_names, cfg),
                          masks=(kernel, allowed))
    history.timings["hyperparameters"] = time.perf_counter() - t1 - history.timings["init"]
    stride = int(history.validation.get("hyper_stride", max(int(cfg.hyper_stride), 1)))
    n_hyper = int(min(cfg.n_train_max, -(-len(Xs) // stride)))   # the rows fit_global sees
    # the rows kept for the local layer and later refreshes: all of them up to store_max, then thinned by region
    rows, Xd, Yd = RowStore.empty(D, P, np.asarray(params.metric_lengthscale()), cfg.store_cell, cfg.store_max,
                                  cfg.seed).add_dropped(Xs, Ys)
    evicted = global_stats(params, Xd, Yd, cfg.batch_size) if len(Xd) else None
    if len(rows) < len(Xs):
        notes.append(f"gp: the local layer keeps {len(rows)} of {len(Xs)} rows (store_max), thinned by region")

    # the local layer's neighbour search (one for the store of all rows and the validation's blocks)
    # needs only the rows and the length-scales: it runs in a thread (SciPy's k-d tree releases the
    # GIL) while the global layer is validated and conditioned
    search = None
    if cfg.local and _validating(cfg, len(rows.X)):
        pool = ThreadPoolExecutor(1, thread_name_prefix="gcs-sysid-neighbours")
        search = pool.submit(shared_search, rows.X, 1.0 / np.asarray(params.metric_lengthscale()),
                             cfg.local_neighbours)
        pool.shutdown(wait=False)                 # the thread ends with its one job
    t2 = time.perf_counter()
    params, stats = validated_global(params, Xs, Ys, cfg, history)
    params = posterior_noise(params, cfg, history)
    if cfg.linear_terms == "validated" and cfg.linear_mean and "latent_scale" in history.validation:
        params = _validated_terms(params, Xs, Ys, scaler.active, history)
    params = _validated_mean_only(params, Xs, Ys, cfg, kernel, history)
    post = global_posterior(params, stats)
    history.timings["posterior"] = time.perf_counter() - t2

    var_scale = None
    if cfg.residual_correlation:
        from .colored import variance_inflation

        R = Ys - global_mean(params, post, Xs, cfg.batch_size)
        var_scale = variance_inflation(R) if np.isfinite(R).all() else np.array(      # missing outputs: own rows
            [variance_inflation(R[np.isfinite(R[:, p]), p][:, None])[0] for p in range(P)])
    input_var = None
    if cfg.input_noise:
        t4 = time.perf_counter()
        input_var = learn_input_noise(params, post, Xs, Ys, scaler.active, cfg)
        history.timings["input_noise"] = time.perf_counter() - t4

    local_params, store = None, None
    if cfg.local:
        t3 = time.perf_counter()
        resid = rows.Y - global_mean(params, post, rows.X, cfg.batch_size)
        search = None if search is None else search.result()
        local_params, store = fit_local(cfg, params, rows.X, resid, history,
                                        None if search is None else store_without(search, rows.X, resid, 0, 0))
        local_params = validated_local(local_params, params, rows.X, resid, cfg, history, search)
        history.timings["local"] = time.perf_counter() - t3
    history.timings["total"] = time.perf_counter() - t0
    notes += [n for n in history.notes if n.startswith(("gp: blocked validation", "gp: likelihood-ratio"))]
    history.notes = list(notes)
    model = LocalGlobalGP(cfg, scaler, params, stats, post, local_params, store, input_names, output_names,
                          n_hyper=n_hyper, notes=tuple(notes), rows=rows, evicted=evicted, input_var=input_var,
                          var_scale=var_scale)
    model = calibrate(model, Xs, Ys, history.validation.get("cv_mse"))    # model error at exact conditions
    return model, history


def _validated_terms(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, active: np.ndarray,
                     history: FitHistory) -> GlobalParams:
    """``GPConfig.linear_terms = "validated"``: for the outputs whose latent GP the blocked validation
    shrank to the smallest scale (:data:`gcs_sysid.gp.validation.GLOBAL_GRID`), where the linear fit's
    residual is noise, the linear mean keeps only the regressors significant with coloured residuals
    (:func:`gcs_sysid.gp.colored.significant_inputs`); the prior std of the others becomes 0. The
    statistics do not depend on it: only the posterior changes."""
    from .colored import significant_inputs
    from .validation import GLOBAL_GRID

    lin = [p for p, v in enumerate(history.validation["latent_scale"]) if v <= GLOBAL_GRID[0]]
    if not lin:
        return params
    P, D = Ys.shape[1], Xs.shape[1]
    S = np.array(np.broadcast_to(np.asarray(params.prior_std, float), (P, D + 1)))
    # each output's elimination runs over the regressors its mean may carry: a mean-only input that is not in
    # an output's mean (prior std 0) is no candidate there (near-collinear with q_hat, it would take q_hat's t)
    may = np.asarray(active, bool)[None, :] & (S[:, 1:] > 0)
    groups: dict[bytes, list[int]] = {}
    for p in lin:
        groups.setdefault(may[p].tobytes(), []).append(p)
    for ps in groups.values():
        keep = significant_inputs(Xs, Ys[:, ps], may[ps[0]])
        for k, p in enumerate(ps):
            S[p, 1:] *= keep[k]
    history.validation["linear_terms"] = [[int(d) for d in np.flatnonzero(S[p, 1:])] for p in range(P)]
    return replace(params, prior_std=jax.device_put(S))


def _validated_mean_only(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, cfg: GPConfig,
                         kernel: np.ndarray | None, history: FitHistory) -> GlobalParams:
    """The mean-only inputs (``kernel`` False) kept in an output's mean only where they lower its blocked
    cross-validation error (:func:`gcs_sysid.gp.validation.gate_mean_only`); unchanged without mean-only inputs
    or when the blocked validation does not run. Recorded in ``history.validation["mean_only"]``."""
    from .validation import gate_mean_only

    if kernel is None or np.all(kernel) or not _validating(cfg, len(Xs)):
        return params
    t0 = time.perf_counter()
    params, keep, ratio = gate_mean_only(params, Xs, Ys, np.flatnonzero(~np.asarray(kernel, bool)),
                                         int(cfg.validation_folds), cfg.batch_size, cfg.n_train_max, cfg.seed)
    history.timings["validation_mean_only"] = time.perf_counter() - t0
    info = history.validation.setdefault("mean_only", {})
    info["blocked_ratio"] = [None if not np.isfinite(r) else float(r) for r in ratio]
    info["blocked_kept"] = [bool(k) for k in keep]
    if not np.all(keep):
        history.notes.append(f"gp: blocked validation took the mean-only inputs out of {int(np.sum(~keep))} "
                             "output(s) (they did not lower the blocked error)")
    return params


def _validating(cfg: GPConfig, n: int) -> bool:
    """Whether the blocked cross-validation runs: at least 2 blocks of at least 20 rows each."""
    return int(cfg.validation_folds) >= 2 and n >= 20 * int(cfg.validation_folds)


def validated_global(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, cfg: GPConfig,
                     history: FitHistory) -> tuple[GlobalParams, object]:
    """The global statistics of ``Xs (N, D)``, ``Ys (N, P)`` (standardised, time order) and the
    parameters with the latent GP's prior scale chosen per output by blocked cross-validation
    (:func:`gcs_sysid.gp.validation.gate_global`; unchanged when ``cfg.validation_folds < 2`` or the
    rows are too few). Appends a note with the scales to ``history.notes`` when one is below 1.

    Returns:
        ``(params, stats)``.
    """
    if not _validating(cfg, len(Xs)):
        return params, global_stats(params, Xs, Ys, cfg.batch_size)
    t0 = time.perf_counter()
    # GPConfig.noise_posterior = "diagonal": the choices made by the posterior mean's blocked error (the latent scales,
    # the coupling gate) see the posterior the model will use, the likelihood-ratio test the learned likelihood
    R_noise = params.noise_chol if cfg.noise_correlation and cfg.noise_posterior == "diagonal" else None
    if R_noise is not None:
        params = replace(params, noise_chol=None)
    params, stats, s, sse = gate_global(params, Xs, Ys, int(cfg.validation_folds), cfg.batch_size, cfg.n_train_max,
                                        cfg.seed)
    history.timings["validation_global"] = time.perf_counter() - t0
    history.validation["latent_scale"] = [float(v) for v in s]
    # the blocked squared error at the chosen scales, per validation row: the model discrepancy's source
    n_val = validation_rows(len(Xs), int(cfg.validation_folds), cfg.n_train_max)
    history.validation["cv_mse"] = (np.min(np.asarray(sse), 0) / max(n_val, 1)).tolist()
    if np.any(s < 1.0):
        history.notes.append("gp: blocked validation shrank the latent GP to " + ", ".join(
            f"{v:g}" for v in s) + " of its learned prior std per output")
    if cfg.gates_coupling and Ys.shape[1] > 1:
        from .joint import gate_coupling

        t0 = time.perf_counter()
        params, info = gate_coupling(params, Xs, Ys, int(cfg.validation_folds), cfg.batch_size)
        _record_coupling(history, "validation_coupling", t0, info, "coupled", "blocked validation",
                         "the coupling did not lower their blocked error")
    if R_noise is not None:
        params = replace(params, noise_chol=R_noise)
    if (cfg.coupling_test == "lr" and cfg.coupling != "off" and Ys.shape[1] > 1
            and cfg.output_groups not in ("kernels", "kernels-free", "output-kernels")):
        params = _tested_coupling(params, stats, Xs, Ys, cfg, history)
    return params, stats


def _tested_coupling(params: GlobalParams, stats, Xs: np.ndarray, Ys: np.ndarray, cfg: GPConfig, history: FitHistory
                     ) -> GlobalParams:
    """``GPConfig.coupling_test = "lr"``: :func:`gcs_sysid.gp.joint.lr_coupling` on the statistics ``stats`` of every
    row, the statistic deflated by the long-run variance ratio of the ridge residual of ``Ys (N, P)`` on
    ``Xs (N, D)`` (time order; the median over outputs of :func:`gcs_sysid.gp.colored.variance_inflation`), the
    degrees of freedom at most the shared factors' rank ``cfg.rank * cfg.latent_kernels``. Records ``lr_coupled``,
    ``lr_stat``, ``lr_share`` in ``history.validation`` and a note when an output is decoupled."""
    from .colored import linear_residual, variance_inflation
    from .joint import lr_coupling

    t0 = time.perf_counter()
    R = linear_residual(Xs, Ys)
    vif = [variance_inflation(R[np.isfinite(R[:, p]), p][:, None])[0] for p in range(R.shape[1])]
    params, info = lr_coupling(params, stats, 1.0 / float(np.median(vif)),
                               df_max=max(1, int(cfg.rank) * int(cfg.latent_kernels)))
    _record_coupling(history, "coupling_test", t0, info, "lr_coupled", "likelihood-ratio test on every row",
                     "the bound did not support their coupling")
    return params


def _record_coupling(history: FitHistory, timing: str, t0: float, info: dict, key: str, who: str, why: str) -> None:
    """Record a coupling stage in ``history``: its time since ``t0`` under ``timing``, ``info``'s ``(P,)`` arrays in
    ``validation`` and, when ``info[key]`` leaves an output uncoupled, the note ``"gp: {who} decoupled the signal of
    n of P outputs from the others ({why})"``."""
    history.timings[timing] = time.perf_counter() - t0
    history.validation.update({k: [v.item() for v in a] for k, a in info.items()})
    if not np.all(info[key]):
        history.notes.append(f"gp: {who} decoupled the signal of {int(np.sum(~info[key]))} of {len(info[key])} outputs "
                             f"from the others ({why})")


def validated_local(local: LocalParams, params: GlobalParams, Xs: np.ndarray, resid: np.ndarray, cfg: GPConfig,
                    history: FitHistory, search=None) -> LocalParams:
    """The local layer switched off per output where it does not predict held-back time blocks of
    the global residual ``resid (N, P)`` at ``Xs (N, D)`` (:func:`gcs_sysid.gp.validation.gate_local`;
    unchanged when ``cfg.validation_folds < 2`` or the rows are too few). ``search``: a
    :func:`gcs_sysid.gp.validation.shared_search` of ``Xs`` to reuse (made there when None)."""
    if not _validating(cfg, len(Xs)):
        return local
    t0 = time.perf_counter()
    metric = 1.0 / np.asarray(params.metric_lengthscale())
    local, keep, ratio = gate_local(local, Xs, resid, metric, cfg.local_neighbours, int(cfg.validation_folds),
                                    cfg.batch_size, cfg.n_train_max, cfg.seed, search)
    history.timings["validation_local"] = time.perf_counter() - t0
    history.validation["local_kept"] = [bool(k) for k in keep]
    history.validation["local_ratio"] = [float(r) for r in ratio]
    if not np.all(keep):
        history.notes.append(f"gp: blocked validation switched the local layer off for {int(np.sum(~keep))} of "
                             f"{len(keep)} outputs")
    return local


def learn_input_noise(params: GlobalParams, post, Xs: np.ndarray, Ys: np.ndarray, active: np.ndarray,
                      cfg: GPConfig) -> np.ndarray:
    """Input-noise variances ``(D,)`` (standardised) on ``n_train_max`` random rows of ``Xs (N, D)``,
    ``Ys (N, P)``: the global layer's residuals, latent variances and slopes there, then
    :func:`gcs_sysid.gp.inputnoise.fit_input_noise` (McHutchon and Rasmussen 2011)."""
    complete = np.flatnonzero(np.isfinite(Ys).all(1))
    if len(complete) < len(Xs):                  # missing outputs: the rows that carry all of them
        Xs, Ys = Xs[complete], Ys[complete]
        if len(Xs) < 2:
            return None
    sub = random_points(len(Xs), cfg.n_train_max, cfg.seed + 11)
    m, v = global_predict(params, post, Xs[sub], cfg.batch_size)
    grad = mean_gradient(params, post, Xs[sub], cfg.batch_size)
    input_var, _ = fit_input_noise(Ys[sub] - m, v, grad, np.asarray(active, bool), np.asarray(params.noise))
    return input_var
