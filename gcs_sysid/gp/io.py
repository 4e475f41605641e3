"""Saving and loading a fitted model as ``.npz`` arrays plus ``.json`` settings (no pickle)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import jax.numpy as jnp
import numpy as np

from ..errors import InputError
from ..jaxconfig import enable_x64
from .batching import global_mean, global_posterior
from .config import GPConfig
from .local import LocalParams, build_store
from .model import LocalGlobalGP
from .rowstore import RowStore
from .scaling import Standardiser
from .sparse import GlobalParams, Stats

__all__ = ["save_model", "load_gp"]

FORMAT = "gcs-sysid-gp"
VERSION = 5   # 2: the region-thinned row store (rows_*) replaces store_X / store_resid
#               3: optional global_noise_chol (cross-correlated noise) and input_var (NIGP);
#                  stats_yy is (P, P), was its diagonal (P,)
#               4: optional global_lmc_lengthscale (J-1, D) and global_lmc_A (J-1, P, P) (linear model
#                  of coregionalisation); the statistics C, E, Rphi are then those of the J M stacked
#                  features. Files of versions 1-3 (one kernel) read unchanged. Optional var_scale (P,)
#                  (coloured residuals). Optional offset_cov (D, D) and discrepancy (2, P) (the model's
#                  error at exact conditions, gp/discrepancy.py); files without them read as before.
#                  Optional scale_var (D,) (the same, a common scale error; tenth session).
#                  Optional map_cov (D, D, D) (the same, the aided angles' common linear error; eleventh
#                  session); files without it read as before.
#               5: per-output statistics (rows with missing outputs, gp/sparse.py): stats_C (P, M, M),
#                  stats_E (P, M, D+1), stats_F (P, D+1, D+1), stats_n (P,). Written only by such models;
#                  a model with complete rows is still written as version 4.
_GLOBAL = ("lengthscale", "A", "noise", "Z", "prior_std", "jitter")
_STATS = ("C", "E", "F", "Rphi", "Rx", "yy", "n")
_LOCAL = ("lengthscale", "beta", "amp", "noise")


def _paths(path) -> tuple[Path, Path]:
    p = Path(path)
    if p.suffix in (".npz", ".json"):
        p = p.with_suffix("")
    return p.with_name(p.name + ".npz"), p.with_name(p.name + ".json")


def save_model(model: LocalGlobalGP, path) -> str:
    """Write ``model`` to ``<path>.npz`` and ``<path>.json`` (a ``.npz``/``.json`` suffix is replaced).

    The state is bounded: hyperparameters, the global statistics (``O(M^2)``) and at most
    ``config.store_max`` stored rows, however many rows the model has seen.

    Returns:
        The npz path as a string.
    """
    npz, js = _paths(path)
    arrays = model.scaler.to_arrays()
    arrays.update({"global_" + k: np.asarray(getattr(model.params, k)) for k in _GLOBAL})
    if model.input_var is not None:
        arrays["input_var"] = np.asarray(model.input_var)
    if model.var_scale is not None:
        arrays["var_scale"] = np.asarray(model.var_scale)
    for k in ("offset_cov", "discrepancy", "scale_var", "map_cov"):
        if getattr(model, k) is not None:
            arrays[k] = np.asarray(getattr(model, k))
    if model.params.noise_chol is not None:
        arrays["global_noise_chol"] = np.asarray(model.params.noise_chol)
    if model.params.lmc_lengthscale is not None:
        arrays["global_lmc_lengthscale"] = np.asarray(model.params.lmc_lengthscale)
        arrays["global_lmc_A"] = np.asarray(model.params.lmc_A)
    arrays.update({"stats_" + k: np.asarray(getattr(model.stats, k)) for k in _STATS})
    if model.local_params is not None:
        arrays.update({"local_" + k: np.asarray(getattr(model.local_params, k)) for k in _LOCAL})
    if model.evicted is not None:
        arrays.update({"evicted_" + k: np.asarray(getattr(model.evicted, k)) for k in _STATS})
    rows = model.rows
    if rows is not None:
        arrays.update({"rows_X": rows.X, "rows_Y": rows.Y, "rows_priority": rows.priority, "rows_weight": rows.weight,
                       "rows_cell_scale": rows.cell_scale})
    npz.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(npz, **arrays)
    meta = {"format": FORMAT, "version": VERSION if model.stats.per_output else 4, "config": model.config.to_dict(),
            "input_names": list(model.input_names), "output_names": list(model.output_names),
            "n_hyper": model.n_hyper, "notes": list(model.notes),
            "local_k": int(model.config.local_neighbours) if model.local_params is not None else None,
            "rows": None if rows is None else {"capacity": rows.capacity, "seen": rows.seen, "seed": rows.seed},
            "since_refresh": int(model.since_refresh),
            "summary": model.summary()}
    js.write_text(json.dumps(meta, indent=1))
    return str(npz)


def _stats(a: dict, prefix: str) -> Stats:
    """Statistics from the arrays; a version <= 2 file's ``yy`` (its diagonal, ``(P,)``) becomes ``diag(yy)``,
    exact for those files' independent noise (only the diagonal enters their likelihood)."""
    d = {k: np.asarray(a[prefix + k]) for k in _STATS}
    if d["yy"].ndim == 1:
        d["yy"] = np.diag(d["yy"])
    return Stats(**{k: jnp.asarray(v) for k, v in d.items()})


