"""Saving and loading a fitted model as ``.npz`` arrays plus ``.json`` settings (no pickle)."""

from __future__ import annotations

import json
from pathlib import Path

import jax.numpy as jnp
import numpy as np

from ..errors import InputError
from ..jaxconfig import enable_x64
from .batching import global_posterior
from .config import GPConfig
from .local import LocalParams, build_store
from .model import LocalGlobalGP
from .scaling import Standardiser
from .sparse import GlobalParams, Stats

__all__ = ["save_model", "load_gp"]

FORMAT = "gcs-sysid-gp"
VERSION = 1
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

    Returns:
        The npz path as a string.
    """
    npz, js = _paths(path)
    arrays = model.scaler.to_arrays()
    arrays.update({"global_" + k: np.asarray(getattr(model.params, k)) for k in _GLOBAL})
    arrays.update({"stats_" + k: np.asarray(getattr(model.stats, k)) for k in _STATS})
    if model.local_params is not None and model.store is not None:
        arrays.update({"local_" + k: np.asarray(getattr(model.local_params, k)) for k in _LOCAL})
        arrays.update({"store_X": model.store.X, "store_resid": model.store.resid, "store_metric": model.store.metric})
    npz.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(npz, **arrays)
    meta = {"format": FORMAT, "version": VERSION, "config": model.config.to_dict(),
            "input_names": list(model.input_names), "output_names": list(model.output_names),
            "n_hyper": model.n_hyper, "notes": list(model.notes),
            "local_k": int(model.store.k) if model.store is not None else None,
            "summary": model.summary()}
    js.write_text(json.dumps(meta, indent=1))
    return str(npz)


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
        params = GlobalParams(**{k: jnp.asarray(a["global_" + k]) for k in _GLOBAL})
        stats = Stats(**{k: jnp.asarray(a["stats_" + k]) for k in _STATS})
    except (KeyError, ValueError, OSError) as exc:
        raise InputError(f"{npz}: GP model arrays missing or unreadable ({exc})") from None
    config = GPConfig.from_dict(meta.get("config", {}))
    local_params, store = None, None
    if "local_lengthscale" in a:
        local_params = LocalParams(**{k: jnp.asarray(a["local_" + k]) for k in _LOCAL})
        store = build_store(a["store_X"], a["store_resid"], a["store_metric"], int(meta["local_k"]))
    return LocalGlobalGP(config, scaler, params, stats, global_posterior(params, stats), local_params, store,
                         tuple(meta["input_names"]), tuple(meta["output_names"]), int(meta.get("n_hyper", 0)),
                         tuple(meta.get("notes", [])))
