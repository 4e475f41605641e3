"""Differential diagnosis: what the model never captured against what changed since the reference flight.

A model fitted on a reference flight and held against a new flight leaves two kinds of residual:

- **model inadequacy**: structure the model never had; it is in the reference flight's residual
  too (a term outside the fit's vocabulary, a tabulated stall break, a sensor calibration that was
  already wrong). It is not news about the aircraft; it is the extension the model needs.
- **a change**: something that is in the new flight and not in the reference (damage, icing, a
  CG shift, a sensor that drifted, a surface that failed), often with an onset inside the flight.

:func:`differential` takes the diagnosis of the new flight (:func:`gcs_sysid.diagnose.core.diagnose`)
and the reference flight(s), each turned into the same coefficient table and residual against the
*same* model. Every finding of the new flight is re-estimated on each reference with the same
correction (an aero term by least squares on the reference residual, coloured-residual standard
errors, Morelli and Klein sec. 5.3; any other cause by its own fit in
:mod:`gcs_sysid.diagnose.candidates`) and compared, in units of its correction from the model's
(or airframe's) value:

- present in every reference with a consistent size (significant there, ``|t| >= 3``, and
  ``|c_flight - c_ref| <= 3 sqrt(se_f^2 + se_r^2) + 0.25 |c_flight|``): **model inadequacy**;
  reported with where in the envelope it acts (the regressors of the term, the 10-90 % range of the
  rows where its contribution is at least half its largest), how large (RMS of the contribution,
  percent of the measured coefficient), and the extension (the term and the value that fixes it,
  the inverse-variance mean of flight and references);
- otherwise **changed**: it stays a named finding, with ``evidence.differential`` giving the
  reference value and the change, and an onset where it has one. Telemetry faults and coefficient-
  level stuck surfaces carry their own onset; for the others the onset is found by a change-point
  in the cause's amplitude over 4-s blocks (each block's least-squares amplitude of the finding's
  own correction; a step from about 0 to the full amplitude, accepted when it lowers the weighted
  squared error by at least ``min_step_chi2`` against "present from the start").

Between-flight allowances (issue 9): an aero finding that is only an offset of its coefficient
(:func:`offset_allowance`: the term refitted with a free constant is not significant or gains less
than ``min_gain_pct`` beyond it on the held-out rows; ``C:1`` always) and, with two or more
references, a correction within the references' own flight-to-flight spread, are not named; they are
listed under ``allowance``. ``wind`` is the coefficient-domain correction to the wind the estimator
reconstructed (a real wind is reconstructed and is no cause): the same correction in the references is
a systematic air-data error (``model_inadequacy``); only a correction of this flight alone is named.

Structure the residual GP (:mod:`gcs_sysid.diagnose.residual_gp`) finds in the new flight is
compared the same way: structured in the same coefficient in a reference too means model
inadequacy outside the library (with its region), structured only in the new flight means an
unexplained change. Neither ever gets a cause name.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from ..errors import SysidError
from .context import DiagContext
from .regression import ols
from .residual_gp import residual_structure
from .terms import term_factors, term_matrix
from .uncertainty import block_jackknife_cov

__all__ = ["Reference", "DifferentialOptions", "differential", "offset_allowance", "beta_scale_allowance",
           "angle_scale_allowance", "angle_error_allowance", "force_moment_allowance", "FORCE_MOMENT_ARMS",
           "block_jackknife_se",
           "BETA_COEFFICIENTS", "ANGLE_COEFFICIENTS",
           "onset_of_change", "fit_record", "reference_logs"]


@dataclass
class Reference:
    """A reference flight (the one the model was fitted on, or another flight of the same aircraft).

    Attributes:
        table: its :class:`~gcs_sysid.aero.table.CoefficientTable`.
        states: its FlightStates (needed for the causes that use states: inertia, CG, wind); optional.
        flight: its decoded Flight (for sensor causes judged by data compatibility); optional.
        label: how it is named in the report (the log's file name).
    """

    table: object
    states: object = None
    flight: object = None
    label: str = "reference"
    extra: dict = field(default_factory=dict)


#: :class:`DifferentialOptions` field -> the key of :data:`gcs_sysid.diagnose.sparse.THRESHOLDS` it is read from
_THRESHOLD_KEYS = {
    "allowance_on_search_residual": "allowance_on_search_residual", "angle_scale_se": "angle_scale_se",
    "alpha_scale": "alpha_scale_allowance", "delay_same_fit": "delay_reference_same_fit",
    "delay_change_min_t": "delay_change_min_t", "delay_se_central": "delay_se_central",
    "alpha_jackknife_s": "alpha_jackknife_s", "angle_error_along": "angle_error_along_term",
    "force_moment_arm_max": "force_moment_arm_max", "scale_beta_allowance": "scale_beta_allowance",
    "scale_wind_axis": "side_force_wind_axis", "angle_error_beside_named": "angle_error_beside_named",
    "beta_scale_type_b": "beta_scale_type_b", "estimate_beyond_scale": "estimate_beyond_angle_scale",
    "angle_error_parents": "angle_error_parents", "estimate_beyond_error": "estimate_beyond_angle_error",
}


@dataclass(frozen=True)
class DifferentialOptions:
    """The switches of :func:`differential`'s between-flight allowances, one per key of the frozen thresholds
    (:data:`gcs_sysid.diagnose.sparse.THRESHOLDS`, named in brackets), so the sparse search and the differential
    step of one diagnosis read the same mapping (:meth:`from_thresholds`).

    Attributes:
        allowance_on_search_residual: a term the sparse search named is judged for the allowances on the search's
            differential residual (``differential``'s ``search_residual``), not on the raw residual against the
            model (``allowance_on_search_residual``).
        angle_scale_se: carry the fitted angle scale's standard error into the scale allowances
            (:func:`angle_scale_allowance`; ``angle_scale_se``).
        alpha_scale: also judge a finding in alpha against a between-flight scale of the measured angle of attack
            seen in the other longitudinal coefficients; the sideslip's is always judged (``alpha_scale_allowance``).
        delay_same_fit: a delay the sparse search sized as a difference (``evidence.delay_differential``) is compared
            with each reference by the same fit (:func:`_reference_delay`), the flight's own delay against the
            reference's (``delay_reference_same_fit``; added 2026-11-22, branch i9-delay). Off: the reference's delay
            by the catalogue's scan (:func:`gcs_sysid.diagnose.candidates.fit_delays`), whose grid starts at one
            sample, so a reference without a delay reads one sample (0.02 s at 50 Hz) with a standard error of a
            minimum on the grid's edge, and the flight's *change* was held against it.
        delay_change_min_t: with ``delay_same_fit``, a delay whose change against the reference (its estimate) is
            below this many of its standard errors (time resolution included) is an allowance, not a change
            (``delay_change_min_t``; added 2026-11-22 13:20 UTC, branch i9-delay, after the first freeze: the PA-28
            s1 2-m/s pitot bias got a 0.010 +- 0.006 s delay beside it); 0: off.
        delay_se_central: with ``delay_same_fit``, the reference's delay standard error by a central difference about
            its best delay, as the flight's (``delay_se_central``; ``sparse._refine_delay``).
        alpha_jackknife_s: block length, s, of the block-jackknife standard error with which a finding in alpha is
            also judged beyond the alpha scale (:func:`angle_scale_allowance` ``jackknife``, the first reference's
            slope included); 0: off (``alpha_jackknife_s``).
        angle_error_along: the air angles (``"beta"``) against whose error along a finding's own term each aero
            finding of that angle's coefficients is also judged (:func:`angle_error_allowance`;
            ``angle_error_along_term``; eleventh session, branch i9-b747); (): off.
        force_moment_arm_max: a moment finding (Cl, Cm, Cn) beside named findings that change forces only is also
            judged beyond those force changes' moment about the CG, each with a free arm of at most this many
            reference lengths (:func:`force_moment_allowance`; ``force_moment_arm_max``; twelfth session, branch
            i9-second); 0: off.
        scale_beta_allowance: also judge a ``scale:<coef>`` finding of a sideslip coefficient (``scale:CY``) against a
            between-flight scale of the measured sideslip (:func:`angle_scale_allowance` with the finding's own
            column, :func:`_scale_column`), as a ``CY:beta`` finding is (``scale_beta_allowance``; eighteenth
            session, branch i9-c684). A sideslip scale ``1 + s`` moves CY by ``s beta dCY/dbeta``, which on an
            airframe whose side force is mostly its sideslip slope is ``s`` times the model's CY: the column of
            ``scale:CY``; before, only a finding named ``CY:beta`` was judged so, and the c684's clean seed 13 named
            ``scale:CY`` 1.146 where its sideslip read 8 % smaller against the truth than the reference's.
        scale_wind_axis: a scale's column in the search's convention (``side_force_wind_axis``;
            :func:`gcs_sysid.diagnose.sparse.scale_columns`).
        angle_error_beside_named: the angle's error along a finding's term (``angle_error_along``) is fitted on the
            other coefficients with the other named aero findings' terms there free (:func:`_named_columns`,
            ``beside`` of :func:`angle_scale_allowance`; ``angle_error_beside_named``, nineteenth session, branch
            i9-ultra), on ``differential``'s ``search_residual`` where given for a search finding.
        beta_scale_type_b: the type-B standard uncertainty of the sideslip's between-flight scale (``scale_type_b``
            of :func:`angle_scale_allowance`; ``beta_scale_type_b``); 0: none.
        estimate_beyond_scale: causes (``"scale:CY"``) whose kept finding reports its change beyond the air angle's
            between-flight scale, the estimate its naming was judged on (:func:`report_beyond_scale`;
            ``estimate_beyond_angle_scale``); (): every finding keeps its selected estimate.
        angle_error_parents: the angle's error along a finding's term (``angle_error_along``) is judged with the
            terms the finding entered the search with (``evidence.entered_with``: ``beta`` beside ``Cl:alpha*beta``)
            fitted beside it, as the offset and scale allowances and the jackknife judge it (``angle_error_parents``;
            sixtieth session). False: the term alone there (before).
        estimate_beyond_error: coefficients (``("Cl", "Cn")``) whose kept findings report their change beyond the
            sideslip's error along their own term, the estimate the along-term allowance refitted
            (:func:`report_beyond_angle_error`; ``estimate_beyond_angle_error``, sixty-first session); (): every
            finding keeps its selected estimate.
    """

    allowance_on_search_residual: bool
    angle_scale_se: bool
    alpha_scale: bool
    delay_same_fit: bool
    delay_change_min_t: float
    delay_se_central: bool
    alpha_jackknife_s: float
    angle_error_along: tuple
    force_moment_arm_max: float
    scale_beta_allowance: bool
    scale_wind_axis: bool
    angle_error_beside_named: bool
    beta_scale_type_b: float
    estimate_beyond_scale: tuple
    angle_error_parents: bool
    estimate_beyond_error: tuple

    @classmethod
    def from_thresholds(cls, overrides: dict | None = None) -> DifferentialOptions:
        """The options read from the frozen thresholds (:data:`gcs_sysid.diagnose.sparse.THRESHOLDS`, as they are at
        the call) with ``overrides`` (keys of that mapping) on top; the keys the differential step does not read
        are ignored, as :func:`gcs_sysid.diagnose.sparse.sparse_search` ignores this step's.

        Raises:
            KeyError: a key this step reads is missing from the thresholds (a mapping patched by hand).
        """
        from .sparse import THRESHOLDS

        th = dict(THRESHOLDS, **(overrides or {}))
        kinds = {"bool": bool, "float": float, "tuple": lambda v: tuple(v or ())}   # the fields' annotations

        return cls(**{f.name: kinds[f.type](th[_THRESHOLD_KEYS[f.name]]) for f in fields(cls)})


def _null_value(cause: str, airframe) -> float:
    """The value of a cause's headline estimate that means "nothing there"."""
    if cause == "mass":
        return float(airframe.mass)
    if cause.startswith("inertia:"):
        return float(getattr(airframe, cause[8:]))
    if cause.startswith("scale:"):
        return 1.0
    return 0.0


