"""The diagnosis at the air-relative roll rate: the reference flight's ``p_hat`` less its rolling gust (issue 9).

JSBSim's aerodynamics (and the air's) read the roll rate relative to the air, ``p_aero = p - p_g``
(``FGAuxiliary``: ``vAeroPQR = vPQR - TurbPQR``); the gyro measures ``p``. Fitted at the gyro's ``p``, the
reference model's roll damping ``Cl_p`` and ``Cl_delta_a`` are attenuated (the gust drives the roll response, so
``p`` is correlated with the ``Cl_p p_g`` left in the residual; Morelli and Klein, *Aircraft System
Identification*, 2nd ed., 2016, sec. 5.6 and ch. 10). A hidden rolling moment (``Cl:alpha*beta``) is flown
against by the roll loop, so ``p`` and ``delta_a`` move with it, and a model that under-predicts that response
leaves only part of the term in the residual: on the s23's ``Cl:alpha*beta = 3`` flights the bare residual reads
1.5-1.7 against the model fitted at the gyro's rate, 2.45-2.79 against the one fitted at the reference's own
``p_hat - p_hat_g`` (``docs/diagnose.md``, "The air-relative roll rate"; ``docs/benchmarks.md``, *Twenty-fifth
session, i9-airroll*).

``p_hat_g`` is the ``"rollgp"`` roll fit's Rauch-Tung-Striebel smoothed rolling gust
(:func:`gcs_sysid.aero.gustfilter.filter_gust_table`, :mod:`gcs_sysid.aero.rollgust`: the gust a first-order
Gauss-Markov state of the roll dynamics, MIL-F-8785C's Dryden time constant, the filter-error method of
Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., 2015, ch. 5), estimated on every valid row of the
flight's *own* measured roll moment. It is applied as one regressor of the table, so every coefficient's
``p_hat`` terms (Cl's and Cn's, and CY's where the model has one) and every library column in ``p_hat`` read the
air-relative rate.

**Circularity.** The gust state is estimated from the roll moment, which on a flight with a hidden rolling
moment carries that moment too. Measured on the s23's ``Cl:alpha*beta = 3`` flights: the diagnosed flight's own
``p_hat_g`` regressed on JSBSim's ``p_hat_g`` and the injected moment over ``-Cl_p`` takes 0.63-0.65 of the
injected term (0.99 at 1.5), and the residual along ``alpha*beta`` falls from 1.5-1.7 to -0.9 .. -0.2; with the
term itself in the roll fit's design it still takes 0.45-0.47, and a 1-s high-pass of the estimate 0.11-0.15.
So the option's mode ``"reference"`` (:data:`gcs_sysid.diagnose.run.AIR_ROLL_RATE`; ``"reference:Cl"`` by default
since the fiftieth session, ``"off"`` before) moves only
the reference flight, the flight the model is fitted on and whose residual the differential search subtracts, to the
air rate;
the flight under test keeps the gyro's ``p_hat`` (its residual then carries the gust's ``-Cl_p p_hat_g``, which is
independent of the regressors, as noise). ``"both"`` moves the flight under test too (measured, not recommended).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS

__all__ = ["AIR_ROLL_MODES", "CL_TARGET_NOTE", "air_roll_table", "air_roll_cl_table", "moved_targets",
           "unlike_targets"]

#: The modes of :data:`gcs_sysid.diagnose.run.AIR_ROLL_RATE`: ``"off"`` (the gyro's rate everywhere),
#: ``"reference"`` (the reference flight at its own air-relative rate, the flight under test at the gyro's) and
#: ``"both"`` (each flight at its own air-relative rate; circular on a flight with a hidden rolling moment);
#: ``"fit"`` (only the model is fitted at the reference's air-relative rate; both flights diagnosed at the gyro's);
#: ``"reference:Cl"`` (as ``"reference"``, but only the reference's Cl moves, by its target: :func:`air_roll_cl_table`;
#: every ``p_hat`` column stays the gyro's, so Cn and CY see the same rate on both flights).
AIR_ROLL_MODES = ("off", "fit", "reference", "both", "reference:Cl")

#: How a table's note begins where :func:`air_roll_cl_table` moved its Cl target (for the reader; the table's
#: ``corrected_targets`` says it to the code, :func:`moved_targets`).
CL_TARGET_NOTE = "air roll rate (Cl target)"


def air_roll_table(table, states, airframe):
    """The table with ``p_hat`` less the flight's own smoothed rolling gust on its valid rows.

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` (``X`` ``(T, 10)`` with the gyro's ``p_hat``,
            ``Y`` ``(T, 6)``, ``valid`` ``(T,)``).
        states: the smoothed states (``data["p"]`` ``(T,)`` rad/s on the table's grid; the stated ``p_dot`` noise,
            :func:`gcs_sysid.aero.gustfilter.stated_moment_variance`).
        airframe: span ``b`` m, area ``S`` m^2, inertia ``Ixx`` kg m^2.

    Returns:
        ``(table', info)``: a new table (the input is not changed; ``x_var``'s ``p_hat`` column carries the
        estimate's variance) and ``{"applied": bool, "note": str, "g_sd": float, "Cl_p": float}``. Where the fit
        cannot be made or fails the Dryden check (:data:`gcs_sysid.aero.gustfilter.ROLL_MIN_DRYDEN_RATIO`: the
        roll moment does not read a gust) the table is returned unchanged with ``applied`` False.
    """
    from ..aero.gustfilter import filter_gust_table

    out, G = filter_gust_table(table, states, airframe, np.asarray(table.valid, bool), method="rollgp")
    if G is None:
        note = out.notes[-1] if out.notes else "air-relative roll rate not estimated"
        return replace(table, notes=list(table.notes) + [f"air roll rate: {note}"]), \
            {"applied": False, "note": note, "g_sd": 0.0, "Cl_p": float("nan")}
    j = REGRESSORS.index("p_hat")
    g = np.asarray(table.X, float)[:, j] - np.asarray(out.X, float)[:, j]
    return out, {"applied": True, "note": out.notes[-1], "g_sd": float(np.std(g[G.used])), "Cl_p": float(G.Cl_p)}


def air_roll_cl_table(table, states, airframe):
    """The table with Cl's target at the air-relative roll rate on its valid rows, every regressor the gyro's.

    ``Cl + Cl_p p_hat_g`` (:func:`gcs_sysid.aero.gustfilter.air_roll_target` with its own ``"rollgp"`` roll fit,
    :func:`~gcs_sysid.aero.gustfilter.air_roll_fit`, on the flight's valid rows; the filter-error method, Jategaonkar,
    *Flight Vehicle System Identification*, 2nd ed., 2015, ch. 5): the moment the rolling gust caused is taken out
    of Cl, so a model fitted on it
    with the gyro's ``p_hat`` is not attenuated by the gust, and a residual against it carries no gust moment. Unlike
    :func:`air_roll_table` nothing else moves: Cn's and CY's ``p_hat`` terms read the gyro's rate on the reference as
    on the flight under test (forty-ninth session: moving the regressor for every coefficient lost ``Cn:delta_a``,
    ``CY:scale`` and ``bias:airspeed`` tops where Cl's ``alpha*beta`` gained; ``docs/diagnose.md``, "The air-relative
    roll rate").

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` (``X`` ``(T, 10)`` with the gyro's ``p_hat``, ``Y``
            ``(T, 6)``, ``valid`` ``(T,)``).
        states: the smoothed states (``data["p"]`` ``(T,)`` rad/s; the stated ``p_dot`` noise).
        airframe: span ``b`` m, area ``S`` m^2, inertia ``Ixx`` kg m^2.

    Returns:
        ``(table', info)``: a new table (``Y``'s Cl column changed on the valid rows, ``"Cl"`` in its
        ``corrected_targets``, a note added) and
        ``{"applied": bool, "note": str, "g_sd": float, "Cl_p": float}``; where the roll fit is refused the table is
        returned with only the note and ``applied`` False.
    """
    from ..aero.gustfilter import air_roll_target

    Y, info = air_roll_target(table, states, airframe, np.asarray(table.valid, bool))
    note = str(info.get("note", ""))
    if "Cl_p" not in info:
        return replace(table, notes=list(table.notes) + [f"air roll rate (Cl): {note}"]), \
            {"applied": False, "note": note, "g_sd": 0.0, "Cl_p": float("nan")}
    g = np.asarray(info["g"], float)
    moved = tuple(dict.fromkeys([*table.corrected_targets, "Cl"]))
    return replace(table, Y=Y, notes=list(table.notes) + [f"{CL_TARGET_NOTE}: {note}"], corrected_targets=moved), \
        {"applied": True, "note": note, "g_sd": float(np.std(g[np.asarray(info["rows"], bool)])),
         "Cl_p": float(info["Cl_p"])}


def moved_targets(table) -> frozenset:
    """The coefficients whose measured target was corrected on ``table`` (its ``corrected_targets``; today only Cl,
    by :func:`air_roll_cl_table`).

    A residual of such a coefficient against a model is not comparable with the same coefficient's residual on a
    flight whose target did not move (the one carries the rolling gust's moment, the other not), so the
    differential diagnosis does not fit an air angle's between-flight scale on it
    (:func:`gcs_sysid.diagnose.differential.angle_scale_allowance`'s ``witness_exclude``; :func:`unlike_targets`).

    Args:
        table: a :class:`~gcs_sysid.aero.table.CoefficientTable`, or anything with ``corrected_targets`` (a table
            without the attribute counts as measured).

    Returns:
        ``frozenset({"Cl"})`` where the Cl target was moved, else an empty set.
    """
    return frozenset(getattr(table, "corrected_targets", None) or ())


def unlike_targets(table, references) -> tuple[str, ...]:
    """The coefficients whose target was corrected on ``table`` or on some reference but not on both.

    Args:
        table: the flight under test's :class:`~gcs_sysid.aero.table.CoefficientTable`.
        references: the reference flights (each with a ``table``).

    Returns:
        the coefficients, in :data:`~gcs_sysid.aero.table.COEFFICIENTS` order (empty when every target is alike).
    """
    mine = moved_targets(table)
    differ = set().union(*(moved_targets(r.table) ^ mine for r in references))
    return tuple(c for c in COEFFICIENTS if c in differ)
