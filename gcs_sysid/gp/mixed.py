"""Prior knowledge on single linear slopes, by mixed estimation, imposed on the GP's training target.

Mixed estimation (Theil and Goldberger, "On pure and mixed statistical estimation in economics",
International Economic Review 2 (1961) 65-78; in aircraft equation-error terms Morelli and Klein,
*Aircraft System Identification*, ch. 5, a priori information against collinear regressors): the
linear model ``z = X theta + v``, ``Var(v) = c s^2 I``, and stochastic prior information
``theta_k = 0 + u_k``, ``u_k ~ N(0, sigma_k^2)`` on a few of its slopes, estimated together:

    theta_ME = (X'X / (c s^2) + R' S^-1 R)^-1 X'z / (c s^2)

(``R`` picks the slopes with a prior, ``S = diag(sigma_k^2)``; ``s^2`` the least-squares residual
variance, ``c`` the residual's long-run variance ratio, :func:`gcs_sysid.gp.colored.variance_inflation`,
so coloured residuals count as the fewer independent samples they are). ``sigma -> inf`` gives least
squares, ``sigma = 0`` the fit with those slopes fixed at zero (the columns left out: Morelli and Klein's
parameters fixed at a priori values).

Why on the target and not on the GP's linear-mean weights (a cap on one weight's prior std, tried and
not kept): a prior on a mean weight moves only the weight; the GP's kernel, which sees the same input, takes up whatever
slope the weight gives back (a synthetic check: the mean weight of ``r_hat`` 0.02-prior -> -0.003,
the model's slope along ``r_hat`` -1.89 either way, ``docs/gp.md``). Here the target's linear part is
replaced by the mixed estimate's, ``z' = z - X (theta_LS - theta_ME)``: least squares of ``z'`` on
``X`` returns ``theta_ME`` exactly and the residual is least squares' own, so neither the mean nor
the kernel finds the slope the prior refused.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .colored import variance_inflation

__all__ = ["mixed_estimate", "apply_slope_prior", "apply_fixed_slopes"]


def mixed_estimate(X: np.ndarray, z: np.ndarray, prior_std: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least squares and the mixed estimate of ``z ~ theta_0 + X theta`` with zero-mean slope priors.

    Args:
        X: ``(N, D)`` regressors in time order (an intercept is added; columns that do not vary get slope 0).
        z: ``(N,)`` output.
        prior_std: ``(D,)`` prior std of each slope in the data's units (``inf``: no prior; 0: fixed at 0).

    Returns:
        ``(theta_ls, theta_me)``, each ``(D + 1,)``, intercept first.

    Raises:
        InputError: shapes that do not match, a negative or NaN prior std, or non-finite data.
    """
    X = np.asarray(X, float)
    z = np.asarray(z, float)
    sd = np.asarray(prior_std, float)
    if X.ndim != 2 or z.shape != (X.shape[0],) or sd.shape != (X.shape[1],):
        raise InputError(f"mixed_estimate: X (N, D), z (N,), prior_std (D,); got {X.shape}, {z.shape}, {sd.shape}")
    if np.any(np.isnan(sd)) or np.any(sd < 0):
        raise InputError("mixed_estimate: prior std must be >= 0 (inf: none)")
    if not (np.isfinite(X).all() and np.isfinite(z).all()):
        raise InputError("mixed_estimate: non-finite regressors or output")
    N, D = X.shape
    mu, sx = X.mean(0), X.std(0)
    act = sx > 0
    Xs = np.zeros_like(X)
    Xs[:, act] = (X[:, act] - mu[act]) / sx[act]
    A = np.c_[np.ones(N), Xs[:, act]]
    b_ls, *_ = np.linalg.lstsq(A, z, rcond=None)
    v = z - A @ b_ls
    s2 = float(v @ v) / max(N - A.shape[1], 1)
    c = float(variance_inflation(v[:, None])[0])
    free = np.r_[True, sd[act] > 0]                   # sd 0: the slope fixed at 0, its column left out
    Af = A[:, free]
    prec = np.zeros(Af.shape[1])                      # prior precision of the standardised slopes
    sdf = sd[act][free[1:]] * sx[act][free[1:]]
    prec[1:] = np.where(np.isinf(sdf), 0.0, 1.0 / np.where(np.isinf(sdf), 1.0, sdf) ** 2)
    w = 1.0 / max(c * s2, 1e-300)
    b_me = np.zeros(A.shape[1])
    b_me[free] = np.linalg.solve(Af.T @ Af * w + np.diag(prec), Af.T @ z * w)

    def raw(b):                                       # back to the data's units, intercept first
        th = np.zeros(D + 1)
        th[1:][act] = b[1:] / sx[act]
        th[0] = b[0] - th[1:] @ mu
        return th

    return raw(b_ls), raw(b_me)