def _refit_aero(ctx: DiagContext, R: np.ndarray, coef: str, term: str) -> tuple[float, float] | None:
    """Correction (and std error) of ``coef:term`` fitted on a residual; None when the term is not excited."""
    j = COEFFICIENTS.index(coef)
    if not ctx.active[j]:
        return None
    try:
        phi = term_matrix(ctx.X, [term])[:, 0]
    except SysidError:                  # a term outside the vocabulary (a breakpoint of the sparse search)
        return None
    m = ctx.valid & np.isfinite(R[:, j]) & np.isfinite(phi)
    if m.sum() < 50 or np.std(phi[m]) == 0 and term != "1":
        return None
    res = ols(phi[m, None], R[m, j], terms=[term])
    return float(res.theta[0]), float(res.std_error[0])


def _refit_other(ctx: DiagContext, R: np.ndarray, finding: dict, ref: Reference, airframe) -> tuple | None:
    """Headline estimate (and std error) of a non-aero cause on the reference, by its own fit."""
    from .candidates import Scorer, fit_delays, fit_sensor_causes

    cause = finding["cause"]
    if finding.get("evidence", {}).get("domain") == "data compatibility":
        if ref.flight is None or ref.states is None:
            return None
        from .core import _compat_findings

        cands = _compat_findings(ctx, ref.flight, ref.states, airframe, 0.0, 0.0)
        hit = [c for c in cands if c["cause"] == cause]
        return (float(hit[0]["estimate"]), float(hit[0]["std_error"])) if hit else None
    scorer = Scorer(ctx, R, None)
    cands = fit_delays(ctx, R, scorer) if cause.startswith("delay:") else fit_sensor_causes(ctx, R, scorer)
    hit = [c for c in cands if c.cause == cause]
    if not hit or not np.isfinite(hit[0].std_error):
        return None
    return float(hit[0].estimate), float(hit[0].std_error)


def _with_parents(parents) -> str:
    """The words an allowance's ``why`` gives a finding judged with its parents beside it ("" without)."""
    return f" (with {', '.join(parents)} beside it, which it entered the search with)" if parents else ""


def _parent_columns(X: np.ndarray, parents) -> np.ndarray:
    """(T, k) the columns of the terms a finding entered the search with (``evidence.entered_with``); (T, 0) none."""
    if not parents:
        return np.zeros((len(X), 0))
    return np.asarray(term_matrix(X, list(parents)), float).reshape(len(X), -1)


def offset_allowance(X: np.ndarray, R: np.ndarray, train: np.ndarray, test: np.ndarray, coef: str, term: str,
                     min_t: float = 3.0, min_gain_pct: float = 10.0, column: np.ndarray | None = None,
                     parents=()) -> dict:
    """Is an aero finding more than a between-flight offset of its coefficient?

    Flights of one aircraft differ by near-constant coefficient offsets that are no cause (the
    reconstruction's angle-of-attack offset, ``CZ_alpha d_alpha``; weight and CG within their tolerance
    at one trim speed; an engine's torque at one power setting). The finding's term is refitted on the
    selection rows together with a free constant, ``r_j ~ c + theta phi`` (coloured-residual standard
    error, Morelli and Klein sec. 5.3), and scored on the held-out rows against the constant alone.
    It is more than an offset when the term is not the constant, ``|theta| >= min_t se`` and the
    held-out gain beyond the constant is at least ``min_gain_pct``.

    Args:
        X: (T, 10) regressors. R: (T, 6) residual without the finding (measured minus model).
        train, test: (T,) selection and held-out rows. coef, term: the finding (``"CZ"``, ``"alpha"``).
        min_t, min_gain_pct: the tests above.
        column: (T,) the finding's own column where ``term`` is no vocabulary monomial (``scale:CY``: the model's
            side force, :func:`_scale_column`); None: ``term_matrix(X, [term])``.
        parents: vocabulary terms the finding entered the sparse search with (its ``evidence.entered_with``:
            ``alpha`` beside ``alpha^2``, ``sparse.THRESHOLDS["power_with_parent"]``): fitted beside the term, the
            gain beyond the offset is the term's and theirs together (a curvature about a shifted zero is
            ``k x^2 - 2 k e x``; without its parent the term alone reads a fraction of ``k``). () (the default): the
            term alone.

    Returns:
        ``{"offset_only": bool, "estimate", "std_error", "t", "gain_beyond_offset_percent", "why"}``.
    """
    j = COEFFICIENTS.index(coef)
    if term == "1":
        return {"offset_only": True, "why": f"{coef}:1 is a between-flight offset of {coef}"}
    try:
        phi = np.asarray(column, float) if column is not None else term_matrix(X, [term])[:, 0]
    except SysidError:                  # a term outside the vocabulary: the search fitted its own constant
        return {"offset_only": False, "why": "term outside the vocabulary (the sparse search's own constant)"}
    P = _parent_columns(X, parents)
    r = R[:, j]
    ok = np.isfinite(r) & np.isfinite(phi) & np.isfinite(P).all(axis=1)
    tr, te = train & ok, test & ok
    if tr.sum() < 50 or te.sum() < 20 or np.std(phi[tr]) == 0:
        return {"offset_only": True, "why": f"{term} does not vary on these rows: an offset of {coef}"}
    res = ols(np.column_stack([np.ones(tr.sum()), phi[tr], P[tr]]), r[tr], terms=["1", term, *parents])
    c, th, se = float(res.theta[0]), float(res.theta[1]), float(res.std_error[1])
    b = float(np.sqrt(np.mean((r[te] - np.mean(r[tr])) ** 2)))
    a = float(np.sqrt(np.mean((r[te] - c - th * phi[te] - P[te] @ res.theta[2:]) ** 2)))
    gain = 100.0 * (1.0 - a / b) if b > 0 else 0.0
    t = th / se if se > 0 else 0.0
    only = abs(t) < min_t or gain < min_gain_pct
    with_p = _with_parents(parents)
    why = (f"with {coef}'s between-flight offset free, {coef}:{term}{with_p} is {th:+.4g} +- {se:.2g} (t {t:.1f}) "
           f"and gains {gain:.0f} % on the held-out rows beyond the offset")
    return {"offset_only": bool(only), "estimate": th, "std_error": se, "t": float(t),
            "gain_beyond_offset_percent": float(gain), "why": why}


#: The lateral coefficients a sideslip-measurement scale acts on through the model's beta terms.
BETA_COEFFICIENTS = ("CY", "Cl", "Cn")
#: The coefficients a scale error of each measured air angle acts on through the model's terms in it:
#: the sideslip's lateral ones, and the angle of attack's longitudinal ones (lift, drag, pitch).
ANGLE_COEFFICIENTS = {"beta": BETA_COEFFICIENTS, "alpha": ("CX", "CZ", "Cm")}


def _angle_factors(term: str) -> list[str]:
    """Regressor names among a monomial's factors (``alpha^2*delta_e`` -> alpha, delta_e; others: [])."""
    if "(" in term or ":" in term:
        return []
    return [part.partition("^")[0] for part in term.replace(" ", "").split("*")]


def block_jackknife_se(t: np.ndarray, phi: np.ndarray, r: np.ndarray, rows: np.ndarray, block_s: float,
                       beside: np.ndarray | None = None) -> float:
    """Block-jackknife standard error of the slope of ``r`` on ``phi`` (a free constant beside it).

    The rows are cut into contiguous blocks of ``block_s`` seconds; the slope is refitted with each block
    left out, ``theta_i``, and ``se^2 = (B - 1)/B sum (theta_i - mean theta)^2`` (the delete-a-block
    jackknife for dependent observations: Kuensch, *Ann. Statist.* 17 (1989) 1217-1241; Efron and
    Tibshirani, *An Introduction to the Bootstrap*, 1993, ch. 11). Unlike the coloured-residual standard
    error (Morelli and Klein sec. 5.3), which holds the regressor fixed, it also carries a slowly varying
    error of the *regressor* (a measured air angle that misses slow gusts) whose chance alignment with the
    flight's manoeuvres moves the slope.

    Args:
        t: (T,) time, s. phi: (T,) regressor. r: (T,) response. rows: (T,) bool rows to use.
        block_s: block length, s. beside: (T, k) columns fitted beside ``phi`` (a finding's parents,
            :func:`offset_allowance` ``parents``); None: the constant only.

    Returns:
        the standard error (same units as the slope); NaN with fewer than 3 blocks of 50 rows or more
        (:func:`gcs_sysid.diagnose.uncertainty.block_jackknife_cov`, whose slope entry it is).
    """
    B = np.zeros((len(phi), 0)) if beside is None else np.asarray(beside, float).reshape(len(phi), -1)
    rows = np.asarray(rows, bool) & np.isfinite(phi) & np.isfinite(r) & np.isfinite(B).all(axis=1)
    # the slope's entry of the general delete-a-block covariance (a constant column beside the regressor:
    # the same blocks, thresholds and leave-one-out fits; agrees with the centred-slope form to 1e-13)
    cov = block_jackknife_cov(t[rows], np.column_stack([np.ones(int(rows.sum())), phi[rows], B[rows]]), r[rows],
                              block_s)
    return float(np.sqrt(cov[1, 1])) if cov is not None else float("nan")


