"""Pieces the benchmark scripts share word for word: the ``--aircraft`` help of the harness's names and the
``--json`` records (one JSON line per result, appended; read back, plain or gzip-compressed, by :func:`read_lines`);
the rows' output-pair correlations (:func:`pair_correlations`) and the truth's own coupling beyond a linear model
(:func:`truth_residual_correlation`, sixty-eighth session).

Moved here from ``eval_jsbsim.py``, ``eval_gp_jsbsim.py``, ``eval_gp_joint.py``, ``eval_live_jsbsim.py``,
``eval_accel_sigma.py``, ``alpha_stages.py``, ``rate_floor.py`` and ``beta_band.py`` (twenty-eighth session, a
refactoring: every script's output, records and ``--help`` are unchanged).
"""

from __future__ import annotations

import gzip
import json
from collections.abc import Iterable
from pathlib import Path

import numpy as np

__all__ = ["AIRCRAFT_HELP", "append_jsonl", "read_lines", "truth_residual_correlation", "pair_correlations",
           "false_couplings", "LEARNED_CORR_LIMIT", "TRUTH_NONE_LIMIT"]

#: ``--aircraft`` help of the scripts that fly the harness's aircraft by name (``aircraft_argument``).
AIRCRAFT_HELP = ("harness names (c172x sgs pa28 j3cub c182 t37 t6 b747 f16 f4n rascal sgs126 asw20 iar80 "
                 "c684 ultrastick b737 c172p eternity us25e ka350 s23 dr1 navion fokker50) or JSBSim model names "
                 "(J3Cub, "
                 "T37, "
                 "t6texan2, B747, "
                 "f16_direct, "
                 "F4N_fcs, Rascal110_glide, asw20_glide, IAR80_glide, C684_glide, UltraStick120_glide, 737, "
                 "Eternity_glide, UltraStick25e_glide, KingAir350_glide, ShortS23_glide, Dr1_glide, "
                 "Navion_glide, Fokker50_glide); no aircraft is untouched now (docs/jsbsim.md); default %(default)s")


def append_jsonl(path: str | None, rows: Iterable[dict]) -> None:
    """Append each of ``rows`` to the file ``path`` as one JSON line (``json.dumps``, then a newline); nothing
    where ``path`` is None or empty (no ``--json`` given).

    Args:
        path: the ``--json`` file, created if missing.
        rows: JSON-serialisable records (dicts of numbers, strings, lists, dicts).

    Raises:
        OSError: the file cannot be opened for appending. TypeError: a record is not JSON-serialisable (the
            lines before it are written).
    """
    if not path:
        return
    with open(path, "a") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")


def read_lines(path: str | Path) -> list[str]:
    """The lines of a text file of records, gzip-decompressed where the name ends in ``.gz`` (the committed record
    sets, ``benchmarks/records/``).

    Args:
        path: a ``.jsonl`` file, or a ``.jsonl.gz`` one.

    Returns:
        its lines, without their line ends.

    Raises:
        OSError: the file cannot be read, or a ``.gz`` file is not gzip data (``gzip.BadGzipFile``).
        UnicodeDecodeError: the content is not UTF-8 text.
    """
    p = Path(path)
    if p.name.endswith(".gz"):
        with gzip.open(p, "rt", encoding="utf-8") as f:
            return f.read().splitlines()
    return p.read_text(encoding="utf-8").splitlines()


def truth_residual_correlation(Xt_air: np.ndarray, Yt: np.ndarray, rows: np.ndarray) -> dict[str, float]:
    """The correlations between JSBSim's coefficients' residuals after least squares on the ten exact regressors (with
    the rates its aerodynamics reads) over ``rows``, per output pair ``"A-B"`` (|r|, the learned correlations' pairs):
    the coupling the truth itself has beyond a linear model of the regressors (issue 8: "no learned output correlation
    above 0.5 where the truth has none"). ``Xt_air`` ``(T, 10)``, ``Yt`` ``(T, 6)``, ``rows`` ``(T,)`` bool."""
    ok = rows & np.isfinite(Xt_air).all(1) & np.isfinite(Yt).all(1)
    A = np.column_stack([np.ones(int(ok.sum())), Xt_air[ok]])
    R = Yt[ok] - A @ np.linalg.lstsq(A, Yt[ok], rcond=None)[0]
    from gcs_sysid.aero.table import COEFFICIENTS

    return pair_correlations(np.corrcoef(R.T), COEFFICIENTS)


def pair_correlations(C, names) -> dict[str, float]:
    """``{"A-B": |C[i, j]|}`` over the pairs ``i < j`` of ``names`` (rounded to 3 digits): a correlation matrix
    ``(P, P)`` as the eval rows keep it (the learned output correlations, ``corr_pairs``; the truth's residual ones,
    ``truth_resid_corr``)."""
    C = np.abs(np.asarray(C, float))
    return {f"{a}-{b}": round(float(C[i, j]), 3) for i, a in enumerate(names) for j, b in enumerate(names) if i < j}


#: issue 8's line: a learned output correlation above this (|r|) is a coupling
LEARNED_CORR_LIMIT = 0.5
#: the truth "has none" for a pair whose residual correlation (:func:`truth_residual_correlation`) is below this;
#: chosen before any count used it (the sixty-eighth session's rule 68c, ``docs/benchmarks.md``): well below the
#: learned line, so that a pair counts only where the truth is clearly uncoupled
TRUTH_NONE_LIMIT = 0.3


def false_couplings(corr_pairs: dict | None, truth_resid_corr: dict | None) -> list[str] | None:
    """The output pairs a model couples where the truth does not: issue 8's "no learned output correlation above 0.5
    where the truth has none", read pair by pair.

    Args:
        corr_pairs: ``{"A-B": |r|}``, the model's learned output correlations (an eval row's ``corr_pairs``).
        truth_resid_corr: ``{"A-B": |r|}``, JSBSim's residual correlations on the same flight's training rows (an
            eval row's ``truth_resid_corr``, :func:`truth_residual_correlation`).

    Returns:
        the pairs with a learned ``|r| > LEARNED_CORR_LIMIT`` and a truth ``|r| < TRUTH_NONE_LIMIT``, sorted; a pair
        the truth's dict lacks (or holds as NaN) is not counted. None when either dict is missing (a row written
        before the fields existed).
    """
    if not isinstance(corr_pairs, dict) or not isinstance(truth_resid_corr, dict):
        return None
    out = []
    for pair, r in corr_pairs.items():
        t = truth_resid_corr.get(pair)
        try:
            r, t = float(r), float(t)
        except (TypeError, ValueError):
            continue
        if r > LEARNED_CORR_LIMIT and t < TRUTH_NONE_LIMIT:       # NaN compares False: not counted
            out.append(pair)
    return sorted(out)
