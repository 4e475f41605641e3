"""Noisy inputs: the regressors are estimates (errors in variables), after NIGP.

McHutchon and Rasmussen (2011), "Gaussian process training with input noise", NIPS 24, sec. 2:
with ``x_meas = x + eps_x``, ``eps_x ~ N(0, Sigma_x)`` and a first-order Taylor expansion of the
function about the measured input,

    y_p = f_p(x_meas) - grad f_p(x_meas)^T eps_x + eps_y,p
    var(y_p | x_meas) = sigma_y,p^2 + grad m_p^T Sigma_x grad m_p       (their eq. 4, posterior-mean slope)

so the input noise shows as an output noise that grows where the mean is steep. Here
``Sigma_x = diag(s_x^2)`` (one variance per regressor, standardised units) is learned, as in NIGP,
by maximising the likelihood of the global layer's training residuals under this heteroscedastic
noise, with the global layer's slope and latent variance held fixed (one pass of their
alternating scheme: GP first, then the noise given its slopes; sec. 3 of the paper iterates).
At prediction the slope term is added to the predictive variance of a query whose regressors
are estimates too (``predict(..., input_noise=True)``), not at exact conditions.

Slope of the global mean, closed form for the ARD squared-exponential kernel with the whitened
weights ``alpha = Lm^{-T} w_phi`` (``M x P``) and the linear-mean weights ``W``:

    m_p(x) = k(x, Z) alpha_p + xa(x)^T W_p
    d m_p / d x_d = sum_m k(x, z_m) (z_md - x_d) / l_d^2 alpha_mp + W_{1+d, p}

(a sum of such terms, one per kernel with its own ``alpha_j``, for a linear model of
coregionalisation).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from ..jaxconfig import stored_jit
from jax.scipy.linalg import solve_triangular
from scipy.optimize import minimize

from .kernels import ARDSquaredExponential
from .sparse import GlobalParams, GlobalPosterior

__all__ = ["mean_gradient", "slope_variance", "fit_input_noise"]


@stored_jit
def _gradient_chunk(params: GlobalParams, post: GlobalPosterior, Xs: jax.Array) -> jax.Array:
    M, D = params.Z.shape
    Lms = post.Lm[None] if post.Lm.ndim == 2 else post.Lm                       # (J, M, M)
    g = 0.0
    for j, ls in enumerate(params.lengthscales):                                 # one term per latent kernel
        alpha = solve_triangular(Lms[j].T, post.weights[j * M:(j + 1) * M], lower=False)   # (M, P)
        K = ARDSquaredExponential(ls)(Xs, params.Z)                             # (N, M)
        KA = K @ alpha                                                          # (N, P)
        P = alpha.shape[1]
        ZA = (params.Z[:, :, None] * alpha[:, None, :]).reshape(M, D * P)         # one GEMM for all d, p
        KZA = (K @ ZA).reshape(-1, D, P)                                        # (N, D, P)
        g = g + (KZA - Xs[:, :, None] * KA[:, None, :]) / (ls**2)[None, :, None]
    J = Lms.shape[0]
    return jnp.transpose(g + post.weights[J * M + 1:][None], (0, 2, 1))        # (N, P, D)


def mean_gradient(params: GlobalParams, post: GlobalPosterior, Xs: np.ndarray, batch: int = 2048) -> np.ndarray:
    """Slope ``d m_p / d x_d`` of the global layer's mean, ``(N, P, D)``, standardised units.

    Args:
        params, post: the global layer. Xs: ``(N, D)`` standardised query rows (finite).
        batch: rows per compiled chunk (chunks padded to one shape).

    Source: differentiating ``k(x, Z) alpha`` of the ARD squared exponential (module docstring).
    """
    Xs = np.asarray(Xs, float)
    out = []
    for a in range(0, len(Xs), batch):
        chunk = Xs[a:a + batch]
        n = len(chunk)
        pad = np.zeros((min(batch, max(len(Xs), 1)), Xs.shape[1]))
        pad[:n] = chunk
        out.append(np.asarray(_gradient_chunk(params, post, jax.device_put(pad)))[:n])
    return np.concatenate(out) if out else np.zeros((0, params.A.shape[0], Xs.shape[1]))


def slope_variance(grad: np.ndarray, input_var: np.ndarray) -> np.ndarray:
    """``grad m_p^T diag(input_var) grad m_p`` of shape ``(N, P)`` from ``grad (N, P, D)``, ``input_var (D,)``
    (McHutchon and Rasmussen 2011, eq. 4)."""
    return np.einsum("npd,d->np", grad**2, np.asarray(input_var, float))


def fit_input_noise(resid: np.ndarray, latent_var: np.ndarray, grad: np.ndarray, active: np.ndarray,
                    noise0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Input-noise variances ``s_x^2 (D,)`` and output-noise variances ``(P,)`` by maximum likelihood.

    Maximises ``sum_{n,p} log N(r_np | 0, s_y,p^2 + v_np + sum_d g_npd^2 s_x,d^2)`` (NIGP's
    heteroscedastic likelihood with the slopes ``g`` and latent variances ``v`` of the fitted GP
    held fixed) over ``log s_y^2`` and ``log s_x^2`` by L-BFGS with the analytic gradient.

    Args:
        resid: ``(N, P)`` training residuals of the global mean (standardised).
        latent_var: ``(N, P)`` its latent variance there. grad: ``(N, P, D)`` its slope there.
        active: ``(D,)`` bool, regressors that vary (the others keep ``s_x^2 = 0``).
        noise0: ``(P,)`` starting output-noise variances (the fitted homoscedastic ones).

    Returns:
        ``(input_var (D,), output_var (P,))`` standardised.
    """
    r2 = np.asarray(resid, float) ** 2
    v = np.asarray(latent_var, float)
    g2 = np.asarray(grad, float)[:, :, active] ** 2
    P, Da = r2.shape[1], int(np.sum(active))

    def nll(theta):
        sy, sx = np.exp(theta[:P]), np.exp(theta[P:])
        tot = sy[None] + v + g2 @ sx + 1e-12
        d = 0.5 * (1.0 / tot - r2 / tot**2)                        # d nll / d tot
        f = 0.5 * np.sum(np.log(tot) + r2 / tot)
        return f / r2.size, np.concatenate([d.sum(0) * sy, np.einsum("np,npd->d", d, g2) * sx]) / r2.size

    theta0 = np.concatenate([np.log(np.maximum(noise0, 1e-8)), np.full(Da, np.log(1e-3))])
    res = minimize(nll, theta0, jac=True, method="L-BFGS-B", bounds=[(-18.0, 3.0)] * (P + Da),
                   options={"maxiter": 200})
    input_var = np.zeros(len(active))
    input_var[active] = np.exp(res.x[P:])
    return input_var, np.exp(res.x[:P])