def angle_scale_allowance(X: np.ndarray, R: np.ndarray, train: np.ndarray, test: np.ndarray, model, coef: str,
                          term: str, angle: str = "beta", min_t: float = 3.0, min_gain_pct: float = 10.0,
                          scale_se: bool = True, jackknife: dict | None = None,
                          along_term: bool = False, column: np.ndarray | None = None,
                          beside: dict | None = None, parents=(), witness_exclude=(),
                          scale_type_b: float = 0.0) -> dict | None:
    """Is a finding in an air angle more than a between-flight *scale* of that measured angle?

    The log's air angles are estimates whose scale differs from flight to flight: the reconstruction
    (GPS velocity minus the wind estimate, aided by the specific force through a slope fitted on each
    flight, :mod:`gcs_sysid.estimation.airangles`) reads the JSBSim SGS's sideslip 0.6 % small on its
    reference flight and 3.0 % small on clean seed 15, the PA-28's angle of attack 3.1 % large on its
    reference and 3.0 % small on clean seed 14 (``docs/benchmarks.md``, branch i9-clean). A scale
    ``1 + s`` of the angle moves *every* coefficient of :data:`ANGLE_COEFFICIENTS` by ``s`` times the
    model's own contribution of the angle, ``n_j = x dC_j/dx``; a change of one coefficient's
    aerodynamics moves that coefficient alone. So ``s`` is fitted on the *other* coefficients of the
    group (those with a contribution; offsets free, each weighted by its residual variance on the
    selection rows; coloured-residual standard error, Morelli and Klein sec. 5.3), the finding's
    coefficient is corrected by ``s n_j``, and :func:`offset_allowance` judges what is left.

    With ``scale_se`` the scale's own uncertainty is carried into that judgement (added 2026-11-22,
    branch i9-clean): the term's estimate beyond the scale moves by ``k ds`` for an error ``ds`` of
    ``s``, ``k`` the slope of ``n_j`` on the term (a free constant beside it, selection rows), so its
    standard error is ``sqrt(se^2 + (k se_s)^2)`` (first-order propagation of independent errors;
    the other coefficients' residuals are not the finding's). Without it a scale known to +- 1.2 %
    from the moments left a 2.4 % CY:beta "change" at 7 standard errors.

    Args:
        X: (T, 10) regressors. R: (T, 6) residual without the finding. train, test: (T,) rows.
        model: the model under test (:data:`~gcs_sysid.diagnose.context.ModelDict`).
        coef, term: the finding; judged only when ``coef`` is in ``ANGLE_COEFFICIENTS[angle]`` and
            ``angle`` is among the term's factors.
        angle: ``"beta"`` or ``"alpha"``.
        min_t, min_gain_pct: as :func:`offset_allowance`.
        scale_se: carry the scale's standard error into the term's (see above).
        along_term: the angle's error is ``s phi`` along the finding's own term ``phi`` instead of ``s x``
            (a scale): :func:`angle_error_allowance` (eleventh session, branch i9-b747). Then ``angle``
            need not be among the term's factors, ``n_j = phi dC_j/dx`` and the document's keys read
            ``error_along_term`` (``scale`` is ``s``, in radians per unit of the term: the true angle is the
            measured one plus ``s phi``, as the scale's ``1 + s`` multiplies the measured angle).
        beside: ``{coef: (T, k) columns}``: the other named findings' own columns in the *other* coefficients the
            angle's error is fitted on; each is partialled out of that coefficient's residual and contribution first
            (Frisch-Waugh-Lovell: the error fitted jointly with free slopes of those findings), so a real change named
            there is not read as the angle's error (``sparse.THRESHOLDS["angle_error_beside_named"]``; nineteenth
            session, branch i9-ultra: the ultrastick's ``Cn:delta_a`` flights named ``CY:p_hat`` beside it). None:
            as before.
        column: (T,) the finding's own column where ``term`` is no vocabulary monomial: ``scale:CY`` judged against
            a between-flight scale of the measured sideslip (:func:`_scale_column`; eighteenth session, branch
            i9-c684); the angle need not be among the term's factors then. None: ``term_matrix(X, [term])``.
        jackknife: ``{"t": (T,) s, "block_s": s, "reference": (t_r, X_r, R_r, rows_r) or None}``: the term
            beyond the scale is also judged with the block-jackknife standard error
            (:func:`block_jackknife_se`) of this flight's slope and of the reference flight's (the model's
            value is the reference's estimate, so a change carries both), in quadrature; the larger of that
            and the standard error above is used (added 2026-11-22, branch i9-delay:
            ``sparse.THRESHOLDS["alpha_jackknife_s"]``).
        parents: the terms the finding entered the search with, fitted beside it in the judgement beyond the
            scale (:func:`offset_allowance`), its scale share and its jackknife. (): the term alone.
        witness_exclude: coefficients the angle's scale is *not* fitted on although in its group: those whose
            measured target differs in kind between this flight and the reference (the reference's Cl at the
            air-relative roll rate, the flight's at the gyro's: :func:`gcs_sysid.diagnose.air_roll.moved_targets`),
            whose residual then carries the rolling gust's moment, which follows the sideslip through the lateral
            dynamics (fiftieth session: on the JSBSim SGS 1-23's clean seed 21 Cl and Cn read a sideslip scale
            1.035 +- 0.047 that way, 0.885 +- 0.04 with both flights at the gyro's rate, so ``scale:CY`` 0.865 was
            named; Cn alone reads 0.955 +- 0.048 either way).
            (): every coefficient of the group with a contribution.
        scale_type_b: a type-B standard uncertainty of the fitted scale ``s`` (dimensionless), added in quadrature
            to its fitted standard error (JCGM 100:2008 sec. 4.3 and eq. 10) before ``scale_se`` carries it; the
            scale's fit treats the witnesses' residual as noise, while what moves ``s`` is the part of that residual
            which follows the angle (gusts, a witness's own inadequacy), common to the whole flight: on the JSBSim
            roster's ``CY:scale`` flights the fitted sideslip scale lies 0.039-0.044 RMS from JSBSim's, against a
            median stated 0.012 (``docs/benchmarks.md``, *Forty-fourth session, lead*). Not applied ``along_term``
            (whose ``s`` is in radians per unit of the term). 0: the fit's standard error alone.

    Returns:
        None when the finding is not such a term or no other coefficient has a contribution of the
        angle; else ``{"scale_only": bool, "angle", "scale", "std_error", "from": [coef...],
        "beyond_scale": {...}, "why"}`` (``beyond_scale`` is :func:`offset_allowance`'s document, with
        ``std_error_scale_share`` and the propagated ``std_error``/``t`` when ``scale_se``).

    Raises:
        KeyError: ``angle`` other than ``"alpha"`` or ``"beta"``.
    """
    from .context import evaluate_model

    group = ANGLE_COEFFICIENTS[angle]
    if coef not in group or (not along_term and column is None and angle not in _angle_factors(term)):
        return None
    ia = REGRESSORS.index(angle)
    eps = 1e-3
    X1 = np.array(X, float, copy=True)
    if along_term:
        try:
            phi_e = term_matrix(X, [term])[:, 0]
        except SysidError:              # a term outside the vocabulary (lag, hinge): nothing to align with
            return None
        if not np.isfinite(phi_e).any() or np.nanstd(phi_e) == 0:
            return None
        d = eps / float(np.nanstd(phi_e))       # an angle error of 1e-3 rad at one standard deviation of phi
        X1[:, ia] += d * np.nan_to_num(phi_e)
        N = (evaluate_model(model, X1) - evaluate_model(model, X)) / d      # (T, 6): phi dC/dx
    else:
        X1[:, ia] *= 1.0 + eps
        N = (evaluate_model(model, X1) - evaluate_model(model, X)) / eps    # (T, 6): x dC/dx
    ok = train & np.isfinite(R).all(axis=1) & np.isfinite(N).all(axis=1)
    others = [c for c in group if c != coef and c not in witness_exclude and np.std(N[ok, COEFFICIENTS.index(c)]) > 0]
    if ok.sum() < 50 or not others:
        return None
    num = den = 0.0
    cols = []
    for c in others:
        j = COEFFICIENTS.index(c)
        r, n = R[ok, j] - R[ok, j].mean(), N[ok, j] - N[ok, j].mean()
        B = (beside or {}).get(c)
        if B is not None and np.size(B):
            B = np.nan_to_num(np.asarray(B, float).reshape(len(X), -1)[ok])
            B = np.column_stack([np.ones(len(B)), B])
            r = r - B @ np.linalg.lstsq(B, r, rcond=None)[0]
            n = n - B @ np.linalg.lstsq(B, n, rcond=None)[0]
        w = 1.0 / max(float(np.var(r)), 1e-30)
        num, den = num + w * float(n @ r), den + w * float(n @ n)
        cols.append((r * np.sqrt(w), n * np.sqrt(w)))
    if den <= 0:
        return None
    s_hat = num / den
    res = ols(np.concatenate([n for _, n in cols])[:, None], np.concatenate([r for r, _ in cols]), terms=["s"])
    se_s_fit = float(res.std_error[0])
    se_s = float(np.hypot(se_s_fit, scale_type_b)) if scale_type_b > 0 and not along_term else se_s_fit
    j = COEFFICIENTS.index(coef)
    R_adj = np.array(R, float, copy=True)
    R_adj[:, j] = R[:, j] - s_hat * N[:, j]
    beyond = offset_allowance(X, R_adj, train, test, coef, term, min_t=min_t, min_gain_pct=min_gain_pct,
                              column=column, parents=parents)
    if scale_se and "std_error" in beyond and np.isfinite(se_s):
        try:
            phi = np.asarray(column, float) if column is not None else term_matrix(X, [term])[:, 0]
        except SysidError:
            phi = None
        P = _parent_columns(X, parents)
        m = ok & np.isfinite(phi) & np.isfinite(P).all(axis=1) if phi is not None else ok[:0]
        if phi is not None and m.sum() >= 50 and np.std(phi[m]) > 0:
            k = float(np.linalg.lstsq(np.column_stack([np.ones(m.sum()), phi[m], P[m]]), N[m, j],
                                      rcond=None)[0][1])
            share = abs(k) * se_s
            se = float(np.hypot(beyond["std_error"], share))
            t = beyond["estimate"] / se if se > 0 else 0.0
            beyond = dict(beyond, std_error=se, std_error_fit=beyond["std_error"], std_error_scale_share=share,
                          t=float(t), offset_only=bool(beyond["offset_only"] or abs(t) < min_t),
                          why=(f"with {coef}'s between-flight offset free, {coef}:{term}{_with_parents(parents)} is "
                               f"{beyond['estimate']:+.4g} +- {se:.2g} (the scale's uncertainty {share:.2g} included; "
                               f"t {t:.1f}) and gains "
                               f"{beyond['gain_beyond_offset_percent']:.0f} % on the held-out rows beyond the offset"))
    if jackknife and "std_error" in beyond:
        beyond = _with_jackknife(beyond, X, R_adj[:, j], ok, term, jackknife, min_t, parents)
    if along_term:
        return {"scale_only": bool(beyond["offset_only"]), "angle": angle, "scale": float(s_hat),
                "error_along_term": float(s_hat), "term": term,
                "std_error": se_s, "std_error_fit": se_s_fit, "from": others, "beyond_scale": beyond,
                "why": f"a common {angle} error {s_hat:+.3g} +- {se_s:.2g} rad per unit of {term} (fitted on "
                       f"{', '.join(others)}) and {coef}'s offset free: "
                       f"{beyond['why'].split(': ', 1)[-1] if 'why' in beyond else ''}"}
    return {"scale_only": bool(beyond["offset_only"]), "angle": angle, "scale": float(s_hat),
            "beta_scale" if angle == "beta" else "alpha_scale": float(s_hat),
            "std_error": se_s, "std_error_fit": se_s_fit, "std_error_type_b": float(scale_type_b),
            "from": others, "beyond_scale": beyond,
            "why": f"a common {angle} scale {1 + s_hat:.3f} +- {se_s:.2g} (fitted on {', '.join(others)}) and {coef}'s "
                   f"offset free: {beyond['why'].split(': ', 1)[-1] if 'why' in beyond else ''}"}


