"""``gcs-sysid predict``: the learned model evaluated at flight conditions the user gives.

Input: a CSV file with a header row holding the regressor columns of
:data:`gcs_sysid.aero.table.REGRESSORS`, in SI units (``alpha beta`` rad, ``p_hat q_hat r_hat``
dimensionless, ``delta_e delta_a delta_r`` rad in the project's sign conventions, ``delta_t`` 0..1,
``V`` m/s true airspeed); degrees are not accepted (convert before). Other columns (a time, a case
name) are copied to the output unchanged. Output: the input's columns, then for each coefficient
the model's mean ``<C>_mean``, the standard deviation of the coefficient itself ``<C>_sigma`` (the
model's uncertainty, without measurement noise: the band that should cover the true coefficient; with
the model's error at exact conditions, :mod:`gcs_sysid.gp.discrepancy`)
and ``<C>_sigma_obs`` (with the learned measurement noise: the band for a new measurement).

The model is the one a replay saves (``OUT/model.npz`` + ``OUT/model.json``, :func:`gcs_sysid.gp.load_gp`).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .aero.table import COEFFICIENTS, REGRESSORS
from .errors import InputError

__all__ = ["read_conditions", "predict_conditions", "run_predict", "model_prefix", "Predictions"]


@dataclass(frozen=True)
class Predictions:
    """Model output at the given conditions.

    Attributes:
        X: regressors, shape (N, 10), columns :data:`REGRESSORS`, SI.
        outputs: coefficient names of the model's outputs (P of them).
        mean, sigma, sigma_obs: shape (N, P): mean, latent and observation standard deviations.
    """

    X: np.ndarray
    outputs: tuple[str, ...]
    mean: np.ndarray
    sigma: np.ndarray
    sigma_obs: np.ndarray


def model_prefix(model: str | Path) -> Path:
    """The ``<prefix>`` of a saved model (``<prefix>.npz`` and ``<prefix>.json``).

    Args:
        model: a replay's output directory (holding ``model.npz``), or the prefix itself,
            or the ``.npz`` / ``.json`` file.

    Raises:
        InputError: no saved model there.
    """
    p = Path(model)
    if p.is_dir():
        p = p / "model"
    if p.suffix in (".npz", ".json"):
        p = p.with_suffix("")
    npz = p.with_name(p.name + ".npz")
    if not npz.is_file():
        raise InputError(f"{model}: no saved model (expected {npz}; a replay writes OUT/model.npz and OUT/model.json)")
    return p


def read_conditions(path: str | Path) -> tuple[np.ndarray, list[str], list[list[str]]]:
    """Read a conditions CSV.

    Args:
        path: CSV file with a header row.

    Returns:
        ``(X (N, 10) SI regressors, header, rows as strings)``.

    Raises:
        InputError: unreadable file, no header or rows, a missing regressor column, or a value
            that is not a finite number (names the row and column).
    """
    p = Path(path)
    try:
        with open(p, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as exc:
        raise InputError(f"{p}: cannot read conditions file ({exc.strerror})") from None
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{p}: not a CSV text file ({exc})") from None
    rows = [r for r in rows if r and any(c.strip() for c in r)]
    if not rows:
        raise InputError(f"{p}: empty; expected a header row with {', '.join(REGRESSORS)}")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in REGRESSORS if c not in header]
    if missing:
        deg = [h for h in header if h.endswith("_deg")]
        hint = f" (degree columns such as {deg[0]} are not accepted: give rad)" if deg else ""
        raise InputError(f"{p}: missing column(s) {', '.join(missing)}; expected {', '.join(REGRESSORS)} "
                         f"in SI units{hint}")
    if len(rows) < 2:
        raise InputError(f"{p}: no data rows after the header")
    idx = [header.index(c) for c in REGRESSORS]
    X = np.empty((len(rows) - 1, len(REGRESSORS)))
    for i, r in enumerate(rows[1:]):
        if len(r) != len(header):
            raise InputError(f"{p}: row {i + 2} has {len(r)} fields, the header has {len(header)}")
        for j, k in enumerate(idx):
            try:
                v = float(r[k])
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                raise InputError(f"{p}: row {i + 2}, column {REGRESSORS[j]}: expected a finite number, got {r[k]!r}")
            X[i, j] = v
    if (X[:, REGRESSORS.index("V")] <= 0).any():
        i = int(np.argmax(X[:, REGRESSORS.index("V")] <= 0))
        raise InputError(f"{p}: row {i + 2}, column V: airspeed must be > 0 m/s, got {X[i, -1]}")
    return X, header, [[c.strip() for c in r] for r in rows[1:]]


def predict_conditions(model, X: np.ndarray, output_names=None) -> Predictions:
    """Evaluate a loaded GP at regressors ``X`` (N, 10).

    Args:
        model: a :class:`gcs_sysid.gp.LocalGlobalGP`.
        X: regressors, (N, 10), SI.
        output_names: names of the model's outputs (default: the first P of :data:`COEFFICIENTS`).
    """
    # the user's conditions are exact (no estimated regressors): no input-noise variance, but the model's
    # own error there (the training flight's common regressor offset, model discrepancy; docs/gp.md)
    mean, var_obs = model.predict(X, include_noise=True, input_noise=False)
    _, var = model.predict(X, include_noise=False, input_noise=False)
    names = tuple(output_names or COEFFICIENTS[: model.n_outputs])
    return Predictions(np.asarray(X), names, np.asarray(mean), np.sqrt(np.asarray(var)),
                       np.sqrt(np.asarray(var_obs)))


def _output_names(prefix: Path, n: int) -> tuple[str, ...]:
    """Coefficient names of the model's ``n`` outputs: the model file's names when they are
    coefficient names; else the replay's record beside it (``result/result.json``, ``gp_summary.outputs``:
    a replay fits only the coefficients it can identify and saves the model with generic names)."""
    import json

    def read(path: Path):
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError):
            return None

    meta = read(prefix.with_name(prefix.name + ".json")) or {}
    names = meta.get("output_names") if isinstance(meta, dict) else None
    if isinstance(names, list) and len(names) == n and all(x in COEFFICIENTS for x in names):
        return tuple(names)
    rec = read(prefix.parent / "result" / "result.json")
    outs = rec.get("gp_summary", {}).get("outputs") if isinstance(rec, dict) else None
    if isinstance(outs, list) and len(outs) == n and all(x in COEFFICIENTS for x in outs):
        return tuple(outs)
    if isinstance(names, list) and len(names) == n:
        return tuple(str(x) for x in names)
    return tuple(COEFFICIENTS[:n]) if n == len(COEFFICIENTS) else tuple(f"y{i}" for i in range(n))


def run_predict(model_dir: str | Path, inputs: str | Path, out: str | Path) -> Predictions:
    """Load the model, read the conditions, write the predictions CSV.

    Raises:
        InputError: missing model, bad conditions file, or a model that does not take the 10 regressors.

    A model fitted with mean-only inputs (the replay's ``alpha_dot_hat``, ``docs/gp.md``, "Mean-only inputs")
    reads them from columns of the same names when all are present; without them they are 0 (steady flight).
    """
    from .gp import load_gp

    prefix = model_prefix(model_dir)
    X, header, rows = read_conditions(inputs)
    model = load_gp(prefix)
    if model.n_inputs - model.n_mean_only != len(REGRESSORS):
        raise InputError(f"{prefix}.npz: model takes {model.n_inputs} regressors, expected {len(REGRESSORS)}")
    extra = list(model.input_names[len(REGRESSORS):])        # mean-only inputs (alpha_dot_hat): optional columns
    if extra and all(c in header for c in extra):
        cols = []
        for c in extra:
            try:
                v = np.array([float(r[header.index(c)]) for r in rows])
            except ValueError:
                v = np.array([math.nan])
            if not np.isfinite(v).all():
                raise InputError(f"{inputs}: column {c}: expected finite numbers")
            cols.append(v)
        X = np.concatenate([X, np.stack(cols, 1)], axis=1)
    pred = predict_conditions(model, X, _output_names(prefix, model.n_outputs))
    out_p = Path(out)
    try:
        with open(out_p, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header + [f"{c}_{k}" for c in pred.outputs for k in ("mean", "sigma", "sigma_obs")])
            for i, r in enumerate(rows):
                vals = [f"{v:.8g}" for j in range(len(pred.outputs))
                        for v in (pred.mean[i, j], pred.sigma[i, j], pred.sigma_obs[i, j])]
                w.writerow(r + vals)
    except OSError as exc:
        raise InputError(f"{out_p}: cannot write predictions ({exc.strerror})") from None
    return pred
