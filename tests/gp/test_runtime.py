"""Run-time settings of the GP: early stopping, the persistent compilation cache, BLAS threads."""

import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gp_data import FAST, flight_regressors, linear_truth
from gcs_sysid.errors import InputError
from gcs_sysid.gp import GPConfig, fit_gp

REPO = Path(__file__).resolve().parents[2]


def test_early_stopping_stops_on_a_plateau_and_tol_zero_runs_every_step():
    X = flight_regressors(200, seed=3)
    Y = linear_truth(X) + 1e-3 * np.random.default_rng(4).standard_normal((200, 6))
    cfg = replace(FAST, steps=120, local=False, reselect=False)
    _, every = fit_gp(X, Y, replace(cfg, tol=0.0))
    _, early = fit_gp(X, Y, replace(cfg, tol=10.0))      # any window improves by less than 10 nats/point
    assert len(every.elbo) == 120
    assert len(early.elbo) == 20                          # two windows of 10 steps, then the plateau test stops it
    np.testing.assert_allclose(early.elbo, every.elbo[:20], rtol=1e-9)


def test_negative_tol_is_rejected():
    with pytest.raises(InputError, match="tol"):
        GPConfig(tol=-1.0)


def _child(code: str, env: dict) -> str:
    full = dict(os.environ, PYTHONPATH=str(REPO), **env)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=full, check=True,
                          timeout=120).stdout


def test_compilation_cache_is_written_and_can_be_switched_off(tmp_path):
    code = ("import jax, jax.numpy as jnp\n"
            "from gcs_sysid.jaxconfig import enable_compilation_cache\n"
            "print(enable_compilation_cache(min_compile_time_s=0.0))\n"
            "jax.jit(lambda x: jnp.linalg.cholesky(x @ x.T + 3 * jnp.eye(3)))(jnp.ones((3, 3))).block_until_ready()\n")
    out = _child(code, {"GCS_SYSID_JAX_CACHE": str(tmp_path / "jax")})
    assert out.strip() == str(tmp_path / "jax")
    assert any(p.is_file() for p in (tmp_path / "jax").rglob("*"))     # a compiled program was stored
    assert _child(code, {"GCS_SYSID_JAX_CACHE": "off"}).strip() == "None"


def test_limit_blas_threads_sets_every_loaded_openblas_to_one_thread():
    code = ("import os, numpy as np, scipy.linalg\n"
            "from gcs_sysid.jaxconfig import limit_blas_threads\n"
            "n = limit_blas_threads(1)\n"
            "maps = open('/proc/self/maps').read() if os.path.exists('/proc/self/maps') else ''\n"
            "libs = {l.split()[-1] for l in maps.splitlines() if 'openblas' in os.path.basename(l.split()[-1]).lower()}\n"
            "a = np.random.default_rng(0).standard_normal((50, 50))\n"
            "print(n, len(libs), float(np.abs(np.linalg.solve(a, a) - np.eye(50)).max()) < 1e-8)\n")
    n, n_libs, ok = _child(code, {}).split()
    assert int(n) == int(n_libs) and ok == "True"     # each loaded OpenBLAS was found and set; results unchanged


STORED = r"""
import json, sys
import numpy as np
from dataclasses import replace
import jax
from gcs_sysid.jaxconfig import enable_compilation_cache, enable_x64
import gcs_sysid.jaxconfig as jc
enable_x64()
enable_compilation_cache()
if sys.argv[1] == "load":                          # this process must find the program on disk, never export it
    def refuse(*a, **k):
        raise AssertionError("exported again")
    jax.export.export = refuse
from gcs_sysid.gp import GPConfig, fit_gp
rng = np.random.default_rng(5)
X = rng.uniform(-1, 1, (300, 10))
Y = X[:, :6] * np.array([1.0, -0.5, 0.3, 0.8, -1.2, 0.4]) + 0.05 * rng.standard_normal((300, 6))
model, hist = fit_gp(X, Y, GPConfig(n_inducing=12, steps=30, local_steps=10, seed=1))
mean, var = model.predict(X[:7])
used = sum(p is not None for p in jc._PROGRAMS.values())
print(json.dumps({"elbo": [float(v).hex() for v in hist.elbo], "local": [float(v).hex() for v in hist.local_loss],
                  "mean": [float(v).hex() for v in np.ravel(mean)], "var": [float(v).hex() for v in np.ravel(var)],
                  "stored": used}))
"""


def test_stored_gp_programs_give_the_jitted_results_and_are_loaded_by_the_next_process(tmp_path):
    import json

    cache = {"GCS_SYSID_JAX_CACHE": str(tmp_path / "jax")}
    first = json.loads(_child(STORED.replace("sys.argv[1]", "'export'"), cache).splitlines()[-1])
    files = sorted((tmp_path / "jax" / "traced").glob("*.jaxexport"))
    # the Adam steps of both layers and the other stored GP programs, each written once
    assert first["stored"] >= 2 and len(files) == first["stored"]
    again = json.loads(_child(STORED.replace("sys.argv[1]", "'load'"), cache).splitlines()[-1])
    assert sorted((tmp_path / "jax" / "traced").glob("*.jaxexport")) == files
    off = {"GCS_SYSID_JAX_CACHE": "off"}
    plain = json.loads(_child(STORED.replace("sys.argv[1]", "'export'"), off).splitlines()[-1])
    assert plain["stored"] == 0
    for k in ("elbo", "local", "mean", "var"):                # bit for bit: the same program either way
        assert first[k] == plain[k] and again[k] == plain[k], k
    assert again["stored"] == first["stored"]                 # every one loaded (exporting again raises there)


def test_stored_program_refuses_a_closure():
    import jax.numpy as jnp

    from gcs_sysid.jaxconfig import stored_program

    k = 2.0
    closure = lambda x: (x * k,)                             # noqa: E731  (what it computes is not in its code)
    assert stored_program(closure, (jnp.ones(3),)) is None