def angle_error_allowance(X: np.ndarray, R: np.ndarray, train: np.ndarray, test: np.ndarray, model, coef: str,
                          term: str, angle: str = "beta", min_t: float = 3.0, min_gain_pct: float = 10.0,
                          scale_se: bool = True, witness_exclude=(), parents=()) -> dict | None:
    """Is a finding more than an error of the measured air angle that moves with the finding's own term?

    The scale allowance (:func:`angle_scale_allowance`) covers an angle error proportional to the angle.
    The reconstructed sideslip also carries errors that follow the flight's other states, differently on
    each flight: on the JSBSim b747 (clean seed 15, measured against the truth, ``docs/benchmarks.md``,
    *Eleventh session, i9-b747*) the aided sideslip's error has a slope of +0.136 rad per unit of
    ``r_hat`` (correlation 0.48; -0.005 on the reference flight, -0.050 on clean seed 11), and through
    ``CY_beta`` = -1.06 it reads as a ``CY:r_hat`` "change" of +0.096 at 15 standard errors; Cl and Cn
    see the same error through their own ``beta`` derivatives (their residual slopes on ``r_hat``,
    +0.017 and -0.016, are the +0.014 and -0.019 the sideslip error predicts). An error ``e = s phi`` of
    the angle along the finding's term ``phi`` moves *every* coefficient of the angle's group by
    ``-s phi dC_j/dx`` (the model's own derivatives, so in the model's ratios), while a change of one
    coefficient's aerodynamics moves that coefficient alone. So ``s`` is fitted on the *other*
    coefficients of the group and the finding judged beyond it, with ``s``'s standard error carried, exactly
    as for the scale (the scale is the case ``phi = x``).

    Args, returns: as :func:`angle_scale_allowance` (``along_term=True``); None when ``coef`` is not in the
    angle's group, the term is not a vocabulary monomial, or no other coefficient depends on the angle.
    """
    return angle_scale_allowance(X, R, train, test, model, coef, term, angle, min_t, min_gain_pct, scale_se,
                                 along_term=True, witness_exclude=witness_exclude, parents=parents)


#: The force coefficients whose moment about the CG each moment coefficient carries when the aerodynamic force
#: acts at a point off the CG, for an airframe symmetric about its x-z plane (the lateral offset of the force's
#: point of action is zero): ``L = y Z - z Y``, ``M = z X - x Z``, ``N = x Y - y X`` (body axes; Etkin and
#: Reid, *Dynamics of Flight*, 3rd ed., sec. 4.2; JSBSim transfers its aerodynamic forces from the
#: aerodynamic reference point ``AERORP`` to the CG so, ``FGAerodynamics::GetMoments``).
FORCE_MOMENT_ARMS = {"Cl": ("CY",), "Cm": ("CX", "CZ"), "Cn": ("CY",)}


def force_moment_allowance(X: np.ndarray, R: np.ndarray, train: np.ndarray, test: np.ndarray, coef: str,
                           term: str, force_change: dict, arm_max: float = 0.1, min_t: float = 3.0,
                           min_gain_pct: float = 10.0) -> dict | None:
    """Is a moment finding only the moment about the CG of a force change named beside it?

    A model fitted at the CG holds a force change and the change of that force's moment about the CG
    as separate numbers, but a real change of an aerodynamic force acts at a point of the airframe (for
    JSBSim, ``AERORP``; for a real aircraft, wherever the changed surface's load acts): a side force
    scaled by ``k`` moves ``Cl`` by ``-(z_a/b) dCY`` and ``Cn`` by ``(x_a/b) dCY`` along *every* term of
    the side force, ``z_a, x_a`` the point's offset from the CG (:data:`FORCE_MOMENT_ARMS`). On the
    JSBSim f16 (``AERORP`` 9 in above the CG: 0.025 b) a ``CY:scale`` of 1.6 moves the exact
    ``Cl_beta`` from -0.1133 to -0.1268 and ``Cl_r`` from 0.114 to 0.130 (ratio to the CY changes
    0.020-0.023), which the diagnosis named as a second cause ``Cl:beta`` (twelfth session, branch
    i9-second, ``docs/benchmarks.md``). So the finding's coefficient is fitted jointly on a free
    constant, the named force changes ``dF_k(t)`` (one free arm ``a_k`` each, in the moment's reference
    length per unit force coefficient) and the finding's term ``phi``; the finding is the force's moment
    when its term is not significant beyond them (``|theta| < min_t se``, coloured-residual standard
    error of the joint fit, Morelli and Klein sec. 5.3) or gains less than ``min_gain_pct`` on the held-out
    rows beyond the offset and the arms (:func:`offset_allowance` on the residual less ``sum a_k dF_k``),
    and every arm is within ``arm_max`` reference lengths of the CG (a point of action inside the airframe).

    Args:
        X: (T, 10) regressors. R: (T, 6) residual without the finding (measured minus model).
        train, test: (T,) selection and held-out rows. coef, term: the finding (``"Cl"``, ``"beta"``).
        force_change: force coefficient -> (T,) the change of that force the other named findings make
            (measured minus model: minus their summed ``delta``); forces outside ``FORCE_MOMENT_ARMS[coef]``
            are ignored.
        arm_max: the largest arm, in the moment's reference length (``b`` for Cl and Cn, ``c`` for Cm).
        min_t, min_gain_pct: as :func:`offset_allowance`.

    Returns:
        None when ``coef`` is not a moment, no named finding changes a force with an arm to it, or the rows
        are too few; else ``{"moment_only": bool, "arms": {force: a}, "arms_std_error": {...}, "estimate",
        "std_error", "t", "gain_beyond_arm_percent", "why"}``.
    """
    forces = [k for k in FORCE_MOMENT_ARMS.get(coef, ())
              if k in force_change and np.nanstd(force_change[k]) > 0]
    if not forces:
        return None
    try:
        phi = term_matrix(X, [term])[:, 0]
    except SysidError:
        return None
    j = COEFFICIENTS.index(coef)
    F = np.column_stack([np.asarray(force_change[k], float) for k in forces])
    ok = np.isfinite(R[:, j]) & np.isfinite(phi) & np.isfinite(F).all(axis=1)
    tr = train & ok
    if tr.sum() < 50 or (test & ok).sum() < 20 or np.std(phi[tr]) == 0:
        return None
    res = ols(np.column_stack([np.ones(tr.sum()), F[tr], phi[tr]]), R[tr, j], terms=["1", *forces, term])
    arms = {k: float(res.theta[1 + i]) for i, k in enumerate(forces)}
    arms_se = {k: float(res.std_error[1 + i]) for i, k in enumerate(forces)}
    th, se = float(res.theta[-1]), float(res.std_error[-1])
    t = th / se if se > 0 else 0.0
    R_adj = np.array(R, float, copy=True)
    R_adj[:, j] = R[:, j] - np.nan_to_num(F) @ np.array([arms[k] for k in forces])
    beyond = offset_allowance(X, R_adj, train & ok, test & ok, coef, term, min_t=min_t, min_gain_pct=min_gain_pct)
    gain = float(beyond.get("gain_beyond_offset_percent", 0.0))
    inside = all(abs(a) <= arm_max for a in arms.values())
    only = inside and (abs(t) < min_t or gain < min_gain_pct)
    arm_txt = ", ".join(f"{k} {a:+.4f} +- {arms_se[k]:.2g}" for k, a in arms.items())
    why = (f"with the named force change's moment free (arm per reference length: {arm_txt}; largest allowed "
           f"{arm_max:g}) and {coef}'s offset free, {coef}:{term} is {th:+.4g} +- {se:.2g} (t {t:.1f}) and gains "
           f"{gain:.0f} % on the held-out rows beyond them")
    return {"moment_only": bool(only), "arms": arms, "arms_std_error": arms_se, "arm_max": float(arm_max),
            "estimate": th, "std_error": se, "t": float(t), "gain_beyond_arm_percent": gain, "why": why}


def _named_columns(diag, cause: str) -> dict:
    """Coefficient -> (T, k) the own columns of the *other* named aero findings (``"Cn:delta_a"`` -> ``delta_a``).

    For :func:`angle_scale_allowance`'s ``beside``: the JSBSim ultrastick's ``Cn:delta_a`` = -0.06 flights (seeds 2
    and 3) also named ``CY:p_hat`` +0.106 and +0.115: against the truth the aided sideslip's error follows ``p_hat``
    with a slope of 1.24-1.27 there and 0.785 on the reference (so ``-CY_beta`` x 0.47 = +0.088 in CY and
    ``-Cn_beta`` x 0.47 = -0.025 in Cn, read -0.032..-0.036). The error along ``p_hat`` is fitted on Cn, whose
    residual also holds the named ``delta_a`` change (correlated with ``p_hat`` through the roll response): left
    in, it biases the error's fit. Terms outside the vocabulary (lags, hinges, ``scale:``) are left out, and so is a
    finding of the judged finding's own term: there the other coefficient's change *is* what the angle's error
    along that term would make, and partialled out it leaves the error to the coefficients that barely see it
    (ultrastick seed 1, ``CY:delta_a`` and ``Cn:delta_a`` both named: the error then came from Cl alone and
    removed ``Cn:delta_a``).
    """
    cols: dict = {}
    own = cause.split(":", 1)[1] if ":" in cause else None
    for f in diag.findings:
        c = f.get("coefficient")
        if f["cause"] == cause or f.get("kind") == "fault" or f["cause"].split(":")[0] not in COEFFICIENTS \
                or f["cause"].split(":", 1)[1] == own:
            continue
        try:
            phi = term_matrix(diag.X, [f["cause"].split(":", 1)[1]])[:, 0]
        except SysidError:
            continue
        cols.setdefault(c, []).append(phi)
    return {c: np.column_stack(v) for c, v in cols.items()}


