"""Settings of the local + global GP."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from ..errors import InputError

__all__ = ["GPConfig"]


@dataclass(frozen=True)
class GPConfig:
    """How :func:`gcs_sysid.gp.fit_gp` builds the model.

    Attributes:
        n_inducing: inducing points ``M`` of the global layer (the feature space has
            ``P*M + P*(D+1)`` dimensions; keep ``P*M`` below ~1500).
        n_inducing_hyper: inducing points while learning the hyperparameters (the cost
            of a step grows as ``(P*M)^3``); the final posterior uses ``n_inducing`` points
            chosen again with the learned length-scales. None: ``n_inducing``.
        n_train_max: rows (random subset) used to learn hyperparameters; the posterior
            then uses every row.
        steps: most Adam steps on the VFE bound (half before and half after re-selecting the
            inducing points when ``reselect``).
        learning_rate: Adam step size (unconstrained, log-scale parameters).
        tol: early stopping: an Adam run (global or local) stops when the mean loss (per data
            point and output) of the last 10 steps improved by less than this on the 10 before;
            0 runs every step.
        rank: rank ``R`` of the shared part ``L L^T`` of the coregionalisation matrix (of each
            kernel's ``B_j`` with ``latent_kernels > 1``).
        latent_kernels: latent kernels ``J`` of the global layer: 1 is the intrinsic
            coregionalisation model (one set of ARD length-scales for all outputs); ``J > 1`` a
            linear model of coregionalisation, ``cov(f(x), f(x')) = sum_j B_j k_j(x, x')`` with
            one length-scale vector per kernel, so each output weighs short and long
            length-scales in its own proportions (``docs/gp.md``, "Per-output length-scales").
            The feature space grows to ``J*P*M + P*(D+1)`` dimensions and the statistics to
            ``(J M)^2``: keep ``J*P*M`` below ~1500.
        inducing: ``"mi"`` (greedy mutual information), ``"kmeans"`` or ``"random"``.
        mi_pool: candidates for the mutual-information selection.
        reselect: re-run the selection with the learned length-scales halfway.
        train_inducing: also optimise the inducing inputs ``Z``.
        linear_mean: include the linear (stability-and-control-derivative) mean.
        prior_std: prior std of the linear-mean weights, standardised units.
        linear_terms: which regressors enter each output's linear mean: ``"validated"`` (the default,
            below); ``"all"`` every active regressor (the model before the tenth session);
            ``"significant"`` (opt-in) those whose slope keeps ``|t| >= 2`` with
            coloured-residual standard errors in a backward elimination on the training rows
            (:func:`gcs_sysid.gp.colored.significant_inputs`; ``docs/gp.md``, "Linear terms that earn
            their place": better than LS on 196 of 216 JSBSim pairs against 190, but it drops true
            linear terms of outputs with a large nonlinear part, and with missing outputs that broke
            the joint model's prediction of the missing output); ``"validated"``: the same elimination
            after the blocked validation, only for the outputs whose latent GP it shrank to the
            smallest scale (there the linear fit's residual is noise): better than LS on 194 of 216
            pairs against main's 189, no CX loss, the slow synthetic tests pass.
        jitter: added to the diagonal of ``Kmm``.
        local: add the local non-stationary layer.
        local_neighbours: neighbours ``K`` per local prediction.
        local_batch: neighbourhoods in the local composite likelihood.
        local_steps: most Adam steps for the local hyperparameters.
        local_learning_rate: their Adam step size.
        batch_size: rows per compiled chunk when computing statistics and predictions.
        seed: seed of every random choice.
        store_max: most training rows kept for the local layer and hyperparameter refreshes
            (:mod:`gcs_sysid.gp.rowstore`): beyond it the densest regions are thinned, so the
            saved state and memory stop growing. The default keeps every row of a 10-minute
            50 Hz flight (the replay path is unchanged) and ~4 MiB of rows.
        store_cell: width of the thinning grid's cells in global length-scales (standardised).
        swap_max: most new rows per :meth:`LocalGlobalGP.update` considered for replacing an
            inducing point (mutual-information exchange, :mod:`gcs_sysid.gp.streaming`); 0: the
            inducing points never change after the fit.
        swap_threshold: least unexplained prior variance ``sigma^2(x | Z)`` (standardised,
            of 1) of a new row for it to be considered.
        swap_pool: stored rows standing for the unselected set in the exchange criterion.
        noise_correlation: learn a full ``P x P`` noise covariance in the likelihood of the
            global layer (cross-correlated noise: a gust moves several coefficients at once),
            not only one variance per output; ``docs/gp.md``, "Noise". Off in ``GPConfig()``; the
            replay turns it on, with ``noise_posterior = "diagonal"``, since the twenty-fifth session
            (``gcs_sysid.pipeline.GP_NOISE = "learned"``; ``docs/gp.md``, "The default noise"), the live learner
            since the twenty-sixth (``gcs_sysid.live.learner.GP_NOISE``).
        noise_start: where the residual's cross-output covariance starts, with ``noise_correlation``:
            ``"signal"`` (the default, the start before the seventeenth session): 0.7 of the ridge
            residual's covariance in ``B``, the noise independent (0.3 of each output's variance);
            ``"noise"``: ``B`` starts diagonal (the same 0.7 of each variance) and the noise covariance
            at the residual's cross-output correlation, so the shared error starts as noise and the
            bound moves it into ``B`` only as far as it climbs (``docs/gp.md``, "Noise: where the shared
            error starts"). Ignored without ``noise_correlation``, with missing outputs and with the
            per-group kernels of ``output_groups``.
        noise_posterior: with ``noise_correlation``, the noise covariance the posterior (the predictions' mean and
            band, the local layer's residuals) conditions on: ``"full"`` (``GPConfig``'s default) the learned ``P x P``
            one; ``"diagonal"`` (twenty-third session, i8-noise2) only its per-output variances. The correlation
            is learned with the other hyperparameters and used by every later decision (the blocked validation's
            latent scales, the coupling test, the validated terms), so the gusts' shared error is not explained as
            signal coupling in ``B``; it is dropped just before the posterior
            (:func:`gcs_sysid.gp.fit.posterior_noise`). Why: with a noise correlation the
            posterior is a seemingly-unrelated-regressions GLS, which moves one output's mean by another's
            residual wherever their regressors or priors differ (``alpha_dot_hat`` in Cm's mean alone, each
            output's own linear terms and blocked-validation scale; Zellner 1962); sgs126 light s1: a learned CZ-Cm
            correlation of 0.74 moved Cm's pitch slopes (Cm_q -10.2 -> -0.7, Cm_alpha_dot -4.9 -> -16.4;
            ``docs/gp.md``, "Noise: learned, not conditioned on"). ``GPConfig()`` keeps ``"full"``; the replay uses
            ``"diagonal"`` with ``noise_correlation`` since the twenty-fifth session (``pipeline.GP_NOISE``).
            Ignored without ``noise_correlation``.
        hyper_stride: learn the global hyperparameters on every ``hyper_stride``-th training row in time
            order (then at most ``n_train_max`` of them at random); 1 (the default): any ``n_train_max`` rows.
            Rows that close in time share the gusts' coloured error, which the bound, counting rows as
            independent, explains as signal (``docs/gp.md``, "Noise: where the shared error starts"). The
            posterior still conditions on every row. Opt-in, measured only by ``eval_gp_joint``.
            0: the stride from the data (eighteenth session): the decorrelation time of the training
            residual, the median over outputs of the first lag where the autocorrelation of a ridge
            least-squares fit's residual on the rows in time order falls below 1/e
            (:func:`gcs_sysid.gp.colored.decorrelation_lag`; rows that far apart are worth ~0.46 of an
            independent row each, Bayley and Hammersley 1946); recorded in ``history.validation["hyper_stride"]``
            (``docs/gp.md``, "The stride from the decorrelation time").
        coupling: ``"learned"`` (the default): the cross-output coupling (the off-diagonals of ``B`` and, with
            ``noise_correlation``, of the noise covariance) is kept as the bound learned it; ``"off"``: the
            hyperparameters are learned with it (so the gusts' shared error has somewhere to go other than the
            length-scales and the per-output noise), then ``B`` and the noise covariance are made diagonal
            (:func:`gcs_sysid.gp.joint.decoupled`) before the blocked validation, the posterior and every
            hyperparameter refresh. What the outputs then still share: one kernel (one set of ARD length-scales),
            the inducing inputs, the bound the per-output latent and noise variances were learned in, and the
            regressors' input-noise variances (NIGP); each output's posterior conditions on its own column only.
            Refused with ``coupling_validation=True`` and ``output_groups="kernels-free"`` (no one latent per
            output to keep).
        coupling_rows: ``"subset"`` (the default): the coregionalisation ``B`` and the noise covariance are learned
            with the other hyperparameters on the ``n_train_max`` rows of the bound; ``"all"`` (opt-in, twentieth
            session): after that, ``B`` (its factor and independent part) and the noise covariance (variances and,
            with ``noise_correlation``, the correlation) are learned again by the same bound on the sufficient
            statistics of *every* training row, the kernel and the inducing inputs held (the statistics do not
            depend on ``B`` or the noise, so this costs one pass over the rows and steps in a ``K``-dimensional
            feature space, ``K = P M_h + P (D+1)``). Why: an off-diagonal of ``B`` is poorly determined by the
            1,000-row subset of a coloured 50 Hz flight; on the b737 in moderate turbulence the learned Cl-Cm
            correlation was 0.28-0.69 over the subset's seed, 0.25 with every row (the truth's 0.26;
            ``docs/gp.md``, "Coupling from every row"). Complete rows, one kernel, no per-group kernels
            (otherwise ignored).
        coupling_test: ``"lr"`` (the default since the twenty-second session; opt-in in the twenty-first): after the
            blocked validation's latent scales, an
            output keeps its signal coupling to the others only where the collapsed bound on the statistics of
            *every* training row supports it by a likelihood-ratio test, the statistic deflated for the rows'
            colour (one over the training residual's long-run variance ratio,
            :func:`gcs_sysid.gp.colored.variance_inflation`); backward elimination of outputs at level
            :data:`gcs_sysid.gp.joint.LR_LEVEL` (:func:`gcs_sysid.gp.joint.lr_coupling`). The noise covariance is
            kept. Why: an off-diagonal the data do not determine (the b737's Cl-Cm 0.28-0.69 over the subset's
            seed; a latent part the validation shrank to ~0) is reported by ``output_correlation()`` at full size
            (``docs/gp.md``, "Coupling the data determine"). Costs ``O(P^2)`` bound evaluations on the
            statistics the posterior uses anyway. Not with the per-group kernels of ``output_groups``. ``"none"``:
            ``B``'s off-diagonals are kept as learned (and as the coupling gate left them), the default until the
            twenty-second session. Made the default on the measurement of all 19 tuning aircraft x 3 seeds x light
            and moderate (``eval_gp_jsbsim``, docs/benchmarks.md, twenty-second session, lead): flights with a learned
            output correlation above 0.5 81 -> 8 of 114, pairs flagged (truth below 0.2) 65 -> 1, held-out errors
            unchanged (median 10.73 -> 10.75 %).
        input_noise: learn one input-noise variance per regressor (errors in variables, NIGP)
            and add ``grad m^T Sigma_x grad m`` to the predictive variance at estimated
            regressors (``docs/gp.md``, "Noisy inputs").
        residual_correlation: multiply the global layer's explained predictive variance per output by
            the long-run variance ratio of its time-ordered training residuals (coloured residuals:
            consecutive rows share an error, so they are worth fewer independent rows;
            :mod:`gcs_sysid.gp.colored`). Off by default (``docs/gp.md``, "Coloured residuals").
        validation_folds: contiguous blocks of the time-ordered training rows for the blocked
            cross-validation that decides, per output, how much of the latent GP and whether the
            local layer is kept (:mod:`gcs_sysid.gp.validation`; ``docs/gp.md``, "Earning its
            place"); 0 or 1: keep both as learned (the model before this check).
        coupling_validation: with the blocked validation, keep the cross-output coupling (the
            off-diagonals of ``B`` and of the noise covariance) only for the outputs whose blocked
            error it lowers by 1 % (:func:`gcs_sysid.gp.joint.gate_coupling`, rule ``"ratio"``; its opt-in
            rule ``"paired-t"`` also asks the gain to pass a paired t-test over the time blocks at 5 %;
            ``docs/gp.md``, "Joint vs independent outputs"). ``False`` (the default): off; ``None``: on
            wherever it applies (not with the per-group kernels of ``output_groups``); ``True``: on
            (refused with those kernels).
            Why: on the JSBSim flights' isotopic tables the coupling of ``B``, learned under one noise
            variance per output, took up the gusts' cross-output error (CY-Cn, Cl-Cn) and never lowered the
            held-out error against the truth (asw20: joint worse than its decoupled self on 17 of 24 pairs
            with 20 s of training, better on none).
        output_groups: ``"axes"``: when the outputs are the body-axis coefficients (named
            ``CX CY CZ Cl Cm Cn``, the pipeline's), the shared factors ``L`` of every
            coregionalisation matrix are split between the longitudinal outputs (CX, CZ, Cm) and the
            lateral-directional ones (CY, Cl, Cn): factor ``r`` loads only on group ``r mod 2``, so
            the signal's cross-axis covariance is 0 and each output keeps its own independent part
            ``kappa``. A symmetric aircraft's longitudinal coefficients are even functions of the
            lateral variables (beta, p, r, delta_a, delta_r) and its lateral ones odd (the symmetric-
            flight decoupling; Etkin and Reid 1996, *Dynamics of Flight*), so over an envelope flown
            both ways their nonlinear parts do not correlate; the learned cross-axis correlations
            were what the rank-2 factors shared, not the truth's. ``"none"`` (the default): every
            factor loads on every output. Off by default: on the replay's JSBSim flights it moved the
            errors by 0.0-0.4 points both ways and lost 3 GP-vs-LS pairs of 72 by 0.00-0.18 points
            (``docs/gp.md``, "Joint vs independent outputs", twelfth session).
            ``"kernels"`` (thirteenth session): the same two groups, each with its own latent kernel
            (its own ARD length-scales) and its own coregionalisation ``B_g = L_g L_g^T +
            diag(kappa_g)`` over its outputs only: a linear model of coregionalisation whose kernel
            ``g`` loads on group ``g`` alone, so the longitudinal outputs no longer share the lateral
            outputs' input relevance, the couplings within an axis stay learnable and the cross-axis
            ones are 0 (``docs/gp.md``, "Per-group kernels"). Each kernel has ``|g|`` latent
            processes, so the posterior's feature space keeps the ICM's size ``P M + P (D+1)``.
            ``"kernels-free"``: the same kernels, started the same way, but each kernel's factor
            ``A_g (P, |g|)`` is free to load on every output (an output mixes both kernels' length-
            scales; cross-axis couplings are learnable again).
            ``"output-kernels"``: one kernel (own length-scales) and one latent process per output,
            the latent loading on the outputs of its own axis (free loadings there, 0 elsewhere): the
            semiparametric latent factor model (Teh, Seeger and Jordan 2005) with ``Q = P``; its
            statistics cost ``(P M)^2`` per row.
            All three need ``latent_kernels = 1`` and no ``coupling_validation``; outputs that are not the six
            coefficients (or one axis only) fall back to the ICM.
        mean_only_inputs: names of inputs (``fit_gp``'s ``input_names``; the trailing columns of ``X``) that
            enter only the linear mean, never a kernel: their length-scales are pinned at
            :data:`gcs_sysid.gp.fit.MEAN_ONLY_LENGTHSCALE` (standardised) in both layers, so the latent GP,
            the local layer and the neighbour search do not see them. A query may leave them out (``X`` with
            ``D - len(mean_only_inputs)`` columns): they are then 0 in data units (the pipeline's
            ``alpha_dot_hat``: steady flight). ``docs/gp.md``, "Mean-only inputs".
        mean_only_outputs: the outputs whose linear mean may carry the ``mean_only_inputs`` (others: prior std
            0), and then only where the slope is significant with coloured residuals on the training rows
            (:func:`gcs_sysid.gp.colored.significant_inputs`, the data's own test). The pipeline: ``("Cm",)``.
        mean_only_sign: 0 (any sign), or -1 / +1: a mean-only input enters an output's mean only when its slope
            in that test's least-squares fit has this sign. The pipeline: -1, ``Cm_alpha_dot < 0`` (the lag of the
            wing's downwash at an aft tail: ``Cm_alpha_dot = -2 a_t V_H (l_t / c) d(epsilon)/d(alpha)``, Etkin
            and Reid 1996, *Dynamics of Flight*, 3rd ed., sec. 5.5). A positive slope is what the pitch gust rate
            gives through its correlation with ``alpha_dot`` (measured on the f4n in moderate turbulence,
            +12 to +15 against JSBSim's -9; ``docs/gp.md``, "Mean-only inputs").
        mean_only_partners: per mean-only input (same order; ``""``: none), the kernel regressor whose slope it
            splits with: the input then enters an output's mean only when that same least-squares fit keeps the
            partner too, with the sign ``mean_only_sign``, and the input's slope is at most ``mean_only_ratio``
            times the partner's in data units. The pipeline: ``("q_hat",)`` and 1: ``Cm_q < 0`` and
            ``|Cm_alpha_dot| <= |Cm_q|``. Why: in the short period ``alpha_dot ~ q``, so only their sum is well
            determined from ordinary maneuvers (Grauer, Morelli and Murri 2017, "Flight test techniques for quantifying
            pitch rate and angle of attack rate dependencies", NASA NTRS 20170001231: separating them takes
            dedicated maneuvers) and the split follows whatever else the residual carries; for an aft tail
            ``Cm_alpha_dot / Cm_q(tail) = d(epsilon)/d(alpha) < 1`` (Etkin and Reid 1996, sec. 5.5; Nelson 1998,
            *Flight Stability and Automatic Control*, 2nd ed., ch. 3), and ``Cm_q < 0``. On the JSBSim F-16 (no
            alpha-dot term) ``alpha_dot_hat`` pushed ``q_hat`` out of Cm's mean (the nonlinear
            ``CmDh(alpha, delta_e)`` table left in the linear residual, carried by ``alpha_dot_hat``'s small part
            not collinear with the regressors); ``docs/gp.md``, "The partner rule".
        mean_only_ratio: the largest ``|slope(input)| / |slope(partner)|`` (data units), see
            ``mean_only_partners``.
        hyper_every: rows between automatic hyperparameter refreshes in ``update`` (learned
            again on the stored rows; :meth:`LocalGlobalGP.refresh_hyperparameters`); 0: only
            on request.
    """

    n_inducing: int = 128
    n_inducing_hyper: int | None = 32
    n_train_max: int = 1000
    steps: int = 200
    learning_rate: float = 0.05
    tol: float = 1e-3
    rank: int = 2
    latent_kernels: int = 1
    inducing: str = "mi"
    mi_pool: int = 800
    reselect: bool = True
    train_inducing: bool = False
    linear_mean: bool = True
    prior_std: float = 3.0
    linear_terms: str = "validated"
    jitter: float = 1e-6
    local: bool = True
    local_neighbours: int = 16
    local_batch: int = 64
    local_steps: int = 40
    local_learning_rate: float = 0.1
    batch_size: int = 2048
    seed: int = 0
    store_max: int = 30000
    store_cell: float = 0.5
    swap_max: int = 2
    swap_threshold: float = 0.1
    swap_pool: int = 256
    hyper_every: int = 0
    noise_correlation: bool = False
    noise_start: str = "signal"
    noise_posterior: str = "full"
    hyper_stride: int = 1
    coupling: str = "learned"
    coupling_rows: str = "subset"
    coupling_test: str = "lr"
    input_noise: bool = True
    residual_correlation: bool = False
    validation_folds: int = 5
    coupling_validation: bool | None = False
    output_groups: str = "none"
    mean_only_inputs: tuple[str, ...] = ()
    mean_only_outputs: tuple[str, ...] = ()
    mean_only_sign: float = 0.0
    mean_only_partners: tuple[str, ...] = ()
    mean_only_ratio: float = 1.0

    def __post_init__(self):
        for name in ("mean_only_inputs", "mean_only_outputs", "mean_only_partners"):   # JSON gives lists: kept hashable
            v = getattr(self, name)
            if isinstance(v, str) or not all(isinstance(x, str) for x in v):
                raise InputError(f"GPConfig.{name} must be a sequence of names, got {v!r}")
            object.__setattr__(self, name, tuple(v))
        if self.mean_only_partners and len(self.mean_only_partners) != len(self.mean_only_inputs):
            raise InputError("GPConfig.mean_only_partners must name one partner (or '') per mean-only input, got "
                             f"{self.mean_only_partners!r} for {self.mean_only_inputs!r}")
        if not float(self.mean_only_ratio) > 0:
            raise InputError(f"GPConfig.mean_only_ratio must be > 0, got {self.mean_only_ratio!r}")
        if self.n_inducing_hyper is not None and int(self.n_inducing_hyper) < 1:
            raise InputError(f"GPConfig.n_inducing_hyper must be a positive integer or None, "
                             f"got {self.n_inducing_hyper!r}")
        for name in ("n_inducing", "n_train_max", "local_neighbours", "local_batch", "batch_size", "mi_pool",
                     "latent_kernels"):
            if int(getattr(self, name)) < 1:
                raise InputError(f"GPConfig.{name} must be a positive integer, got {getattr(self, name)!r}")
        if int(self.store_max) < 16:
            raise InputError(f"GPConfig.store_max must be at least 16 rows, got {self.store_max!r}")
        if not (self.store_cell > 0 and 0 <= self.swap_threshold <= 1):
            raise InputError("GPConfig: store_cell must be > 0 and swap_threshold within [0, 1]")
        for name in ("steps", "local_steps", "rank", "swap_max", "swap_pool", "hyper_every", "validation_folds"):
            if int(getattr(self, name)) < 0:
                raise InputError(f"GPConfig.{name} must be >= 0, got {getattr(self, name)!r}")
        if self.linear_terms not in ("significant", "validated", "all"):
            raise InputError("GPConfig.linear_terms must be 'significant', 'validated' or 'all', got "
                             f"{self.linear_terms!r}")
        if self.output_groups not in ("axes", "kernels", "kernels-free", "output-kernels", "none"):
            raise InputError("GPConfig.output_groups must be 'axes', 'kernels', 'kernels-free', 'output-kernels' or "
                             f"'none', got {self.output_groups!r}")
        if self.output_groups in ("kernels", "kernels-free", "output-kernels") and (
                int(self.latent_kernels) != 1 or self.coupling_validation is True):
            raise InputError("GPConfig.output_groups='kernels' gives each output group its own kernel: it needs "
                             "latent_kernels=1 and coupling_validation=False")
        if int(self.hyper_stride) < 0:
            raise InputError(f"GPConfig.hyper_stride must be >= 0 (0: from the residual's decorrelation time), got "
                             f"{self.hyper_stride!r}")
        if self.coupling not in ("learned", "off"):
            raise InputError(f"GPConfig.coupling must be 'learned' or 'off', got {self.coupling!r}")
        if self.coupling == "off" and (self.coupling_validation is True or self.output_groups == "kernels-free"):
            raise InputError("GPConfig.coupling='off' removes the coupling: it cannot go with coupling_validation=True "
                             "or output_groups='kernels-free'")
        if self.coupling_rows not in ("subset", "all"):
            raise InputError(f"GPConfig.coupling_rows must be 'subset' or 'all', got {self.coupling_rows!r}")
        if self.coupling_test not in ("none", "lr"):
            raise InputError(f"GPConfig.coupling_test must be 'none' or 'lr', got {self.coupling_test!r}")
        if self.noise_posterior not in ("full", "diagonal"):
            raise InputError(f"GPConfig.noise_posterior must be 'full' or 'diagonal', got {self.noise_posterior!r}")
        if self.noise_start not in ("signal", "noise"):
            raise InputError(f"GPConfig.noise_start must be 'signal' or 'noise', got {self.noise_start!r}")
        if self.inducing not in ("mi", "kmeans", "random"):
            raise InputError(f"GPConfig.inducing must be 'mi', 'kmeans' or 'random', got {self.inducing!r}")
        if not (self.learning_rate > 0 and self.local_learning_rate > 0 and self.jitter > 0 and self.prior_std >= 0
                and self.tol >= 0):
            raise InputError("GPConfig: learning rates and jitter must be > 0, prior_std and tol >= 0")

    @property
    def gates_coupling(self) -> bool:
        """Whether ``fit_gp`` runs the coupling gate (``coupling_validation``; ``None``: wherever it applies,
        i.e. not with the per-group kernels of ``output_groups``)."""
        if self.coupling == "off":
            return False
        if self.coupling_validation is None:
            return self.output_groups not in ("kernels", "kernels-free", "output-kernels")
        return bool(self.coupling_validation)

    def to_dict(self) -> dict:
        """JSON-able settings."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "GPConfig":
        """Inverse of :meth:`to_dict`; unknown keys are ignored (files from newer versions)."""
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in known})