def apply_slope_prior(X: np.ndarray, Y: np.ndarray, input_names, output_names, prior) -> tuple[np.ndarray, dict]:
    """The GP's training target with the linear part of each output a prior names replaced by the mixed estimate's.

    Args:
        X: ``(N, D)`` training regressors in time order. Y: ``(N, P)`` training outputs (NaN: missing; an output's
            estimate uses its finite rows).
        input_names: ``D`` names. output_names: ``P`` names.
        prior: ``((output, input, std), ...)``, std in the data's units (output per unit input, e.g.
            ``("CY", "r_hat", 0.3)``); names not in this fit are ignored.

    Returns:
        ``(Y', info)``: ``Y' (N, P)`` (a copy; unchanged columns where no prior applies), and per changed output
        ``{output: {"inputs": [...], "ls": {input: slope}, "mixed": {input: slope}}}`` for the prior's inputs.

    Raises:
        InputError: from :func:`mixed_estimate`.
    """
    ins, outs = list(input_names), list(output_names)
    Y2 = np.array(Y, float, copy=True)
    info: dict = {}
    for o in dict.fromkeys(o for o, _, _ in prior):
        if o not in outs:
            continue
        sd = np.full(len(ins), np.inf)
        for o2, i, s in prior:
            if o2 == o and i in ins:
                sd[ins.index(i)] = min(sd[ins.index(i)], float(s))
        if np.isinf(sd).all():
            continue
        p = outs.index(o)
        rows = np.isfinite(Y2[:, p]) & np.isfinite(X).all(1)
        if rows.sum() <= X.shape[1] + 2:
            continue
        th_ls, th_me = mixed_estimate(X[rows], Y2[rows, p], sd)
        Y2[rows, p] -= X[rows] @ (th_ls[1:] - th_me[1:]) + (th_ls[0] - th_me[0])
        named = [ins[d] for d in np.flatnonzero(np.isfinite(sd))]
        info[o] = {"inputs": named, "ls": {k: float(th_ls[1 + ins.index(k)]) for k in named},
                   "mixed": {k: float(th_me[1 + ins.index(k)]) for k in named}}
    return Y2, info


def apply_fixed_slopes(X: np.ndarray, Y: np.ndarray, input_names, output_names, fixed) -> tuple[np.ndarray, dict]:
    """The GP's training target with some slopes of an output fixed at known values (a prior of zero variance
    at a non-zero value: Morelli and Klein, *Aircraft System Identification*, 2nd ed., ch. 5, parameters fixed at
    a priori values; Theil and Goldberger 1961 in the limit).

    Per output ``o`` with fixed slopes ``theta_F`` on the inputs ``F``: the other slopes and the intercept are
    least squares of ``y - X_F theta_F`` on the other inputs, ``theta_R``; the target becomes
    ``y' = y - X (theta_LS - theta)`` with ``theta = (theta_F, theta_R)``, so least squares of ``y'`` on all of
    ``X`` returns ``theta`` exactly and the residual is least squares' own (as :func:`apply_slope_prior`: neither
    the GP's mean nor its kernel finds a slope the residual does not carry).

    Args:
        X: ``(N, D)`` training regressors. Y: ``(N, P)`` training outputs (NaN: missing; an output's fit uses its
            finite rows).
        input_names: ``D`` names. output_names: ``P`` names.
        fixed: ``{output: {input: slope}}`` in the data's units; outputs or inputs not in this fit are ignored.

    Returns:
        ``(Y', info)``: ``Y' (N, P)`` (a copy), and per changed output ``{output: {"inputs": [...],
        "ls": {input: slope}, "fixed": {input: slope}}}``.

    Raises:
        InputError: a fixed slope that is not finite.
    """
    ins, outs = list(input_names), list(output_names)
    Y2 = np.array(Y, float, copy=True)
    X = np.asarray(X, float)
    info: dict = {}
    for o, slopes in fixed.items():
        use = {i: float(v) for i, v in slopes.items() if i in ins}
        if o not in outs or not use:
            continue
        if not all(np.isfinite(v) for v in use.values()):
            raise InputError(f"apply_fixed_slopes: {o}: fixed slopes must be finite, got {use}")
        p = outs.index(o)
        rows = np.isfinite(Y2[:, p]) & np.isfinite(X).all(1)
        if rows.sum() <= X.shape[1] + 2:
            continue
        F = [ins.index(i) for i in use]
        rest = [j for j in range(X.shape[1]) if j not in F]
        A = np.c_[np.ones(int(rows.sum())), X[rows]]
        th_ls = np.linalg.lstsq(A, Y2[rows, p], rcond=None)[0]
        z = Y2[rows, p] - X[rows][:, F] @ np.array(list(use.values()))
        b = np.linalg.lstsq(np.c_[np.ones(int(rows.sum())), X[rows][:, rest]], z, rcond=None)[0]
        th = np.zeros(X.shape[1] + 1)
        th[0], th[1 + np.array(rest, int)], th[1 + np.array(F)] = b[0], b[1:], list(use.values())
        Y2[rows, p] -= A @ (th_ls - th)
        info[o] = {"inputs": list(use), "ls": {i: float(th_ls[1 + ins.index(i)]) for i in use}, "fixed": use}
    return Y2, info