def _force_changes(diag, fitted: dict, cause: str, wind_axis: bool) -> dict:
    """Force coefficient -> (T,) change (measured minus model) of the *other* named aero findings of a force.

    A finding of CX, CY or CZ (an aero term or ``scale:<force>``) changes that force only, as the diagnosis
    names it: its change is the sum of its terms' estimates times their columns (``evidence.terms`` of the
    sparse search; ``scale:C`` is :func:`gcs_sysid.diagnose.sparse.scale_columns`'s column), or minus its fitted
    ``delta`` (a catalogue term). Findings of other kinds (delays, sensors, faults) move the moments through
    their own paths and are left out. ``wind_axis``: the scale's column in the search's convention
    (:attr:`DifferentialOptions.scale_wind_axis`). Returns {} when there is none.
    """
    from .context import evaluate_model
    from .sparse import scale_columns

    out: dict = {}
    cols = None
    for f in diag.findings:
        c = f.get("coefficient")
        if f["cause"] == cause or c not in ("CX", "CY", "CZ") or f.get("kind") == "fault":
            continue
        if f["cause"].split(":")[0] not in COEFFICIENTS and not f["cause"].startswith("scale:"):
            continue
        terms = f.get("evidence", {}).get("terms")
        d = None
        if terms:
            d = np.zeros(len(diag.X))
            for tm in terms:
                if tm["term"].startswith("scale:"):
                    if cols is None:
                        cols = scale_columns(evaluate_model(diag.model, diag.X), diag.X, wind_axis=wind_axis)
                    phi = cols[:, COEFFICIENTS.index(tm["term"].split(":", 1)[1])]
                else:
                    try:
                        phi = term_matrix(diag.X, [tm["term"]])[:, 0]
                    except SysidError:      # a lag or hinge term: the finding's change is not rebuilt
                        d = None
                        break
                d = d + float(tm["estimate"]) * phi
        elif f["cause"] in fitted and getattr(fitted[f["cause"]], "delta", None) is not None:
            d = -np.asarray(fitted[f["cause"]].delta, float)[:, COEFFICIENTS.index(c)]
        if d is not None and np.isfinite(d).any():
            out[c] = out.get(c, 0.0) + d
    return out


def _scale_column(model, X: np.ndarray, coef: str, wind_axis: bool = True) -> np.ndarray:
    """The column (T,) of ``scale:<coef>`` on regressors ``X`` (T, 10): what a scale of that coefficient adds per unit
    of ``k - 1`` (:func:`gcs_sysid.diagnose.sparse.scale_columns` of the model's prediction; CY: its wind-axis side
    force)."""
    from .context import evaluate_model
    from .sparse import scale_columns

    M = np.nan_to_num(evaluate_model(model, X))
    return scale_columns(M, np.nan_to_num(X), wind_axis)[:, COEFFICIENTS.index(coef)]


def _note_allowance(doc: dict, f: dict, allowance: dict, summary: str) -> None:
    """Record an aero finding judged an allowance: its ``evidence.differential`` and an entry of ``doc["allowance"]``
    (``cause coefficient estimate gain why summary``; ``why`` is the allowance document's)."""
    f["evidence"]["differential"] = {"verdict": "allowance", "allowance": allowance}
    doc["allowance"].append({"cause": f["cause"], "coefficient": f["coefficient"], "estimate": f["estimate"],
                             "gain": f.get("gain", {}), "why": allowance["why"], "summary": summary})


def _with_jackknife(beyond: dict, X: np.ndarray, r: np.ndarray, rows: np.ndarray, term: str, jk: dict,
                    min_t: float, parents=()) -> dict:
    """``beyond`` (an :func:`offset_allowance` document) judged with the block-jackknife standard error too
    (``parents``: fitted beside the term, in both flights)."""
    try:
        phi = term_matrix(X, [term])[:, 0]
    except SysidError:
        return beyond
    se_f = block_jackknife_se(np.asarray(jk["t"], float), phi, r, rows, float(jk["block_s"]),
                              _parent_columns(X, parents))
    se_r = 0.0
    if jk.get("reference") is not None:
        t_r, X_r, r_r, rows_r = jk["reference"]
        try:
            se_r = block_jackknife_se(np.asarray(t_r, float), term_matrix(X_r, [term])[:, 0], r_r, rows_r,
                                      float(jk["block_s"]), _parent_columns(X_r, parents))
        except SysidError:
            se_r = float("nan")
    if not (np.isfinite(se_f) and np.isfinite(se_r)):
        return beyond
    se_jk = float(np.hypot(se_f, se_r))
    se = max(float(beyond["std_error"]), se_jk)
    t = beyond["estimate"] / se if se > 0 else 0.0
    return dict(beyond, std_error=se, std_error_jackknife={"flight": se_f, "reference": se_r}, t=float(t),
                offset_only=bool(beyond["offset_only"] or abs(t) < min_t),
                why=beyond["why"] + f"; block jackknife (flight {se_f:.2g}, reference {se_r:.2g}): t {t:.1f}")


def beta_scale_allowance(X: np.ndarray, R: np.ndarray, train: np.ndarray, test: np.ndarray, model, coef: str,
                         term: str, min_t: float = 3.0, min_gain_pct: float = 10.0,
                         scale_se: bool = True) -> dict | None:
    """Is a sideslip finding more than a between-flight scale of the measured sideslip?

    :func:`angle_scale_allowance` with ``angle="beta"`` (the sideslip's lateral coefficients CY, Cl, Cn);
    the result also carries ``beta_scale``. Args, returns: as there.
    """
    return angle_scale_allowance(X, R, train, test, model, coef, term, "beta", min_t, min_gain_pct, scale_se)


def _within_reference_variation(c_f: float, se_f: float, compared: list[dict], k: float = 3.0) -> dict | None:
    """With two or more reference flights: is the flight's correction within their flight-to-flight spread?

    The references' own corrections ``c_r`` (each against the same model) scatter by ``s`` (sample standard
    deviation) from flight to flight with nothing changed; the flight's ``c_f`` is an allowance when
    ``|c_f - mean(c_r)| <= k sqrt(se_f^2 + s^2 + mean(se_r^2))``. None with fewer than two references or
    outside the spread.
    """
    if len(compared) < 2:
        return None
    c = np.array([x["correction"] for x in compared], float)
    se = np.array([x["std_error"] for x in compared], float)
    s = float(np.std(c, ddof=1))
    lim = k * float(np.sqrt(se_f**2 + s**2 + np.mean(se**2)))
    if abs(c_f - float(np.mean(c))) > lim:
        return None
    return {"mean_reference": float(np.mean(c)), "spread_between_references": s, "limit": lim,
            "why": f"{c_f:+.4g} against the references' {np.mean(c):+.4g} +- {s:.2g} (flight to flight): "
                   "within the variation between the reference flights"}


def _wind_fit(ctx: DiagContext, R: np.ndarray):
    """The coefficient-domain wind correction (w_N, w_E) fitted on a residual: (params (2,), cov (2, 2)) or None."""
    from .candidates import Scorer, fit_sensor_causes
    from .causes import transforms

    others = [c.cause for c in transforms(ctx) if c.cause != "wind"]
    got = fit_sensor_causes(ctx, np.nan_to_num(R), Scorer(ctx, np.nan_to_num(R), None), exclude=others)
    if not got or not np.all(np.isfinite(got[0].cov)):
        return None
    return np.asarray(got[0].params, float), np.asarray(got[0].cov, float)


def _wind_differential(f: dict, fitted, refs, min_t: float = 3.0, consistent_rel: float = 0.25) -> dict:
    """Is the flight's wind correction the same in the reference flight(s)?

    The estimator already reconstructs the wind (GPS velocity minus the air-relative velocity), so the
    catalogue's ``wind`` is a *correction* to that reconstruction: the true wind is the estimator's plus
    ``(w_N, w_E)``. A real wind that differs between flights is reconstructed and is no cause; a
    correction is news only when the reconstruction is wrong in this flight and not in the reference
    flight(s). The same correction there (significant, ``|w_r| >= min_t`` standard errors, and
    ``(w_f - w_r)^T (C_f + C_r)^-1 (w_f - w_r) <= 9`` or within ``consistent_rel |w_f|``) is a
    systematic error of the air-data reconstruction (heading or sideslip offset): a calibration note,
    not a named cause.

    Args:
        f: the finding (``evidence.parameters`` ``wn``, ``we``). fitted: its
            :class:`~gcs_sysid.diagnose.candidates.Fitted` (for the covariance) or None.
        refs: ``[(Reference, ctx, R)]`` against the same model.

    Returns:
        ``{"verdict": "changed" | "calibration" | "not compared", "why", "in_flight", "references"}``.
    """
    par = f.get("evidence", {}).get("parameters", {})
    w_f = np.array([par.get("wn", np.nan), par.get("we", np.nan)], float)
    C_f = np.asarray(fitted.cov, float) if fitted is not None and np.shape(fitted.cov) == (2, 2) \
        else np.eye(2) * float(f.get("std_error", np.nan)) ** 2
    comps = []
    for ref, ctx, R in refs:
        try:
            got = _wind_fit(ctx, R) if ctx.has("phi", "theta", "psi") else None
        except (ValueError, ArithmeticError, np.linalg.LinAlgError, SysidError):
            got = None
        if got is None or not np.all(np.isfinite(w_f)):
            comps.append({"label": ref.label, "compared": False})
            continue
        w_r, C_r = got
        d = w_f - w_r
        chi2 = float(d @ np.linalg.pinv(C_f + C_r) @ d)
        sig_r = float(np.sqrt(max(w_r @ np.linalg.pinv(C_r) @ w_r, 0.0)))
        same = sig_r >= min_t and (chi2 <= 9.0 or np.hypot(*d) <= consistent_rel * np.hypot(*w_f))
        comps.append({"label": ref.label, "compared": True, "wn_mps": float(w_r[0]), "we_mps": float(w_r[1]),
                      "t": sig_r, "chi2_difference": chi2, "same": bool(same)})
    inflight = {"wn_mps": float(w_f[0]), "we_mps": float(w_f[1]), "speed_mps": float(np.hypot(*w_f))}
    compared = [c for c in comps if c["compared"]]
    if not compared:
        return {"verdict": "not compared", "why": "no reference flight with attitude to compare the wind with",
                "in_flight": inflight, "references": comps}
    if all(c["same"] for c in compared):
        return {"verdict": "calibration", "in_flight": inflight, "references": comps,
                "why": (f"the reconstructed wind needs the same correction ({inflight['speed_mps']:.2g} m/s) in the "
                        "reference flight(s): a systematic air-data error (heading or sideslip calibration), "
                        "not this flight's air")}
    return {"verdict": "changed", "in_flight": inflight, "references": comps,
            "why": (f"the wind the estimator reconstructed is off by ({w_f[0]:+.2f}, {w_f[1]:+.2f}) m/s (N, E) in "
                    "this flight and not in the reference flight(s): the true wind is the estimator's plus this")}


