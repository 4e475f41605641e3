"""Expected global-layer variance after hypothetical observations, for many candidates at once.

Ranking maneuvers needs, for each of tens of candidate trajectories ``X_e (E, D)``, the
predictive variance at some query points if noisy observations were made along ``X_e``
(the variance does not depend on the values observed; Rasmussen and Williams 2006, eq. 2.26).
:meth:`LocalGlobalGP.variance_after` answers it exactly for both layers by rebuilding the
model (``O((P M)^3)`` plus a k-d tree over all rows per candidate); here the global layer is
updated for all candidates in closed form, without refactoring ``Lambda``.

In the feature space of :mod:`gcs_sysid.gp.sparse` the extra rows add
``Psi Psi^T`` to the posterior precision, ``Psi`` of shape ``(K, P E)`` with columns
``psi_p(x_e) / sigma_p = S_p u_e / sigma_p``. By the Woodbury identity

    S_p^T (Lambda + Psi Psi^T)^{-1} S_p = H_pp - T_p^T (I + Psi^T Lambda^{-1} Psi)^{-1} T_p,
    T_p = Psi^T Lambda^{-1} S_p,

and both ``T_p`` and ``Psi^T Lambda^{-1} Psi`` are products of the candidate's features
``u_e = [phi(x_e); xa(x_e)]`` with the cross-covariances ``H_pq = S_p^T Lambda^{-1} S_q``
``(J, J)``, ``J = K M + D + 1`` for ``K`` latent kernels (1 for the ICM; a linear model of
coregionalisation stacks each kernel's features), computed once per model. A candidate then costs
``O(P^2 E J^2 + (P E)^2 P J + (P E)^3)`` instead of ``O((P M)^3)``: the query variance is
``var_p(x) - |R_p u(x)|^2`` with ``R_p = chol(C)^{-1} T_p``. The rows enter only through
``U_e U_e^T``, so ``U_e`` is first replaced by its thin SVD's leading columns ``U_r diag(s_r)``
(``r <= min(E, J)``; directions that move no variance by more than machine epsilon left out:
:func:`_compressed`), and ``E`` above is ``r``.

The result equals ``model.update(X_e, any Y, exchange=False).predict_global(X_query)`` (a test).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from scipy.linalg import blas, cho_factor, solve_triangular

__all__ = ["cross_covariances", "global_variance_after_many"]


def _features(model, Xs: np.ndarray) -> np.ndarray:
    """``u = [phi_1(x); ..; phi_K(x); xa(x)]`` of shape ``(J, N)`` at standardised ``Xs (N, D)`` (numpy):
    the whitened features of each of the ``K`` latent kernels (one for the ICM), then the design."""
    p = model.params
    Lm = np.asarray(model.post.Lm)
    phis = []
    for Lj, ls in zip(Lm[None] if Lm.ndim == 2 else Lm, np.asarray(p.lengthscales)):
        Z = np.asarray(p.Z) / ls
        A = Xs / ls
        d2 = np.sum(Z * Z, 1)[:, None] + np.sum(A * A, 1)[None, :] - 2.0 * Z @ A.T
        Kzx = np.exp(-0.5 * np.maximum(d2, 0.0))
        phis.append(solve_triangular(Lj, Kzx, lower=True, check_finite=False))
    return np.vstack(phis + [np.ones((1, len(Xs))), Xs.T])


def _selector_block(model, p: int) -> np.ndarray:
    """``S_p (K, J)`` of :func:`gcs_sysid.gp.sparse._selectors` (``psi_p(x) = S_p u(x)``), in NumPy
    (no per-operation compilation): ``A_k[p, r] I_M`` in row block ``(k, r)`` of the inducing part and
    column block ``k`` (kernel ``k``'s features; the ICM has one kernel and ``A`` square), and
    ``diag(prior std of output p's weights)`` in output ``p``'s rows of the linear-mean part."""
    F = np.asarray(model.params.factors)                  # (K, P, R)
    Kk, P, R = F.shape
    M, D1 = int(model.params.Z.shape[0]), int(model.params.Z.shape[1]) + 1
    S = np.zeros((Kk * R * M + P * D1, Kk * M + D1))
    eyeM = np.eye(M)
    for k in range(Kk):
        for q in range(R):
            row = (k * R + q) * M
            S[row:row + M, k * M:(k + 1) * M] = F[k, p, q] * eyeM
    r0 = Kk * R * M + p * D1
    S[r0:r0 + D1, Kk * M:] = np.diag(np.broadcast_to(np.asarray(model.params.prior_std, float), (P, D1))[p])
    return S


def _selectors(model) -> np.ndarray:
    """``S_all (K, P J)``: column block ``p`` is ``S_p`` (:func:`_selector_block`)."""
    return np.hstack([_selector_block(model, p) for p in range(int(model.params.A.shape[0]))])


def _whitened_selectors(model) -> np.ndarray:
    """``V = L^{-1} S_all (K, P J)`` with ``L`` the Cholesky factor of ``Lambda``.

    Solved one output's column block ``S_p (K, J)`` at a time, so ``S_all`` (and a Fortran-ordered
    copy of it) is never held beside ``V``: the same triangular solves, column block by block.
    """
    L = np.asarray(model.post.L)
    P = int(model.params.A.shape[0])
    J = model.params.n_kernels * int(model.params.Z.shape[0]) + int(model.params.Z.shape[1]) + 1
    V = np.empty((L.shape[0], P * J))
    for p in range(P):
        V[:, p * J:(p + 1) * J] = solve_triangular(L, _selector_block(model, p), lower=True, check_finite=False)
    return V


def _compressed(Ue: np.ndarray, drop: float) -> np.ndarray:
    """The candidate's features ``Ue (J, E)`` as ``U_r diag(s_r) (J, r)``, ``r <= E``: the thin SVD's
    leading columns, the trailing ones whose squared singular values sum to ``drop`` or less left out.

    The update depends on the candidate only through the added precision ``Sigma^{-1} kron U_e U_e^T``
    of the predictive weights (the rows' noise is independent across rows): right-multiplying ``U_e``
    by an orthogonal ``(E, E)`` matrix changes nothing (the Woodbury form's ``C`` turns by it, ``T``'s
    rows too), so ``U_e V = U diag(s)`` gives the same numbers with columns ordered by size. A left-out
    part adds precision of norm ``delta <= sum s_i^2 / lambda_min(Sigma)``, and added precision of
    norm ``delta`` lowers any variance of the weights by at most ``delta lambda_max(H)`` of itself
    (``H`` the posterior covariance, ``lambda_max(H) <= trace(H)``); with ``drop = eps
    lambda_min(Sigma) / trace(H)`` no variance moves by more than ``eps`` relative. On the 10-minute
    benchmark flight a maneuver's 64 rows keep 14-59 directions (mean 38): smooth trajectories have
    few independent features. Source: Golub and Van Loan (2013), sec. 2.4 (SVD, low-rank
    approximation); Rasmussen and Williams (2006), eq. A.9 (Woodbury).
    """
    U, s, _ = np.linalg.svd(Ue, full_matrices=False)      # min(J, E) columns: more rows than J is exact
    tail = np.cumsum((s * s)[::-1])[::-1]                  # tail[i] = sum_{j >= i} s_j^2
    r = max(int(np.count_nonzero(tail > drop)), 1)
    return U[:, :r] * s[None, :r]


def cross_covariances(model) -> np.ndarray:
    """``Hc (P J, P J)`` with blocks ``H_pq = S_p^T Lambda^{-1} S_q`` (posterior covariance of the
    per-output predictive weights across outputs); the diagonal blocks are ``post.H``."""
    V = _whitened_selectors(model)
    return V.T @ V


def global_variance_after_many(model, X_extras: Sequence[np.ndarray], X_queries: Sequence[np.ndarray],
                               Hc: np.ndarray | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Latent global-layer variance at each query set before and after observing each candidate.

    Args:
        model: a fitted :class:`~gcs_sysid.gp.LocalGlobalGP`.
        X_extras: ``C`` arrays ``(E_c, D)`` of standardised candidate rows (finite).
        X_queries: ``C`` arrays ``(Q_c, D)`` of standardised query rows (finite).
        Hc: :func:`cross_covariances` of the model (computed when None).

    Returns:
        ``C`` pairs ``(var_before (Q_c, P), var_after (Q_c, P))`` in standardised units, noise
        not included.

    Source: Woodbury identity (Rasmussen and Williams 2006, eq. A.9) applied to the VFE
    posterior of Titsias (2009) in the feature space; module docstring.
    """
    if len(X_extras) != len(X_queries):
        raise ValueError("global_variance_after_many: one query set per candidate")
    Hc = cross_covariances(model) if Hc is None else Hc
    P = int(model.params.noise.shape[0])
    J = Hc.shape[0] // P
    Ls = np.linalg.cholesky(np.asarray(model.params.noise_cov()))
    Wn = solve_triangular(Ls, np.eye(len(Ls)), lower=True)            # (P, P) whitening Ls^{-1}, lower
    Bd = np.sum(np.asarray(model.params.factors) ** 2, 2)              # (K, P): B_k,pp per latent kernel
    bdiag = np.sum(Bd, 0)
    M = int(model.params.Z.shape[0])
    # the candidate's rows enter only through U_e U_e^T: directions of U_e below this much squared
    # length change no variance by more than machine epsilon, relative (_compressed)
    drop = np.finfo(float).eps * float(np.linalg.eigvalsh(np.asarray(model.params.noise_cov())).min()) \
        / max(float(np.trace(Hc)), np.finfo(float).tiny)
    out = []
    V = None
    cache: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for Xe, Xq in zip(X_extras, X_queries):
        key = id(Xq)
        if key not in cache:                                   # query sets are often shared
            Uq = _features(model, np.asarray(Xq, float))       # (J, Q)
            before = np.empty((Uq.shape[1], P))
            for p in range(P):
                Hp = Hc[p * J:(p + 1) * J, p * J:(p + 1) * J]
                before[:, p] = np.einsum("iq,iq->q", Uq, Hp @ Uq)
            rest = sum(Bd[k][None, :] * np.maximum(1.0 - np.sum(Uq[k * M:(k + 1) * M] ** 2, 0), 0.0)[:, None]
                       for k in range(len(Bd)))
            cache[key] = (Uq, np.maximum(rest + before, 1e-12 * bdiag[None, :]))
        Uq, v0 = cache[key]
        Xe = np.asarray(Xe, float)
        if len(Xe) == 0:
            out.append((v0, v0.copy()))
            continue
        Ue = _compressed(_features(model, Xe), drop)          # (J, E), E <= the candidate's rows
        E = Ue.shape[1]
        # whitened candidate features: output q of a row is sum_p Wn_qp psi_p (Wn = chol(Sigma)^{-1},
        # diag(1/sigma) for independent noise). T = Psi^T Lambda^{-1} S (P E, P J): block row q is
        # sum_p Wn_qp Ue^T H_{p,:}
        T0 = [Ue.T @ Hc[p * J:(p + 1) * J] for p in range(P)]
        T = np.vstack([sum(Wn[q, p] * T0[p] for p in range(P) if Wn[q, p] != 0.0) for q in range(P)])
        # C = I + T Psi-features: column block q2 is sum_p Wn_q2p T_p Ue; each T_p Ue (P E, E) once
        TU = [T[:, p * J:(p + 1) * J] @ Ue for p in range(P)]
        Cm = np.eye(P * E)
        for q2 in range(P):
            for p in range(P):
                if Wn[q2, p] != 0.0:
                    Cm[:, q2 * E:(q2 + 1) * E] += Wn[q2, p] * TU[p]
        del T0, TU
        try:
            Lc = cho_factor(0.5 * (Cm + Cm.T), lower=True, check_finite=False)[0]
            # R = Lc^{-1} T (P E, P J), solved from the right on T^T (Fortran order as it stands:
            # no copy; about 1.5x faster than a left solve on a C-ordered T here)
            R = blas.dtrsm(1.0, Lc, T.T, side=1, lower=1, trans_a=1).T
            if not np.all(np.isfinite(R)):
                raise np.linalg.LinAlgError("non-finite Woodbury factor")
        except np.linalg.LinAlgError:
            # Huge features (candidate far outside the data in standardised units, or tiny noise)
            # make C = I + W^T W lose its identity part to rounding. Square-root form instead:
            # W = L^{-1} Psi = U_w diag(s) V_w^T (thin SVD), so T^T C^{-1} T = R^T R with
            # R = diag(s / sqrt(1 + s^2)) U_w^T L^{-1} S, no large numbers cancel (Golub and Van Loan
            # 2013, sec. 6.1: least squares and the normal equations).
            if V is None:
                V = _whitened_selectors(model)
            VU = [V[:, p * J:(p + 1) * J] @ Ue for p in range(P)]
            W = np.hstack([sum(Wn[q, p] * VU[p] for p in range(P) if Wn[q, p] != 0.0)
                           for q in range(P)])                                               # (K, P E)
            Uw, sv, _ = np.linalg.svd(W, full_matrices=False)
            R = (sv / np.sqrt(1.0 + sv**2))[:, None] * (Uw.T @ V)
        red = np.empty_like(v0)
        for p in range(P):   # |R_p u|^2 = u^T (R_p^T R_p) u: a (J, J) form, cheaper than R_p Uq for Q > J
            Rp = R[:, p * J:(p + 1) * J]
            red[:, p] = np.einsum("jq,jq->q", Uq, (Rp.T @ Rp) @ Uq)
        out.append((v0, np.maximum(v0 - red, 1e-12 * bdiag[None, :])))
    return out
