"""The one place where gcs-sysid configures JAX.

The GP (Cholesky factors of kernel matrices with small noise) and the 6-DOF
simulation (RK4 over minutes of flight) need 64-bit floats. JAX defaults to
32-bit, and the switch is process-wide, so it is flipped here, explicitly, by
the entry points that need it (``gp`` and ``sim`` public functions, the CLI and
the test suite) and never as an import-time side effect.

Compiling the GP's functions with XLA takes seconds per process, more than
running them on one flight. :func:`enable_compilation_cache` turns on JAX's
persistent compilation cache so that only the first run on a machine pays for
it; the replay pipeline and the CLI call it explicitly (never on import).

The GP's linear algebra is many small factorisations and solves (32x32 to
~900x900) that JAX and SciPy hand to OpenBLAS. OpenBLAS threads them over
all cores, and for matrices this small the thread hand-off costs more than the
arithmetic: on the 2-core benchmark machine a 32x32 triangular solve with 1000
right-hand sides took 8 ms threaded and 0.2 ms on one thread (with other jobs
running). :func:`limit_blas_threads` sets the OpenBLAS thread count at run time.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["enable_x64", "enable_compilation_cache", "default_cache_dir", "limit_blas_threads"]

#: Environment variable that overrides the cache directory; set it to ``"off"`` to disable the cache.
CACHE_ENV = "GCS_SYSID_JAX_CACHE"


def enable_x64() -> None:
    """Switch JAX to 64-bit floats (idempotent).

    Called by every public GP and simulation function before it creates arrays.
    """
    import jax

    if not jax.config.read("jax_enable_x64"):
        jax.config.update("jax_enable_x64", True)


def default_cache_dir() -> Path:
    """Where compiled XLA programs are kept: ``$GCS_SYSID_JAX_CACHE``, else
    ``$XDG_CACHE_HOME/gcs-sysid/jax``, else ``~/.cache/gcs-sysid/jax``."""
    env = os.environ.get(CACHE_ENV, "").strip()
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME", "").strip()
    return (Path(base).expanduser() if base else Path.home() / ".cache") / "gcs-sysid" / "jax"


def enable_compilation_cache(path: str | os.PathLike | None = None, min_compile_time_s: float = 0.0) -> Path | None:
    """Turn on JAX's persistent compilation cache (idempotent; process-wide).

    A jitted function compiled once on this machine is then loaded from disk by later
    processes (tens of milliseconds instead of seconds). Results are identical: the
    cache holds the compiled XLA executables keyed by the program, the JAX/XLA versions
    and the backend.

    Args:
        path: cache directory (created); None: :func:`default_cache_dir`. The value
            ``"off"`` (or ``GCS_SYSID_JAX_CACHE=off``) leaves the cache disabled.
        min_compile_time_s: programs that compile faster than this are not stored (default 0: all are;
            loading even a small program from the cache is several times faster than compiling it).

    Returns:
        The cache directory, or None when disabled or the directory cannot be created
        (then JAX simply compiles as usual).
    """
    import jax

    if path is None and os.environ.get(CACHE_ENV, "").strip().lower() == "off":
        return None
    if path is not None and str(path).strip().lower() == "off":
        return None
    target = Path(path).expanduser() if path is not None else default_cache_dir()
    current = jax.config.jax_compilation_cache_dir
    if current:                      # already configured (by us or by the user): keep it
        return Path(current)
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    jax.config.update("jax_compilation_cache_dir", str(target))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", float(min_compile_time_s))
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    return target




_BLAS_LIMIT = None  # keeps the threadpoolctl limiter alive


def limit_blas_threads(n: int = 1) -> int:
    """Set the thread count of every BLAS loaded by NumPy and SciPy (which JAX's CPU LAPACK
    calls use) to ``n`` (process-wide; idempotent), with threadpoolctl.

    OpenBLAS's own threading made the GP's many small matrix operations 10-35x slower on a
    2-core machine (a 32x32 triangular solve took 8 ms instead of 0.23 ms; ``docs/gp.md``).
    ``OPENBLAS_NUM_THREADS=1`` set before start-up has the same effect.

    Args:
        n: threads per BLAS call (>= 1).

    Returns:
        The number of BLAS libraries changed.
    """
    import numpy  # noqa: F401  (loads NumPy's BLAS)
    import scipy.linalg  # noqa: F401  (loads SciPy's BLAS)
    from threadpoolctl import threadpool_info, threadpool_limits

    global _BLAS_LIMIT
    _BLAS_LIMIT = threadpool_limits(limits=max(int(n), 1), user_api="blas")
    return sum(1 for lib in threadpool_info() if lib.get("user_api") == "blas")