def onset_of_change(t: np.ndarray, R_without: np.ndarray, delta: np.ndarray, valid: np.ndarray,
                    block_s: float = 4.0, min_step_chi2: float = 25.0, max_before: float = 0.3) -> dict:
    """When a correction starts to be needed: a step change-point in its amplitude over time blocks.

    In each block the amplitude ``a`` of the correction is fitted by least squares,
    ``R_without ~ -a delta`` (1 where the cause acts at full size, 0 where it is absent), with
    variance ``s^2 / sum(delta^2)`` from the block's scatter. A step ``a = 0`` before block ``k``
    and ``a = mean`` after is compared with "the same amplitude throughout" by the weighted squared
    error; the best ``k`` is the onset when it lowers that error by at least ``min_step_chi2`` and the
    amplitude before it is below ``max_before`` (a cause that is there from the start has no onset).

    Args:
        t: (T,) vehicle time, s. R_without: (T, 6) residual without this correction (weighted per
            coefficient by the caller). delta: (T, 6) the correction at full size. valid: (T,) rows.
        block_s: block length, s. min_step_chi2: required improvement. max_before: largest amplitude before.

    Returns:
        ``{"onset_s": float | None, "chi2_gain": float, "amplitude_before": float, "amplitude_after": float,
        "blocks": [[t0, a, se], ...]}``.
    """
    b = np.floor((t - t[0]) / block_s).astype(int)
    rows = []
    for k in np.unique(b[valid]):
        m = valid & (b == k)
        d = delta[m].ravel()
        r = R_without[m].ravel()
        dd = float(d @ d)
        if m.sum() < 20 or dd <= 0:
            continue
        a = -float(r @ d) / dd
        s2 = float(np.mean((r + a * d) ** 2))
        rows.append((float(t[m][0]), a, np.sqrt(s2 / dd)))
    out = {"onset_s": None, "chi2_gain": 0.0, "amplitude_before": None, "amplitude_after": None,
           "blocks": [list(r) for r in rows]}
    if len(rows) < 4:
        return out
    tb, a, se = (np.array(x) for x in zip(*rows))
    w = 1.0 / np.maximum(se, 1e-12) ** 2
    mean_all = float(np.sum(w * a) / np.sum(w))
    e_all = float(np.sum(w * (a - mean_all) ** 2))
    best = (0.0, None, None, None)
    for k in range(2, len(a) - 1):
        after = float(np.sum(w[k:] * a[k:]) / np.sum(w[k:]))
        e = float(np.sum(w[:k] * a[:k] ** 2) + np.sum(w[k:] * (a[k:] - after) ** 2))
        before = float(np.sum(w[:k] * a[:k]) / np.sum(w[:k]))
        if e_all - e > best[0] and abs(before) < max_before and after > 0.5:
            best = (e_all - e, k, before, after)
    gain, k, before, after = best
    out["chi2_gain"] = float(gain)
    if k is not None and gain >= min_step_chi2:
        out.update({"onset_s": float(tb[k]), "amplitude_before": before, "amplitude_after": after})
    return out


def _where(ctx_X: np.ndarray, valid: np.ndarray, term: str, contribution: np.ndarray) -> dict:
    """Region of the envelope where an aero term's contribution is at least half its largest (10-90 %)."""
    m = valid & np.isfinite(contribution)
    c = np.abs(contribution[m])
    if not c.size or c.max() <= 0:
        return {}
    sel = c >= 0.5 * np.percentile(c, 99)
    out = {}
    for i in dict.fromkeys(term_factors(term)) if term != "1" else []:
        x = ctx_X[m, i][sel]
        name = REGRESSORS[i]
        if name in ("alpha", "beta"):
            x, name = np.degrees(x), name + "_deg"
        out[name] = [float(np.percentile(x, 10)), float(np.percentile(x, 90))]
    return out


def _reference_delay(ctx: DiagContext, R: np.ndarray, surf: str, coef: str, central: bool = True
                     ) -> tuple[float, float] | None:
    """A reference flight's own delay of ``surf`` by the fit that sized the flight's (``sparse._refine_delay``).

    The model's response to the delayed surface in ``coef`` is scanned on a grid that reaches below zero
    (a reference without a delay reads about 0, not the grid's first step), on all the reference's valid
    rows. The standard error is the linearised fit's with the log's time resolution ``dt / sqrt(12)`` in
    quadrature, as the flight's (``sparse.THRESHOLDS["delay_time_resolution"]``).

    Returns:
        (delay s, standard error s), or None with fewer than 50 valid rows or a surface that never moves.
    """
    from .sparse import _refine_delay

    rows = np.nonzero(ctx.valid)[0]
    if rows.size < 50 or surf not in REGRESSORS:
        return None
    tau, _, se = _refine_delay(ctx, np.nan_to_num(np.asarray(R, float)), surf, rows, COEFFICIENTS.index(coef),
                               taus=np.arange(-0.1, 0.4001, 0.005), central=central)
    if not np.isfinite(se):
        return None
    dt = float(np.median(np.diff(ctx.t))) if ctx.t.size > 1 else 0.0
    return float(tau), float(np.hypot(se, dt / np.sqrt(12.0)))


def _residual_of(ctx: DiagContext) -> np.ndarray:
    return np.where(ctx.valid[:, None], ctx.Y - ctx.model_values(), np.nan)


