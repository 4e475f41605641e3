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
    # on the CPU backend wherever the suite runs: stored executables are the CPU backend's (gcs_sysid.jaxconfig's
    # stored_jit), and with a CUDA jaxlib installed JAX would otherwise pick the GPU, where none is written
    full = dict(os.environ, PYTHONPATH=str(REPO), JAX_PLATFORMS="cpu", **env)
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
            "libs = {l.split()[-1] for l in maps.splitlines() "
            "if 'openblas' in os.path.basename(l.split()[-1]).lower()}\n"
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
used = len({k for k, p in {**jc._PROGRAMS, **jc._EXECUTABLES}.items() if p is not None})
print(json.dumps({"elbo": [float(v).hex() for v in hist.elbo], "local": [float(v).hex() for v in hist.local_loss],
                  "mean": [float(v).hex() for v in np.ravel(mean)], "var": [float(v).hex() for v in np.ravel(var)],
                  "stored": used}))
"""


def test_stored_gp_programs_give_the_jitted_results_and_are_loaded_by_the_next_process(tmp_path):
    import json

    cache = {"GCS_SYSID_JAX_CACHE": str(tmp_path / "jax")}
    first = json.loads(_child(STORED.replace("sys.argv[1]", "'export'"), cache).splitlines()[-1])
    files = sorted((tmp_path / "jax" / "traced").glob("*.jaxexport"))
    compiled = sorted((tmp_path / "jax" / "compiled").glob("*.jaxexe"))
    # the Adam steps of both layers and the other stored GP programs, each written once (traced and compiled)
    assert first["stored"] >= 2 and len(files) == first["stored"] == len(compiled)
    again = json.loads(_child(STORED.replace("sys.argv[1]", "'load'"), cache).splitlines()[-1])
    assert sorted((tmp_path / "jax" / "traced").glob("*.jaxexport")) == files
    assert sorted((tmp_path / "jax" / "compiled").glob("*.jaxexe")) == compiled
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


EXE = r"""
import json
import numpy as np
import jax, jax.numpy as jnp
from gcs_sysid.jaxconfig import enable_compilation_cache, enable_x64, stored_jit
import gcs_sysid.jaxconfig as jc
enable_x64()
enable_compilation_cache()

def solve(a, b):                                   # LAPACK custom calls (Cholesky, triangular solve) and a fusion
    l = jnp.linalg.cholesky(a @ a.T + 3.0 * jnp.eye(a.shape[0]))
    return jax.scipy.linalg.solve_triangular(l, b, lower=True), jnp.tanh(b).sum()

rng = np.random.default_rng(0)
x, s = stored_jit(solve)(rng.standard_normal((5, 5)), rng.standard_normal((5, 2)))
print(json.dumps({"bits": [float(v).hex() for v in np.ravel(x)] + [float(s).hex()],
                  "loaded": sum(isinstance(p, jc._Loaded) and p._call is p._compiled for p in jc._EXECUTABLES.values()),
                  "exported": sum(p is not None for p in jc._PROGRAMS.values())}))
"""


def _exe_run(env: dict) -> dict:
    import json

    return json.loads(_child(EXE, env).splitlines()[-1])


def test_stored_executable_is_loaded_by_the_next_process_and_gives_the_same_bits(tmp_path):
    cache = {"GCS_SYSID_JAX_CACHE": str(tmp_path / "jax")}
    first = _exe_run(cache)
    files = sorted((tmp_path / "jax" / "compiled").glob("*.jaxexe"))
    assert len(files) == 1 and first["loaded"] == 0 and first["exported"] == 1
    again = _exe_run(cache)
    assert again["loaded"] == 1 and again["exported"] == 0       # neither traced, lowered nor exported
    assert sorted((tmp_path / "jax" / "compiled").glob("*.jaxexe")) == files
    off = _exe_run({"GCS_SYSID_JAX_CACHE": "off", "XDG_CACHE_HOME": str(tmp_path / "xdg")})
    assert off["loaded"] == 0 and off["exported"] == 0 and not (tmp_path / "xdg").exists()   # cache off: no store
    assert first["bits"] == again["bits"] == off["bits"]


def test_corrupt_or_foreign_executable_falls_back_and_a_cache_hit_is_compiled_and_stored(tmp_path):
    import pickle

    cache = {"GCS_SYSID_JAX_CACHE": str(tmp_path / "jax")}
    first = _exe_run(cache)
    (path,) = (tmp_path / "jax" / "compiled").glob("*.jaxexe")
    good = path.read_bytes()
    header, digest, payload, in_tree, out_tree = pickle.loads(good)
    foreign = dict(header, jax="0.0.0")                          # written by another JAX (same file name)
    flipped = bytes([payload[0] ^ 1]) + payload[1:]              # one bit changed, the recorded hash kept
    for bad in (good[: len(good) // 2], pickle.dumps((foreign, digest, payload, in_tree, out_tree)),
                pickle.dumps((header, digest, flipped, in_tree, out_tree))):
        path.write_bytes(bad)
        run = _exe_run(cache)
        assert run["loaded"] == 0 and run["exported"] == 1 and run["bits"] == first["bits"]
    # the program is in JAX's compilation cache but its executable's file is gone (as after a change of the package's
    # source: a new key). What the cache loads lacks its code, so the program is compiled once more without the
    # cache and that executable is written; the next process loads it and runs it, with the same bits
    path.unlink()
    run = _exe_run(cache)
    assert run["bits"] == first["bits"] and run["loaded"] == 0 and run["exported"] == 1
    assert [p.name for p in (tmp_path / "jax" / "compiled").glob("*.jaxexe")] == [path.name]
    again = _exe_run(cache)
    assert again["loaded"] == 1 and again["exported"] == 0 and again["bits"] == first["bits"]


def test_loaded_executable_that_fails_on_its_first_call_gives_way_and_is_removed(tmp_path):
    from gcs_sysid.jaxconfig import _Loaded

    path = tmp_path / "x.jaxexe"
    path.write_bytes(b"x")

    def broken(*args):
        raise RuntimeError("NOT_FOUND: Function fusion not found")

    loaded = _Loaded(broken, lambda: (lambda a, b: a + b), path)
    assert loaded(2, 3) == 5 and loaded(1, 1) == 2 and not path.exists()
    working = _Loaded(lambda a: a * 2, lambda: None, tmp_path / "y.jaxexe")
    assert working(4) == 8 and working._call is working._compiled