def load_gp(path) -> LocalGlobalGP:
    """Load a model written by :meth:`LocalGlobalGP.save`; the posterior is recomputed from its statistics.

    Args:
        path: ``<path>``, ``<path>.npz`` or ``<path>.json``.

    Raises:
        InputError: a file is missing or is not a gcs-sysid GP model.
    """
    enable_x64()
    npz, js = _paths(path)
    for f in (npz, js):
        if not f.is_file():
            raise InputError(f"{f}: GP model file not found (expected {npz.name} and {js.name})")
    try:
        meta = json.loads(js.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{js}: not a GP model description (invalid JSON: {exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise InputError(f"{js}: not a gcs-sysid GP model (format field is not {FORMAT!r})")
    if int(meta.get("version", 0)) > VERSION:
        raise InputError(f"{js}: GP model version {meta.get('version')} is newer than this gcs-sysid reads ({VERSION})")
    try:
        with np.load(npz, allow_pickle=False) as f:
            a = {k: f[k] for k in f.files}
        scaler = Standardiser.from_arrays(a)
        opt = {k: jnp.asarray(a["global_" + k]) for k in ("noise_chol", "lmc_lengthscale", "lmc_A")
               if "global_" + k in a}
        params = GlobalParams(**{k: jnp.asarray(a["global_" + k]) for k in _GLOBAL}, **opt)
        if (params.lmc_lengthscale is None) != (params.lmc_A is None):
            raise ValueError("global_lmc_lengthscale and global_lmc_A must come together")
        stats = _stats(a, "stats_")
        evicted = _stats(a, "evicted_") if "evicted_C" in a else None
    except (KeyError, ValueError, OSError) as exc:
        raise InputError(f"{npz}: GP model arrays missing or unreadable ({exc})") from None
    config = GPConfig.from_dict(meta.get("config", {}))
    post = global_posterior(params, stats)
    local_params, store, rows = None, None, None
    if "local_lengthscale" in a:
        local_params = LocalParams(**{k: jnp.asarray(a["local_" + k]) for k in _LOCAL})
    try:
        if "rows_X" in a:
            r = meta.get("rows") or {}
            rows = RowStore(a["rows_X"], a["rows_Y"], a["rows_priority"], a["rows_cell_scale"],
                            int(r.get("capacity", config.store_max)), a["rows_weight"],
                            int(r.get("seen", len(a["rows_X"]))), int(r.get("seed", config.seed)))
        elif "store_X" in a:      # version 1: the local store's rows and residuals; targets = residual + global mean
            store = build_store(a["store_X"], a["store_resid"], a["store_metric"], int(meta["local_k"]))
            Y = a["store_resid"] + global_mean(params, post, a["store_X"], config.batch_size)
            rows = RowStore.empty(len(a["scaler_x_mean"]), Y.shape[1], np.asarray(params.metric_lengthscale()),
                                  config.store_cell, max(config.store_max, len(Y)), config.seed)
            rows = replace(rows, X=a["store_X"], Y=Y, priority=np.random.default_rng(config.seed).random(len(Y)),
                           seen=len(Y))
    except (KeyError, ValueError) as exc:
        raise InputError(f"{npz}: GP model's stored rows missing or unreadable ({exc})") from None
    return LocalGlobalGP(config, scaler, params, stats, post, local_params, store,
                         tuple(meta["input_names"]), tuple(meta["output_names"]), int(meta.get("n_hyper", 0)),
                         tuple(meta.get("notes", [])), rows=rows, since_refresh=int(meta.get("since_refresh", 0)),
                         evicted=evicted, input_var=a.get("input_var"), var_scale=a.get("var_scale"),
                         offset_cov=a.get("offset_cov"), discrepancy=a.get("discrepancy"),
                         scale_var=a.get("scale_var"), map_cov=a.get("map_cov"))