def differential(diag, references: list[Reference], airframe, *, threshold_pct: float = 20.0,
                 consistent_rel: float = 0.25, min_t: float = 3.0, min_step_chi2: float = 25.0,
                 search_residual: np.ndarray | None = None, angle_witness_exclude=(),
                 options: DifferentialOptions | None = None) -> dict:
    """Split the findings of a diagnosis into model inadequacy and changes, against reference flight(s).

    Args:
        diag: the new flight's :class:`~gcs_sysid.diagnose.core.Diagnosis` (its ``findings`` are
            rewritten: inadequacies are moved out, changes get ``evidence.differential``).
        references: one or more :class:`Reference` flights of the same aircraft, held against the
            same model (``diag.model``).
        airframe: the airframe.
        threshold_pct: structured share for the residual GP on the references.
        consistent_rel, min_t: the "same in the reference" test (see the module docstring).
        min_step_chi2: onset change-point acceptance.
        search_residual: (T, 6) the differential sparse search's residual (after the reference flight's
            inadequacy and the angle nuisance; ``sparse_search(keep_residual=True)``). With
            ``options.allowance_on_search_residual`` a term the search named is judged for the between-flight
            allowances on it, not on the raw residual against the model, where the model's own inadequacy (the
            reference flight has it too, and the search took it out) can hide a change (the JSBSim c172x
            ``Cm:alpha^2``); with ``options.angle_error_beside_named`` a search finding's angle error is fitted and
            judged on it: on the raw residual the reference's own inadequacy (the ultrastick's Cn ridge) stays in
            the other coefficients and the error along ``p_hat`` was not found. None: the raw residual for both.
        angle_witness_exclude: coefficients no air angle's scale or error is fitted on (``witness_exclude`` of
            :func:`angle_scale_allowance`): those whose measured target differs in kind between this flight and the
            references (:func:`gcs_sysid.diagnose.air_roll.moved_targets`). (): none.
        options: the allowances' switches (:class:`DifferentialOptions`); None: the frozen thresholds'
            (:meth:`DifferentialOptions.from_thresholds`), as :func:`gcs_sysid.diagnose.core.diagnose` uses them.

    Returns:
        The ``differential`` document: ``references`` (label, rows, t range), ``model_inadequacy``
        (list), ``changed`` (list of cause names with their reference comparison), ``not_compared``,
        ``allowance`` (findings that are a between-flight offset of their coefficient,
        :func:`offset_allowance`, or within the spread between two or more reference flights; not named),
        ``unexplained`` (per coefficient: ``"in the reference too"`` or ``"only in this flight"``).

    Raises:
        DataError: a reference with too few valid rows (from the table checks).
    """
    opt = DifferentialOptions.from_thresholds() if options is None else options
    type_b = {"beta": float(opt.beta_scale_type_b)}
    # a search finding's allowances on the search's residual (allowance_on_search_residual), its angle error
    # beside the other named findings on it too (angle_error_beside_named)
    allowance_residual = search_residual if opt.allowance_on_search_residual else None
    refs = []
    for ref in references:
        ctx = DiagContext.build(ref.table, airframe, diag.model, ref.states, None, None)
        refs.append((ref, ctx, _residual_of(ctx)))
    doc: dict = {"references": [{"label": r.label, "n_valid": int(c.valid.sum()),
                                 "t_range_s": [float(c.t[c.valid][0]), float(c.t[c.valid][-1])]}
                                for r, c, _ in refs],
                 "model_inadequacy": [], "changed": [], "not_compared": [], "allowance": [], "unexplained": {}}
    fitted = {f.cause: f for f in diag.fitted}
    valid = np.isfinite(diag.residual_after).all(axis=1)
    valid0 = np.isfinite(diag.residual_before).all(axis=1)
    min_gain_pct = float(diag.data.get("thresholds", {}).get("min_gain_pct", 10.0))
    sig = np.nanstd(np.where(valid[:, None], diag.residual_after, np.nan), axis=0)
    sig = np.where(sig > 0, sig, 1.0)
    keep = []
    for f in diag.findings:
        cause = f["cause"]
        if f.get("kind") == "fault" or cause.startswith("stuck:"):
            why = "an event in this flight (telemetry fault or stuck surface)"
            f["evidence"]["differential"] = {"verdict": "changed", "why": why}
            doc["changed"].append({"cause": cause, "onset_s": f.get("onset_s"), "why": why})
            keep.append(f)
            continue
        judged = f.get("evidence", {}).get("differential")
        if judged is not None and f["evidence"].get("domain") in ("data compatibility", "physical signature"):
            # a sensor or pitot cause judged against the references already (compat.judge, pitot)
            if judged.get("verdict") == "changed":
                doc["changed"].append({"cause": cause, "onset_s": f.get("onset_s"),
                                       "reference_corrections": [c.get("estimate")
                                                                 for c in judged.get("references", [])]})
            else:
                doc["not_compared"].append(cause)
            keep.append(f)
            continue
        if cause == "wind":
            verdict = _wind_differential(f, fitted.get(cause), refs)
            f["evidence"]["differential"] = verdict
            if verdict["verdict"] == "changed":
                doc["changed"].append({"cause": cause, "onset_s": f.get("onset_s"), "why": verdict["why"]})
                keep.append(f)
            elif verdict["verdict"] == "not compared":
                doc["not_compared"].append(cause)
                keep.append(f)
            else:
                doc["model_inadequacy"].append({"cause": cause, "coefficient": f["coefficient"],
                                                "in_flight": verdict["in_flight"],
                                                "in_references": verdict["references"], "gain": f.get("gain", {}),
                                                "summary": verdict["why"]})
            continue
        is_aero = cause.split(":")[0] in COEFFICIENTS
        if is_aero:                          # the between-flight allowance: an offset of the coefficient
            coef, term = cause.split(":", 1)
            R_wo = (diag.residual_after - fitted[cause].delta) if cause in fitted else diag.residual_before
            if allowance_residual is not None and f.get("source") == "sparse search":
                R_wo = np.where(valid0[:, None], allowance_residual, np.nan)
            # a curvature that entered the search with its parent is judged with it (sparse.power_parent_blocks)
            parents = tuple(f.get("evidence", {}).get("entered_with") or ())
            allow = offset_allowance(diag.X, R_wo, diag.train & valid0, diag.test & valid0, coef, term,
                                     min_t=min_t, min_gain_pct=min_gain_pct, parents=parents)
            if allow["offset_only"]:
                f["evidence"]["differential"] = {"verdict": "allowance", "allowance": allow}
                doc["allowance"].append({"cause": cause, "coefficient": f["coefficient"], "estimate": f["estimate"],
                                         "gain": f.get("gain", {}), "why": allow["why"],
                                         "summary": f"{cause}: a between-flight offset of {coef}, not a cause"})
                continue
            f["evidence"]["offset_allowance"] = allow
            scaled = None
            for angle in ("beta", "alpha") if opt.alpha_scale else ("beta",):
                jk = None
                if angle == "alpha" and opt.alpha_jackknife_s > 0:
                    r_ctx, r_R = (refs[0][1], refs[0][2]) if refs else (None, None)
                    jk = {"t": diag.t, "block_s": opt.alpha_jackknife_s,
                          "reference": None if r_ctx is None else
                          (r_ctx.t, r_ctx.X, r_R[:, COEFFICIENTS.index(coef)], r_ctx.valid)}
                scale = angle_scale_allowance(diag.X, R_wo, diag.train & valid0, diag.test & valid0, diag.model,
                                              coef, term, angle, min_t=min_t, min_gain_pct=min_gain_pct,
                                              scale_se=opt.angle_scale_se, jackknife=jk, parents=parents,
                                              witness_exclude=angle_witness_exclude,
                                              scale_type_b=type_b.get(angle, 0.0))
                if scale is not None and scale["scale_only"]:
                    scaled = scale
                    break
                if scale is not None:
                    f["evidence"][f"{angle}_scale_allowance"] = scale
            for angle in opt.angle_error_along if scaled is None else ():
                # an error of the measured angle along the finding's own term (angle_error_allowance)
                if opt.angle_error_beside_named:
                    R_e = np.where(valid0[:, None], search_residual, np.nan) \
                        if search_residual is not None and f.get("source") == "sparse search" else R_wo
                    err = angle_scale_allowance(diag.X, R_e, diag.train & valid0, diag.test & valid0, diag.model,
                                                coef, term, angle, min_t, min_gain_pct, opt.angle_scale_se,
                                                along_term=True, beside=_named_columns(diag, cause),
                                                witness_exclude=angle_witness_exclude,
                                                parents=parents if opt.angle_error_parents else ())
                else:
                    err = angle_error_allowance(diag.X, R_wo, diag.train & valid0, diag.test & valid0, diag.model,
                                                coef, term, angle, min_t=min_t, min_gain_pct=min_gain_pct,
                                                scale_se=opt.angle_scale_se, witness_exclude=angle_witness_exclude,
                                                parents=parents if opt.angle_error_parents else ())
                if err is not None and err["scale_only"]:
                    scaled = err
                    break
                if err is not None:
                    f["evidence"][f"{angle}_error_allowance"] = err
            if scaled is not None and "error_along_term" in scaled:
                what = "sideslip" if scaled["angle"] == "beta" else "angle of attack"
                _note_allowance(doc, f, scaled, f"{cause}: an error of the measured {what} that moves with {term}, "
                                                "not a cause")
                continue
            if scaled is not None:
                what = "sideslip" if scaled["angle"] == "beta" else "angle of attack"
                _note_allowance(doc, f, scaled, f"{cause}: a between-flight scale of the measured {what}, not a cause")
                continue
            forces = _force_changes(diag, fitted, cause, opt.scale_wind_axis) if opt.force_moment_arm_max > 0 else {}
            moment = force_moment_allowance(diag.X, R_wo, diag.train & valid0, diag.test & valid0, coef, term,
                                            forces, arm_max=opt.force_moment_arm_max, min_t=min_t,
                                            min_gain_pct=min_gain_pct) if forces else None
            if moment is not None and moment["moment_only"]:
                _note_allowance(doc, f, moment, f"{cause}: the moment about the CG of the named force change "
                                                f"({', '.join(sorted(moment['arms']))}), not a cause")
                continue
            if moment is not None:
                f["evidence"]["force_moment_allowance"] = moment
        if opt.scale_beta_allowance and cause.startswith("scale:") and cause[6:] in BETA_COEFFICIENTS:
            # a side-force scale is judged against a between-flight scale of the measured sideslip, as CY:beta is: on
            # an airframe whose side force is mostly CY_beta beta the two are one column (the c684, eighteenth session)
            coef = cause[6:]
            R_wo = diag.residual_before
            if allowance_residual is not None and f.get("source") == "sparse search":
                R_wo = np.where(valid0[:, None], allowance_residual, np.nan)
            col = _scale_column(diag.model, diag.X, coef, opt.scale_wind_axis)
            scale = angle_scale_allowance(diag.X, R_wo, diag.train & valid0, diag.test & valid0, diag.model, coef,
                                          cause, "beta", min_t=min_t, min_gain_pct=min_gain_pct,
                                          scale_se=opt.angle_scale_se, column=col,
                                          witness_exclude=angle_witness_exclude, scale_type_b=type_b.get("beta", 0.0))
            if scale is not None and scale["scale_only"]:
                _note_allowance(doc, f, scale, f"{cause}: a between-flight scale of the measured sideslip, not a cause")
                continue
            if scale is not None:
                f["evidence"]["beta_scale_allowance"] = scale
        null = 0.0 if is_aero else _null_value(cause, airframe)
        # an aero finding's correction is its change from the model's value (catalogue: evidence.correction;
        # sparse search: estimate - model_value)
        mv = f.get("model_value", f["evidence"].get("model_value", 0.0))
        c_f = f["evidence"].get("correction", f["estimate"] - mv) if is_aero else f["estimate"] - null
        # the standard error the rules below were frozen with: a named term's reported std_error is its combined
        # standard uncertainty since the ninth session (sparse._with_uncertainty), which no decision reads
        se_f = float(f["evidence"].get("std_error_decision", f["std_error"]))
        # a delay sized as a difference (sparse._differential_delay): compare the flight's own delay with each
        # reference's, both by that one fit
        same_fit = opt.delay_same_fit and cause.startswith("delay:") and "delay_differential" in f.get("evidence", {})
        if same_fit and opt.delay_change_min_t > 0 and not abs(c_f) >= opt.delay_change_min_t * se_f:
            # the change of the delay is within its standard error (time resolution included) of none
            why = (f"{cause}: a change of {c_f:+.3f} +- {se_f:.2g} s against the reference (t {c_f / se_f:.1f} "
                   f"< {opt.delay_change_min_t:g}): no change beyond the fit and the log's time resolution")
            f["evidence"]["differential"] = {"verdict": "allowance", "why": why}
            doc["allowance"].append({"cause": cause, "coefficient": f["coefficient"], "estimate": f["estimate"],
                                     "gain": f.get("gain", {}), "why": why, "summary": why})
            continue
        if same_fit:
            c_f = float(f["evidence"]["delay_differential"]["flight_s"])
        comps = []
        for ref, ctx, R in refs:
            if is_aero:
                coef, term = cause.split(":", 1)
                got = _refit_aero(ctx, R, coef, term)
            elif same_fit:
                got = _reference_delay(ctx, R, cause.split(":", 1)[1], f["coefficient"], opt.delay_se_central)
            else:
                try:                                   # a fit that fails on the reference compares nothing
                    got = _refit_other(ctx, ctx.Y - ctx.model_values(), f, ref, airframe)
                except (KeyError, ValueError, ArithmeticError, np.linalg.LinAlgError, SysidError):
                    got = None
                got = (got[0] - null, got[1]) if got is not None and np.all(np.isfinite(got)) else None
            if got is None:
                comps.append({"label": ref.label, "compared": False})
                continue
            c_r, se_r = got
            same = abs(c_r) >= min_t * se_r and np.sign(c_r) == np.sign(c_f) and \
                abs(c_f - c_r) <= 3.0 * np.hypot(se_f, se_r) + consistent_rel * abs(c_f)
            comps.append({"label": ref.label, "compared": True, "correction": c_r, "std_error": se_r,
                          "same": bool(same)})
        compared = [c for c in comps if c["compared"]]
        if not compared:
            f["evidence"]["differential"] = {"verdict": "not compared", "references": comps}
            doc["not_compared"].append(cause)
            keep.append(f)
            continue
        spread = _within_reference_variation(c_f, se_f, compared)
        if spread is not None:
            f["evidence"]["differential"] = {"verdict": "allowance", "references": comps, "allowance": spread}
            doc["allowance"].append({"cause": cause, "coefficient": f["coefficient"], "estimate": f["estimate"],
                                     "gain": f.get("gain", {}), "why": spread["why"],
                                     "summary": f"{cause}: within the variation between the reference flights"})
            continue
        if all(c["same"] for c in compared):
            w = np.array([1 / se_f**2] + [1 / c["std_error"] ** 2 for c in compared])
            v = np.array([c_f] + [c["correction"] for c in compared])
            pooled = float(np.sum(w * v) / np.sum(w))
            item = {"cause": cause, "coefficient": f["coefficient"],
                    "in_flight": {"correction": c_f, "std_error": se_f},
                    "in_references": compared, "gain": f.get("gain", {}),
                    "extension": {"cause": cause, "correction": pooled, "std_error": float(1 / np.sqrt(np.sum(w))),
                                  "value": (f["evidence"].get("model_value", 0.0) + pooled) if is_aero
                                  else null + pooled}}
            if is_aero:
                coef, term = cause.split(":", 1)
                j = COEFFICIENTS.index(coef)
                contrib = pooled * term_matrix(diag.X, [term])[:, 0]
                rms_c = float(np.sqrt(np.nanmean(contrib[valid] ** 2)))
                rms_y = float(np.sqrt(np.nanmean(diag.residual_before[valid, j] ** 2))) if valid.any() else 0.0
                item.update({"where": _where(diag.X, valid, term, contrib), "rms_contribution": rms_c,
                             "rms_residual_before": rms_y,
                             "summary": f"{coef} needs {term} ({pooled:+.4g}) in this flight and in "
                                        f"{len(compared)} reference flight(s): the model never had it"})
            else:
                item["summary"] = (f"{cause} ({f['estimate']:.4g}) is in the reference flight(s) too: present when "
                                   "the model was fitted, not a change")
            doc["model_inadequacy"].append(item)
            continue
        # changed: keep the finding, with the comparison and an onset where the data show one
        info = {"verdict": "changed", "references": comps}
        if f.get("onset_s") is None and cause in fitted:
            fd = fitted[cause].delta
            R_wo = (diag.residual_after - fd) / sig
            on = onset_of_change(diag.t, np.nan_to_num(R_wo), np.nan_to_num(fd / sig), valid,
                                 min_step_chi2=min_step_chi2)
            info["onset_search"] = {k: v for k, v in on.items() if k != "blocks"}
            if on["onset_s"] is not None:
                f["onset_s"] = on["onset_s"]
                if is_aero:                            # its size once it is there
                    coef, term = cause.split(":", 1)
                    j = COEFFICIENTS.index(coef)
                    m = valid & (diag.t >= on["onset_s"])
                    phi = term_matrix(diag.X, [term])[:, 0]
                    res = ols(phi[m, None], (diag.residual_after - fd)[m, j], terms=[term])
                    info["after_onset"] = {"estimate": float(f["evidence"].get("model_value", 0.0) + res.theta[0]),
                                           "std_error": float(res.std_error[0])}
        f["evidence"]["differential"] = info
        doc["changed"].append({"cause": cause, "onset_s": f.get("onset_s"),
                               "reference_corrections": [c.get("correction") for c in compared]})
        keep.append(f)
    for f in keep:                             # every decision is made: only what a finding reports changes
        if f["cause"] in opt.estimate_beyond_scale:
            report_beyond_scale(f)
        elif f["cause"].split(":")[0] in opt.estimate_beyond_error:
            report_beyond_angle_error(f)
    diag.findings[:] = keep
    # structure no term explains: in the references too, or only here
    ref_gp = [residual_structure(ctx, np.nan_to_num(R), threshold_pct=threshold_pct) for _, ctx, R in refs]
    for u in diag.unexplained:
        g = u.get("gp")
        if not g or not g.get("structured"):
            continue
        coef = u["coefficient"]
        also = [r.label for (r, _, _), rg in zip(refs, ref_gp) if rg.get(coef, {}).get("structured")]
        verdict = "in the reference too: model inadequacy outside the library" if also \
            else "only in this flight: an unexplained change"
        u["differential"] = verdict
        doc["unexplained"][coef] = {"verdict": verdict, "references_with_it": also, "region": g["region"],
                                    "structured_percent": g["structured_percent"], "rms_gp_mean": g["rms_gp_mean"]}
    return doc


