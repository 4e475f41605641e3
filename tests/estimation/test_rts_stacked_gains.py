"""The single-filter RTS smoother's stacked gain solves give the numbers of one solve per step."""

import numpy as np

from gcs_sysid.estimation.kalman import FilterResult, rts_smoother


def _stepwise(res, F, wrap):
    """The smoother as written before the gains were stacked: one solve per step."""
    T = res.x.shape[0]
    x1, P1, xp1, Pp1 = res.x[:, 0], res.P[:, 0], res.xp[:, 0], res.Pp[:, 0]
    xs, Ps = res.x.copy(), res.P.copy()
    xn, Pn = xs[T - 1, 0], Ps[T - 1, 0]
    for k in range(T - 2, -1, -1):
        Fk1 = F[k + 1] if F.ndim == 3 else F
        Ct = np.linalg.solve(Pp1[k + 1], Fk1 @ P1[k])
        d = xn - xp1[k + 1]
        d[list(wrap)] = np.mod(d[list(wrap)] + np.pi, 2 * np.pi) - np.pi
        xn = x1[k] + Ct.T @ d
        Pn = P1[k] + Ct.T @ (Pn - Pp1[k + 1]) @ Ct
        xs[k, 0], Ps[k, 0] = xn, Pn
    return xs, Ps


def test_stacked_gains_equal_one_solve_per_step():
    rng = np.random.default_rng(5)
    T, n = 400, 6

    def spd(k):
        a = rng.normal(size=(k, n, n))
        return a @ a.transpose(0, 2, 1) + n * np.eye(n)

    res = FilterResult(rng.normal(size=(T, 1, n)), 0.01 * spd(T)[:, None], rng.normal(size=(T, 1, n)),
                       0.02 * spd(T)[:, None], np.zeros(1))
    for F in (np.eye(n) + 0.01 * rng.normal(size=(T, n, n)), np.eye(n) + 0.01 * rng.normal(size=(n, n))):
        xs, Ps = rts_smoother(res, F, wrap=(0, 1, 2))
        xr, Pr = _stepwise(res, F, (0, 1, 2))
        np.testing.assert_allclose(xs, xr, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(Ps, Pr, rtol=1e-12, atol=1e-14)
    one = FilterResult(res.x[:1], res.P[:1], res.xp[:1], res.Pp[:1], np.zeros(1))   # T = 1: nothing to smooth
    xs, Ps = rts_smoother(one, np.eye(n))
    np.testing.assert_array_equal(xs, one.x)
