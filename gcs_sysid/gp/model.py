"""The fitted local + global GP: prediction, incremental update, expected variance, summary."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import jax
import numpy as np
from scipy.linalg import block_diag, cho_solve

from ..errors import InputError
from ..jaxconfig import enable_x64, stored_jit
from .batching import global_mean, global_posterior, global_predict, global_stats, local_predict
from .config import GPConfig
from .local import LocalParams, LocalStore, build_store
from .rowstore import RowStore
from .scaling import Standardiser, check_inputs, check_training
from .sparse import GlobalParams, GlobalPosterior, Stats, add_stats, elbo
from .streaming import chol_kmm, exchange_inducing, project_stats, projection

__all__ = ["LocalGlobalGP"]

_elbo_jit = stored_jit(elbo)
_add_jit = stored_jit(add_stats)


def _projection_all(old: GlobalParams, Z_new: np.ndarray, lengthscales_new: np.ndarray) -> np.ndarray:
    """Streaming projection ``R`` of the stacked features of every latent kernel: block-diagonal,
    one :func:`gcs_sysid.gp.streaming.projection` per kernel (each kernel's features move to the new
    inducing inputs under its own new length-scales), ``(J M_old, J M_new)``."""
    Z_old, jitter = np.asarray(old.Z), float(old.jitter)
    blocks = [projection(chol_kmm(Z_old, ls_old, jitter), Z_old, Z_new, ls_new, jitter)
              for ls_old, ls_new in zip(np.asarray(old.lengthscales), np.asarray(lengthscales_new))]
    return blocks[0] if len(blocks) == 1 else block_diag(*blocks)


@dataclass(frozen=True)
class LocalGlobalGP:
    """Local + global approximated dependent multi-output GP (immutable; methods return new models).

    Prediction ``y_p(x) = m_global,p(x) + m_local,p(x)`` with variance
    ``var_global,p + var_local,p (+ noise_p)``: the global layer is the sparse ICM GP with a
    linear mean (:mod:`gcs_sysid.gp.sparse`), the local layer the nearest-neighbour
    non-stationary GP on its residual (:mod:`gcs_sysid.gp.local`). All arrays are in
    standardised units inside; the methods take and return data units.

    Bounded for streaming (``docs/gp.md``, "Streaming"): the global layer keeps only its
    statistics (``O(M^2)``), the local layer's rows live in a region-thinned store of at most
    ``config.store_max`` rows (``rows``), and :meth:`update` may exchange inducing points.
    The posterior and the local layer's k-d tree are derived data, computed when first needed
    after an update (``post``, ``store``), so an update costs ``O(E M^2)`` and the
    ``O((P M)^3)`` refactorisation is paid once per prediction, not once per update.

    Attributes:
        config: the settings it was fitted with.
        scaler: input/output standardisation.
        params: global hyperparameters. stats: sufficient statistics of the data seen.
        post: global posterior (derived from ``params`` and ``stats``; property).
        local_params, store: the local layer (None when ``config.local`` is False; ``store``
            is derived from ``rows``, a property).
        input_names, output_names: column names.
        n_hyper: rows used for hyperparameter learning.
        notes: one-line remarks made while fitting.
        rows: the capped, region-thinned training rows (:class:`gcs_sysid.gp.rowstore.RowStore`).
        since_refresh: rows conditioned on since the hyperparameters were last learned.
        input_var: ``(D,)`` input-noise variances of the regressors (standardised; NIGP,
            :mod:`gcs_sysid.gp.inputnoise`), None when not learned.
        var_scale: ``(P,)`` factors on the global layer's explained variance for coloured residuals
            (:mod:`gcs_sysid.gp.colored`; from the fit's time-ordered rows, kept through updates and
            refreshes), None when not learned (``GPConfig.residual_correlation``).
        offset_cov: ``(D, D)`` covariance of the training regressors' flight-common offset
            (standardised; :mod:`gcs_sysid.gp.discrepancy`), None when not known.
        scale_var: ``(D,)`` variance of the training regressors' relative scale error common to the flight
            (dimensionless; :mod:`gcs_sysid.gp.discrepancy`), None when not known.
        map_cov: ``(D, D, D)`` second moment of the training regressors' flight-common linear error, ``[j]`` for
            regressor ``j`` along all regressors (standardised; :mod:`gcs_sysid.gp.discrepancy`; in place of
            ``scale_var_j`` where ``[j]`` is not zero), None when not known.
        discrepancy: ``(2, P)``: the model discrepancy ``d`` and the white noise ``w`` per output from
            the blocked cross-validation (standardised; :mod:`gcs_sysid.gp.discrepancy`), None when the
            check did not run.
        evicted: the part of ``stats`` from rows no longer stored (None: none). When the
            inducing inputs or length-scales change, the stored rows' statistics are computed
            again exactly and only this part is carried by the streaming projection.
    """

    config: GPConfig
    scaler: Standardiser
    params: GlobalParams
    stats: Stats
    _post: GlobalPosterior | None
    local_params: LocalParams | None
    _store: LocalStore | None
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    n_hyper: int = 0
    notes: tuple[str, ...] = field(default_factory=tuple)
    rows: RowStore | None = None
    since_refresh: int = 0
    evicted: Stats | None = None
    input_var: np.ndarray | None = None
    var_scale: np.ndarray | None = None
    offset_cov: np.ndarray | None = None
    discrepancy: np.ndarray | None = None
    scale_var: np.ndarray | None = None
    map_cov: np.ndarray | None = None

    # ------------------------------------------------------------ derived
    @property
    def post(self) -> GlobalPosterior:
        """Global posterior from ``params`` and ``stats`` (computed on first use and kept)."""
        if self._post is None:
            object.__setattr__(self, "_post", global_posterior(self.params, self.stats))
        return self._post

    @property
    def store(self) -> LocalStore | None:
        """The local layer's indexed rows with residuals of the global mean (computed on first use)."""
        if self._store is None and self.local_params is not None and self.rows is not None and len(self.rows):
            resid = self.rows.Y - self._global_mean_s(self.rows.X)
            metric = 1.0 / np.asarray(self.params.metric_lengthscale())
            object.__setattr__(self, "_store", build_store(self.rows.X, resid, metric, self.config.local_neighbours))
        return self._store

    # ---------------------------------------------------------------- shapes
    @property
    def n_inputs(self) -> int:
        """Number of regressors ``D``."""
        return int(self.scaler.x_mean.shape[0])

    @property
    def n_mean_only(self) -> int:
        """Trailing inputs that enter only the linear mean (``GPConfig.mean_only_inputs``), which a query may
        leave out."""
        return sum(1 for n in self.input_names if n in self.config.mean_only_inputs)

    def full_inputs(self, X, what: str = "X", fill: float = 0.0) -> np.ndarray:
        """``X`` with the trailing mean-only inputs appended as ``fill`` (0: in data units, the pipeline's
        ``alpha_dot_hat`` of steady flight) when a query leaves them out: ``(N, D - n_mean_only)`` ->
        ``(N, D)``; an ``(N, D)`` array is returned checked and unchanged.

        Raises:
            InputError: ``X`` has neither ``D`` nor ``D - n_mean_only`` columns.
        """
        k = self.n_mean_only
        if k:
            X = check_inputs(X, None, what)
            if X.shape[1] == self.n_inputs - k:
                return np.concatenate([X, np.full((len(X), k), fill)], axis=1)
        return check_inputs(X, self.n_inputs, what)

    @property
    def n_outputs(self) -> int:
        """Number of outputs ``P``."""
        return int(self.scaler.y_mean.shape[0])

    @property
    def n_used(self) -> int:
        """Rows the posterior is conditioned on."""
        return int(round(self.stats.rows()))

    # ------------------------------------------------------------ prediction
    def _standardise_query(self, X) -> tuple[np.ndarray, np.ndarray]:
        X = self.full_inputs(X)
        ok = np.isfinite(X).all(1)
        return self.scaler.x(X[ok]), ok

    def _finish(self, ok, mean_s, var_s):
        mean = np.full((len(ok), self.n_outputs), np.nan)
        var = np.full_like(mean, np.nan)
        mean[ok], var[ok] = self.scaler.y_back(mean_s, var_s)
        return mean, var

    def predict(self, X, include_noise: bool = True, input_noise: bool = True,
                model_error: bool | None = None, x_var=None,
                white_noise: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Predictive mean and variance of the coefficients.

        Args:
            X: ``(N, D)`` regressors in data units (rows with NaN give NaN outputs).
            include_noise: add the observation noise: per output the larger of the global
                layer's likelihood noise and the local layer's nugget.
            input_noise: the regressors are estimates (a flight's table): add the variance that
                their errors carry through the mean's slope, ``grad m^T Sigma_x grad m``
                (McHutchon and Rasmussen 2011, eq. 4; when ``input_var`` was learned). False for
                exact conditions (a user's flight condition, the truth's regressors).
            model_error: add the model's own error at exact conditions, the model discrepancy and
                the training regressors' common offset carried through the slope
                (:mod:`gcs_sysid.gp.discrepancy`; Kennedy and O'Hagan 2001); with ``include_noise``
                the noise is then ``max(noise, d + w)``, not a sum. None: ``not input_noise`` (exact
                conditions). False: the latent variance alone (what more data can reduce).
            x_var: ``(N, D)`` per-row variances of the regressors' errors that the estimator states
                (data units squared; NaN: none stated; ``CoefficientTable.x_var``), or None. With
                ``input_noise`` the slope term then uses, per row and regressor, the larger of this and
                the learned ``input_var``: the learned one sees only the input errors that show in the
                residuals, and an air angle built from the measured coefficient itself (the
                specific-force aiding) carries errors that move the coefficient with it and do not
                (``docs/gp.md``, "Noisy inputs: the estimator's stated variance").
            white_noise: with ``include_noise``, keep the white part of the observation noise. False: leave
                out the white measurement noise ``w_p`` (the lag-1 semivariogram of the time-ordered training
                residuals, :mod:`gcs_sysid.gp.discrepancy`), which a new *measurement* carries and the
                coefficient itself does not, and keep the coloured rest of the noise (what the regressors
                do not explain and the coefficient does carry: gust rates, unsteady terms): the band for the
                coefficient, noise floored at 0 (at exact conditions at ``d``). Rasmussen and Williams
                (2006), eqs. 2.22-2.26: the latent ``f*`` against the noisy ``y* = f* + eps``, with only the
                white ``eps`` as measurement noise. Without a known ``w`` (no blocked validation) the whole
                noise is kept (conservative). ``docs/gp.md``, "Two bands: the coefficient and a new
                measurement".

        Returns:
            ``(mean (N, P), var (N, P))`` in the outputs' units (variance in units squared).

        Raises:
            InputError: ``X`` is not ``(N, D)``, or ``x_var`` is not ``X``'s shape.
        """
        enable_x64()
        Xs, ok = self._standardise_query(X)
        xv_s = self._x_var_s(x_var, ok) if input_noise else None
        mean, var = global_predict(self.params, self.post, Xs, self.config.batch_size, self.var_scale)
        noise = self._noise_s()
        if self.local_params is not None and self.store is not None:
            ml, vl = local_predict(self.local_params, self.store, Xs, self.config.batch_size)
            mean, var = mean + ml, var + vl
        white = None if white_noise or not include_noise else self.white_noise_var()
        if (not input_noise) if model_error is None else model_error:
            from .discrepancy import exact_condition_variance

            var = var + exact_condition_variance(self, Xs, noise if include_noise else None,
                                                 white_noise=white is None)
        elif include_noise:
            var = var + (noise if white is None else np.maximum(noise - white, 0.0))[None, :]
        if input_noise and (self.input_var is not None or xv_s is not None) and len(Xs):
            var = var + self.input_variance_s(Xs, xv_s)
        return self._finish(ok, mean, var)

    def predict_parts(self, X, x_var=None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`predict` at a flight's own regressors (``predict(X, x_var=x_var)``: noise and input noise on) and two
        of its terms, from one pass over the layers and one gradient.

        Args:
            X: ``(N, D)`` regressors in data units (rows with NaN give NaN outputs).
            x_var: as :meth:`predict`'s.

        Returns:
            ``(mean, var, latent, learned_input)``, each ``(N, P)`` in the outputs' units (squared for the
            variances): ``mean`` and ``var`` equal to :meth:`predict`'s to the last bit; ``latent`` the latent variance
            (``predict(X, include_noise=False, input_noise=False, model_error=False)``); ``learned_input`` NIGP's
            learned input noise through the slope alone (McHutchon and Rasmussen 2011, eq. 4; zeros when none was
            learned), without the stated ``x_var``. :func:`gcs_sysid.gp.coefband.stated_band_variance` reads the last
            two.

        Raises:
            InputError: as :meth:`predict`.
        """
        from .inputnoise import mean_gradient, slope_variance

        enable_x64()
        Xs, ok = self._standardise_query(X)
        xv_s = self._x_var_s(x_var, ok)
        mean, var = global_predict(self.params, self.post, Xs, self.config.batch_size, self.var_scale)
        if self.local_params is not None and self.store is not None:
            ml, vl = local_predict(self.local_params, self.store, Xs, self.config.batch_size)
            mean, var = mean + ml, var + vl
        lat = var
        var = var + self._noise_s()[None, :]
        learned = np.zeros(np.shape(lat))
        if (self.input_var is not None or xv_s is not None) and len(Xs):
            grad = mean_gradient(self.params, self.post, Xs, self.config.batch_size)
            learned = slope_variance(grad, self._learned_input_var())
            var = var + (learned if xv_s is None else self._stated_slope_variance(grad, xv_s))
        mean_o, var_o = self._finish(ok, mean, var)
        _, lat_o = self._finish(ok, mean, lat)
        _, learned_o = self._finish(ok, mean, learned)
        return mean_o, var_o, lat_o, learned_o

    def _x_var_s(self, x_var, ok) -> np.ndarray | None:
        """The stated per-row input variances of :meth:`predict` (``x_var``, data units, ``(N, D)`` or without the
        mean-only inputs) standardised for the rows ``ok``; None when none is given.

        Raises:
            InputError: ``x_var`` is not ``X``'s shape.
        """
        if x_var is None:
            return None
        xv = np.asarray(x_var, float)
        if self.n_mean_only and xv.ndim == 2 and xv.shape[1] == self.n_inputs - self.n_mean_only:
            xv = self.full_inputs(xv, "x_var", np.nan)      # none stated for the mean-only inputs
        if xv.shape != (len(ok), self.n_inputs):
            raise InputError(f"x_var: expected shape ({len(ok)}, {self.n_inputs}) like X, got {xv.shape}")
        return np.where(self.scaler.active, xv[ok] / self.scaler.x_std**2, np.nan)

    def _learned_input_var(self) -> np.ndarray:
        """``(D,)`` NIGP's learned input variances (standardised), zeros when none was learned."""
        return np.zeros(self.n_inputs) if self.input_var is None else np.asarray(self.input_var, float)

    def _stated_slope_variance(self, grad: np.ndarray, x_var_s: np.ndarray) -> np.ndarray:
        """``(N, P)`` the slope term with, per row and input, the larger of the learned and the stated variance
        (``x_var_s`` standardised; NaN: the learned one). McHutchon and Rasmussen (2011), eq. 4."""
        return np.einsum("npd,nd->np", grad**2, np.fmax(self._learned_input_var()[None, :], np.asarray(x_var_s, float)))

    def _noise_s(self) -> np.ndarray:
        """``(P,)`` observation-noise variance (standardised): the larger of the global likelihood's and the
        local nugget. The local nugget, learned from nearest-neighbour differences of 50 Hz rows that share a
        gust's error, sees only the white part of the noise; the global layer's likelihood noise also holds
        the coloured part (docs/gp.md, "Noise"; measured on JSBSim flights, docs/benchmarks.md)."""
        noise = np.asarray(self.params.noise)
        if self.local_params is not None and self.store is not None:
            noise = np.maximum(noise, np.asarray(self.local_params.noise))
        return noise

    def noise_var(self, white_noise: bool = True) -> np.ndarray:
        """``(P,)`` the observation-noise variance that :meth:`predict` adds at a flight's own regressors
        (``include_noise=True, input_noise=True``), in the outputs' units squared: ``max(sigma_p^2, tau_p^2)``,
        or with ``white_noise=False`` that less the white part ``w_p``, floored at 0 (:meth:`white_noise_var`;
        the whole noise when ``w`` is not known). The two bands' variances at a flight's regressors differ by
        exactly ``noise_var(True) - noise_var(False)`` (``docs/gp.md``, "Two bands")."""
        noise = self._noise_s()
        w = None if white_noise else self.white_noise_var()
        if w is not None:
            noise = np.maximum(noise - w, 0.0)
        return noise * self.scaler.y_std**2

    def white_noise_var(self) -> np.ndarray | None:
        """``(P,)`` the white measurement-noise variance ``w`` of the outputs (standardised units): the lag-1
        semivariogram of the time-ordered training residuals that the blocked validation stored
        (:func:`gcs_sysid.gp.discrepancy.white_noise_variance`; Cressie 1993 sec. 2.4); None when not known."""
        if self.discrepancy is None:
            return None
        return np.asarray(self.discrepancy, float)[1]

    def input_variance_s(self, Xs: np.ndarray, x_var_s: np.ndarray | None = None) -> np.ndarray:
        """``grad m_p^T Sigma_x grad m_p`` ``(N, P)`` at standardised ``Xs (N, D)`` (standardised units;
        zeros when no input noise was learned or stated). ``x_var_s``: ``(N, D)`` stated per-row input
        variances (standardised; NaN: none), taken where larger than the learned ``input_var``.
        Source: McHutchon and Rasmussen (2011), eq. 4."""
        from .inputnoise import mean_gradient, slope_variance

        if self.input_var is None and x_var_s is None:
            return np.zeros((len(Xs), self.n_outputs))
        grad = mean_gradient(self.params, self.post, Xs, self.config.batch_size)
        if x_var_s is None:
            return slope_variance(grad, self._learned_input_var())
        return self._stated_slope_variance(grad, x_var_s)      # NaN (not stated): the learned one

    def predict_global(self, X, include_noise: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance ``(N, P)`` of the global layer alone (linear mean + sparse ICM GP)."""
        enable_x64()
        Xs, ok = self._standardise_query(X)
        mean, var = global_predict(self.params, self.post, Xs, self.config.batch_size, self.var_scale)
        if include_noise:
            var = var + np.asarray(self.params.noise)[None, :]
        return self._finish(ok, mean, var)

    # ------------------------------------------------------------ conditioning
    def _with_stats(self, stats: Stats) -> "LocalGlobalGP":
        return replace(self, stats=stats, _post=global_posterior(self.params, stats))

    def _mi_nugget(self) -> float:
        """Relative noise of the mutual-information criterion (as in the fit's selection)."""
        bdiag = np.diag(np.asarray(self.params.B))
        noise = np.asarray(self.params.noise)
        return max(float(np.mean(noise / (bdiag + noise))), 1e-4)

    def update(self, X_new, Y_new, exchange: bool = True) -> "LocalGlobalGP":
        """Condition on new rows; memory and saved state stay bounded.

        1. *Inducing points* (``exchange`` and ``config.swap_max > 0``): up to ``swap_max`` of
           the new rows least explained by ``Z`` (``sigma^2(x | Z) > swap_threshold``) may each
           replace the inducing point that mutual information ranks most redundant
           (:func:`gcs_sysid.gp.streaming.exchange_inducing`); the statistics of the rows seen
           so far are then carried to the new points by the streaming sparse GP projection of
           Bui, Nguyen and Turner (2017) (:func:`gcs_sysid.gp.streaming.project_stats`).
        2. *Global layer*: the new rows' statistics are added (sums over rows). With no
           exchange the posterior equals the one computed from all rows at once with the same
           hyperparameters (Titsias 2009), exactly.
        3. *Local layer*: the rows join the region-thinned store (at most ``store_max`` rows,
           :mod:`gcs_sysid.gp.rowstore`); residuals and the k-d tree are recomputed when next needed.
        4. *Hyperparameters*: learned again on the stored rows every ``config.hyper_every`` rows
           (0: only through :meth:`refresh_hyperparameters`).

        The standardisation is kept. Cost ``O(E M^2)`` for ``E`` rows, plus ``O(M^3)`` when an
        exchange is considered; the posterior (``O((P M)^3)``) is refactored at the next prediction.

        Args:
            X_new: ``(N, D)`` regressors. Y_new: ``(N, P)`` coefficients, data units.
            exchange: allow inducing-point replacement (False: exact conditioning, ``Z`` kept).

        Returns:
            A new :class:`LocalGlobalGP` (this one is unchanged).

        Raises:
            InputError: wrong shapes. DataError: no finite row.
        """
        enable_x64()
        X_new, Y_new, notes = check_training(X_new, Y_new, self.n_inputs, self.n_outputs, partial=True)
        Xs, Ys = self.scaler.x(X_new), self.scaler.y(Y_new)
        cfg = self.config
        params, stats, evicted = self.params, self.stats, self.evicted
        if exchange and cfg.swap_max > 0 and self.rows is not None:
            Z_old, ls = np.asarray(params.Z), np.asarray(params.metric_lengthscale())
            pool = self.rows.X[self.rows.sample(cfg.swap_pool, seed=self.rows.seen)]
            Z_new, swaps = exchange_inducing(Z_old, ls, Xs, pool, self._mi_nugget(), cfg.swap_threshold,
                                             cfg.swap_max)
            if swaps:
                R = _projection_all(params, Z_new, np.asarray(params.lengthscales))
                stats = project_stats(stats, R)
                evicted = None if evicted is None else project_stats(evicted, R)
                params = replace(params, Z=jax.device_put(Z_new))
        stats = _add_jit(stats, global_stats(params, Xs, Ys, cfg.batch_size))
        rows = self.rows
        if rows is not None:
            rows, Xd, Yd = rows.add_dropped(Xs, Ys)
            if len(Xd):
                gone = global_stats(params, Xd, Yd, cfg.batch_size)
                evicted = gone if evicted is None else _add_jit(evicted, gone)
        model = replace(self, params=params, stats=stats, _post=None, _store=None, rows=rows, evicted=evicted,
                        since_refresh=self.since_refresh + len(Xs), notes=self.notes + tuple(notes))
        if cfg.hyper_every > 0 and model.since_refresh >= cfg.hyper_every:
            model = model.refresh_hyperparameters()
        return model

    def refresh_hyperparameters(self, reselect: bool = True) -> "LocalGlobalGP":
        """Learn the hyperparameters again on the stored rows; optionally choose the inducing inputs again.

        The global hyperparameters are learned as in :func:`gcs_sysid.gp.fit_gp` (Adam on the
        VFE bound over ``n_train_max`` random stored rows with ``n_inducing_hyper`` points chosen
        by mutual information), starting from the current values. With ``reselect`` the ``M``
        inducing inputs are then chosen again by mutual information among the stored rows (a
        region-thinned sample of all rows seen, so the points follow the envelope flown). The
        statistics are then computed again: exactly for the stored rows, and for the rows no
        longer stored (``evicted``, thinned from dense regions) by the streaming projection to the
        new length-scales and inducing inputs (Bui et al. 2017,
        :func:`gcs_sysid.gp.streaming.projection`); exact for all rows while none was evicted.
        The local layer is learned again on the stored rows' residuals. The blocked
        cross-validation of the fit (:mod:`gcs_sysid.gp.validation`) runs again on the stored rows
        in arrival order, so the latent GP's per-output scales and the local layer's per-output
        switch are chosen again for the new hyperparameters. The cost does not depend
        on the rows seen (``O(store_max M^2)`` plus a fit's hyperparameter stage).

        Args:
            reselect: choose the inducing inputs again (False: keep them).

        Returns:
            A new :class:`LocalGlobalGP`.

        Raises:
            DataError: fewer than 3 stored rows.
        """
        from ..errors import DataError
        from .fit import (FitHistory, _validated_mean_only, _validated_terms, fit_local, learn_global, mean_only_masks,
                          output_groups, posterior_noise, validated_global, validated_local)

        enable_x64()
        rows = self.rows
        if rows is None or len(rows) < 3:
            raise DataError("gp: need at least 3 stored rows to refresh the hyperparameters")
        cfg = self.config
        history = FitHistory()
        M = int(self.params.Z.shape[0])
        hyper_cfg = replace(cfg, n_inducing_hyper=min(cfg.n_inducing_hyper or M, M))   # the fit's compiled shapes
        kernel, allowed, _ = mean_only_masks(cfg, self.input_names, self.output_names, rows.X, rows.Y,
                                             self.scaler.active, self.scaler.x_std)
        new = learn_global(rows.X, rows.Y, self.scaler.active, hyper_cfg, M if reselect else 0, history,
                           start=self.params, groups=output_groups(self.output_names, cfg), masks=(kernel, allowed))
        Z_old = np.asarray(self.params.Z)
        Z_new = np.asarray(new.Z) if reselect and new.Z.shape[0] == M else Z_old
        params = replace(new, Z=jax.device_put(Z_new))
        # the blocked cross-validation of the fit, on the stored rows (arrival order; exact time order
        # while none was thinned): a refresh must not bring back what the fit's check removed
        params, stats = validated_global(params, rows.X, rows.Y, cfg, history)
        params = posterior_noise(params, cfg, history)
        if cfg.linear_terms == "validated" and cfg.linear_mean and "latent_scale" in history.validation:
            params = _validated_terms(params, rows.X, rows.Y, self.scaler.active, history)
        params = _validated_mean_only(params, rows.X, rows.Y, cfg, kernel, history)
        evicted = None
        if self.evicted is not None:
            R = _projection_all(self.params, Z_new, np.asarray(new.lengthscales))
            evicted = project_stats(self.evicted, R)
            stats = _add_jit(stats, evicted)
        model = replace(self, params=params, stats=stats, evicted=evicted, _post=None, _store=None,
                        since_refresh=0, n_hyper=int(min(cfg.n_train_max, len(rows))))
        if cfg.input_noise:
            from .fit import learn_input_noise

            model = replace(model, input_var=learn_input_noise(params, model.post, rows.X, rows.Y, self.scaler.active,
                                                               cfg))
        if self.local_params is not None:
            resid = rows.Y - model._global_mean_s(rows.X)
            local_params, store = fit_local(cfg, params, rows.X, resid, history)
            local_params = validated_local(local_params, params, rows.X, resid, cfg, history)
            model = replace(model, local_params=local_params, _store=store)
        if self.discrepancy is not None:
            from .discrepancy import calibrate

            model = calibrate(model, rows.X, rows.Y, history.validation.get("cv_mse"))
        return model

    def _global_mean_s(self, Xs: np.ndarray) -> np.ndarray:
        return global_mean(self.params, self.post, Xs, self.config.batch_size)

    def variance_after(self, X_extra, X_query, include_noise: bool = True) -> np.ndarray:
        """Predictive variance at ``X_query`` if noisy observations were added at ``X_extra``.

        The variance of a GP does not depend on the observed values, so the statistics of
        ``X_extra`` (with any ``Y``) are added to the global layer (a rank-``P*E`` change of
        the posterior precision, refactored) and its points to the local layer's store.

        Args:
            X_extra: ``(E, D)`` candidate regressors (e.g. a maneuver's trajectory).
            X_query: ``(Q, D)`` where the variance is wanted.

        Returns:
            ``(Q, P)`` predictive variance, data units squared, without the input-noise term
            (what more data can reduce; ``predict(..., input_noise=False)``).
        """
        enable_x64()
        Xe, _ = self._standardise_query(X_extra)
        if len(Xe) == 0:
            return self.predict(X_query, include_noise, input_noise=False, model_error=False)[1]
        zeros = np.zeros((len(Xe), self.n_outputs))
        extra = self._with_stats(add_stats(self.stats, global_stats(self.params, Xe, zeros, self.config.batch_size)))
        if self.store is not None:
            X_all = np.vstack([self.store.X, Xe])
            store = build_store(X_all, np.vstack([self.store.resid, zeros]), self.store.metric, self.store.k)
            extra = replace(extra, _store=store)
        return extra.predict(X_query, include_noise, input_noise=False, model_error=False)[1]

    def global_variance_after_many(self, X_extras, X_queries, include_noise: bool = False
                                   ) -> list[tuple[np.ndarray, np.ndarray]]:
        """Global-layer variance at query sets before and after observing each of ``C`` candidates.

        The batched, closed-form (Woodbury) counterpart of :meth:`variance_after` for ranking
        many candidates: only the global layer is updated (the local layer, a nearest-neighbour
        correction of the residual, is left out of both numbers), and the global posterior
        precision is not refactored (:mod:`gcs_sysid.gp.ranking`). Each pair equals
        ``predict_global(X_query)[1]`` and ``update(X_extra, Y, exchange=False).predict_global(X_query)[1]``.

        Args:
            X_extras: ``C`` arrays ``(E_c, D)`` of candidate regressors, data units (NaN rows ignored).
            X_queries: ``C`` arrays ``(Q_c, D)``; the same array object may be passed for several
                candidates (its features are then computed once).
            include_noise: add the global layer's noise variance.

        Returns:
            ``C`` pairs ``(var_before (Q_c, P), var_after (Q_c, P))``, data units squared (NaN for
            query rows with a NaN).

        Raises:
            InputError: arrays that are not ``(N, D)``; ValueError: list lengths differ.
        """
        from .ranking import global_variance_after_many

        enable_x64()
        qs: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        ext, qry, oks = [], [], []
        for Xe, Xq in zip(X_extras, X_queries):
            ext.append(self._standardise_query(Xe)[0])
            if id(Xq) not in qs:
                qs[id(Xq)] = self._standardise_query(Xq)
            Xs, ok = qs[id(Xq)]
            qry.append(Xs)
            oks.append(ok)
        if len(X_extras) != len(X_queries):
            raise ValueError("global_variance_after_many: one query set per candidate")
        noise = np.asarray(self.params.noise)[None, :] if include_noise else 0.0
        out = []
        for (v0, v1), ok in zip(global_variance_after_many(self, ext, qry), oks):
            out.append((self._finish(ok, v0, v0 + noise)[1], self._finish(ok, v1, v1 + noise)[1]))
        return out

    # ------------------------------------------------------------ reporting
    def output_correlation(self) -> np.ndarray:
        """Correlation ``(P, P)`` between the outputs' global GP parts at one input, from ``B``
        (``sum_j B_j`` for a linear model of coregionalisation)."""
        B = np.asarray(self.params.B)
        s = np.sqrt(np.diag(B))
        return B / np.outer(s, s)

    def noise_correlation(self) -> np.ndarray:
        """Correlation ``(P, P)`` of the global layer's observation noise (identity: independent noise)."""
        S = np.asarray(self.params.noise_cov())
        d = np.sqrt(np.diag(S))
        return S / np.outer(d, d)

    def linear_derivatives(self) -> tuple[np.ndarray, np.ndarray]:
        """Posterior-mean linear part of the model in data units.

        Returns:
            ``(intercept (P,), slopes (P, D))``: ``y_p ~ intercept_p + slopes_p . x`` (the GP
            adds the nonlinear rest; inactive inputs have slope 0).
        """
        P, D = self.n_outputs, self.n_inputs
        K = self.post.b.shape[0]
        mu = cho_solve((np.asarray(self.post.L), True), np.asarray(self.post.b))
        W = (np.broadcast_to(np.asarray(self.params.prior_std, float), (P, D + 1))
             * mu[K - P * (D + 1):].reshape(P, D + 1))
        sc = self.scaler
        slopes = sc.y_std[:, None] * W[:, 1:] / sc.x_std[None, :] * sc.active[None, :]
        intercept = sc.y_mean + sc.y_std * W[:, 0] - slopes @ sc.x_mean
        return intercept, slopes

    def elbo(self) -> float:
        """VFE bound on the log marginal likelihood of all rows seen (standardised units)."""
        return float(_elbo_jit(self.params, self.stats))

    def summary(self) -> dict[str, Any]:
        """Hyperparameters and sizes, JSON-able (data units unless marked standardised)."""
        sc = self.scaler
        ls = np.asarray(self.params.lengthscale)
        names = self.input_names

        def scales(values):
            return {n: (float(v * s) if a else None) for n, v, s, a in zip(names, values, sc.x_std, sc.active)}

        B = np.asarray(self.params.B)
        intercept, slopes = self.linear_derivatives()
        out: dict[str, Any] = {
            "kind": "LocalGlobalGP",
            "approximation": ("VFE (Titsias 2009), intrinsic coregionalisation, linear mean"
                              if self.params.n_kernels == 1 else
                              f"VFE (Titsias 2009), linear model of coregionalisation ({self.params.n_kernels} "
                              "latent kernels), linear mean"),
            "inputs": list(names), "outputs": list(self.output_names),
            "inactive_inputs": [n for n, a in zip(names, sc.active) if not a],
            "n_inducing": int(self.params.Z.shape[0]), "n_used": self.n_used, "n_hyper": int(self.n_hyper),
            "elbo": self.elbo(), "elbo_per_point": self.elbo() / max(self.n_used * self.n_outputs, 1),
            "global": {
                "lengthscales": scales(ls),
                "lengthscales_standardised": {n: float(v) for n, v in zip(names, ls)},
                "B_standardised": B.tolist(),
                "output_correlation": self.output_correlation().tolist(),
                "signal_std": dict(zip(self.output_names, (np.sqrt(np.diag(B)) * sc.y_std).tolist())),
                "noise_std": dict(zip(self.output_names, (np.sqrt(np.asarray(self.params.noise)) * sc.y_std).tolist())),
                "noise_correlation": self.noise_correlation().tolist(),
                "input_noise_std": None if self.input_var is None else scales(np.sqrt(np.asarray(self.input_var))),
                "linear_intercept": dict(zip(self.output_names, intercept.tolist())),
                "linear_derivatives": {o: dict(zip(names, row.tolist())) for o, row in zip(self.output_names, slopes)},
            },
            "latent_kernels": None if self.params.n_kernels == 1 else [
                {"lengthscales": scales(ls_j), "lengthscales_standardised": {n: float(v) for n, v in zip(names, ls_j)},
                 "signal_std": dict(zip(self.output_names, (np.sqrt(np.diag(Bj)) * sc.y_std).tolist()))}
                for ls_j, Bj in zip(np.asarray(self.params.lengthscales), np.asarray(self.params.B_parts))],
            "local": None,
            "streaming": None if self.rows is None else {
                "rows_seen": int(self.rows.seen), "rows_stored": len(self.rows), "store_max": int(self.rows.capacity),
                "rows_evicted": int(round(self.evicted.rows())) if self.evicted is not None else 0,
                "since_refresh": int(self.since_refresh)},
            "notes": list(self.notes),
        }
        from .discrepancy import model_error_summary

        out["model_error"] = model_error_summary(self)       # the band at exact conditions (docs/gp.md)
        if self.local_params is not None and self.store is not None:
            lp = self.local_params
            out["local"] = {
                "neighbours": int(self.store.k), "n_stored": int(len(self.store.X)),
                "lengthscales": scales(np.asarray(lp.lengthscale)),
                "beta": float(lp.beta),
                "signal_std": dict(zip(self.output_names, (np.sqrt(np.asarray(lp.amp)) * sc.y_std).tolist())),
                "noise_std": dict(zip(self.output_names, (np.sqrt(np.asarray(lp.noise)) * sc.y_std).tolist())),
            }
        return out

    def save(self, path) -> str:
        """Write the model to ``<path>.npz`` (arrays) and ``<path>.json`` (settings); no pickle.

        Returns the npz path. See :func:`gcs_sysid.gp.load_gp`.
        """
        from .io import save_model

        return save_model(self, path)