def report_beyond_scale(f: dict) -> bool:
    """Report a kept finding's change beyond the between-flight scale of its air angle (in place).

    A finding in a sideslip coefficient is named only when it stands beyond a common scale ``1 + s`` of the measured
    sideslip fitted on the other coefficients (:func:`angle_scale_allowance`: the residual less ``s x dC/dx``, refitted
    with the coefficient's offset free). The selected estimate is read against the flight's own measured angle, and
    that angle is not the reference's when the change itself enters its reconstruction: the aided sideslip is built
    from the side force (``gcs_sysid.estimation.airangles``) with the reference's side-force model, so a side force
    ``k`` times the model's also scales the measured sideslip by about ``1 + w (k - 1)`` (``w``: the side force's
    weight in the aided angle), and against that angle the side force's change reads
    ``(1 - w)(k - 1) / (1 + w (k - 1))`` where it is ``k - 1``. With ``s`` taken out, what is left is the change per
    unit of the model's side force at the measured angle, ``(k - 1) / (1 + w (k - 1))``
    (``tests/diagnose/test_beta_scale.py``: 0.417 for 0.5 at ``w`` 0.4, 0.23 as selected). Measured on the JSBSim
    roster's seed-90 ``CY:scale`` flights (fifty-eighth session, ``docs/benchmarks.md``): 37 named, within 25 % of
    JSBSim's scale 27 as selected and 34 beyond the sideslip scale (median 0.87 and 0.95 of the change).

    The finding's ``estimate`` becomes ``model_value + beyond_scale.estimate`` and its ``std_error`` the selected
    combined standard uncertainty with the scale's share added in quadrature (``beyond_scale.std_error_scale_share``,
    JCGM 100:2008 eq. 10); what it reported before is kept in ``evidence.estimate_as_selected``. Nothing is changed
    where the finding carries no scale allowance with a finite estimate beyond it (the angle's scale was not fitted,
    or an error along the term, whose ``s`` is in other units).

    Returns:
        Whether the finding was changed.
    """
    return any(_report_beyond(f, key, along_term=False) for key in ("beta_scale_allowance", "alpha_scale_allowance"))


def _report_beyond(f: dict, key: str, along_term: bool) -> bool:
    """Report the change beyond the allowance ``evidence[key]`` as the finding's change (``estimate = model_value +
    beyond_scale.estimate``) with the allowance's standard-uncertainty share (``std_error_scale_share``) added in
    quadrature, what the finding selected kept in ``evidence.estimate_as_selected``; only where the allowance is of
    the kind asked (an error along the finding's term or not, ``along_term``) and its change beyond is finite.

    Returns:
        Whether the finding was changed.
    """
    ev = f.setdefault("evidence", {})
    a = ev.get(key) or {}
    b = a.get("beyond_scale") or {}
    change, share = b.get("estimate"), b.get("std_error_scale_share", 0.0)
    if ("error_along_term" in a) != along_term or change is None or not np.isfinite(change) \
            or not np.isfinite(share):
        return False
    mv = f.get("model_value", ev.get("model_value", 0.0))
    ev["estimate_as_selected"] = {"estimate": f["estimate"], "std_error": f["std_error"], "beyond": key}
    f["estimate"] = float(mv + change)
    f["std_error"] = float(np.hypot(f["std_error"], share))
    return True


def report_beyond_angle_error(f: dict) -> bool:
    """Report a kept moment finding's change beyond the sideslip's error along its own term (in place).

    A finding of ``Cl`` or ``Cn`` is named only when it stands beyond a common error of the measured sideslip along
    its own term, ``e phi`` (rad per unit of the term), fitted on the other lateral coefficients through the model's
    sideslip derivatives (the along-term :func:`angle_scale_allowance`: on ``CY``, where the aided sideslip's error
    shows as ``CY_beta e phi``, and on the other moment); the refit of the finding beyond it, with the
    coefficient's offset free, is ``evidence.beta_error_allowance.beyond_scale``. The selected estimate is read
    against the flight's own measured sideslip, whose error changes with the flight when the change itself moves
    the sideslip: an adverse yaw ``Cn:delta_a`` adds sideslip along ``delta_a`` that the aided sideslip reads in
    part (against JSBSim's sideslip it reads 0.75-0.85 of the true one below 0.3 Hz and 0.93-1.0 at 0.3-1.5 Hz on
    the c684's flights), so the model's ``Cn_beta beta`` misses ``Cn_beta e delta_a`` and the change reads low by
    it (the c684's -0.06: -0.0385 as selected, -0.0597 beyond the error; with JSBSim's sideslip in the pipeline's
    place a linear reference reads -0.0594: ``benchmarks/effect_bias_split.py``, ``docs/benchmarks.md``,
    *Sixty-first session, lead*). Which coefficients' findings are re-read is the caller's
    (``DifferentialOptions.estimate_beyond_error``, ``("Cl", "Cn")`` by default): not ``CY``, whose error is fitted on
    the moments, which hold a moment change along the same term when there is one.

    The finding's ``estimate`` becomes ``model_value + beyond_scale.estimate`` and its ``std_error`` the selected
    combined standard uncertainty with the error's share added in quadrature (``std_error_scale_share``, JCGM
    100:2008 eq. 10); what it reported before is kept in ``evidence.estimate_as_selected``. Nothing is changed
    where the finding carries no along-term allowance with a finite estimate beyond it.

    Returns:
        Whether the finding was changed.
    """
    return _report_beyond(f, "beta_error_allowance", along_term=True)


def fit_record(log, t_from: float | None, t_to: float | None) -> dict:
    """What ``gcs-sysid fit`` records about the flight a model was fitted on (``<model>.fit.json``).

    Enough to find the flight again and re-derive its residual against the model: the log's absolute
    path, its SHA-256 and the vehicle-time window.
    """
    import hashlib
    from pathlib import Path

    p = Path(str(log)).resolve()
    h = hashlib.sha256()
    with open(p, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return {"log": str(p), "sha256": h.hexdigest(), "window_s": [t_from, t_to]}


def reference_logs(model_path, given=None) -> tuple[list[dict], list[str]]:
    """The reference flights of a diagnosis: those given, else those the model's fit recorded.

    Args:
        model_path: the model file; its ``<model>.fit.json`` (written by ``gcs-sysid fit``) is read for
            ``reference_flights`` when ``given`` is None.
        given: log paths (``--reference``, whole logs), or None (use the record), or ``[]`` (none).

    Returns:
        (list of ``{"log", "window_s"}``, notes): a recorded flight whose file is missing or changed
        (SHA-256) is left out with a note saying so and how to pass it.
    """
    import json
    from pathlib import Path

    if given is not None:
        return [{"log": str(g), "window_s": [None, None]} for g in given], []
    rec = Path(str(model_path)).with_suffix(".fit.json")
    if not rec.is_file():
        return [], []
    try:
        flights = json.loads(rec.read_text()).get("reference_flights", [])
    except (ValueError, OSError, AttributeError):
        return [], [f"{rec}: unreadable; no reference flight used (pass --reference LOG)"]
    out, notes = [], []
    for f in flights:
        p = Path(f.get("log", ""))
        if not p.is_file():
            notes.append(f"reference flight {p} (recorded in {rec.name}) not found: no differential diagnosis "
                         "against it; pass --reference LOG")
            continue
        if f.get("sha256") and fit_record(p, None, None)["sha256"] != f["sha256"]:
            notes.append(f"reference flight {p} changed since the fit (SHA-256 differs): not used")
            continue
        out.append({"log": str(p), "window_s": list(f.get("window_s") or [None, None])})
    return out, notes
