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

__all__ = ["enable_x64", "enable_compilation_cache", "default_cache_dir", "limit_blas_threads", "stored_program",
           "stored_jit"]

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


#: Bumped when the layout of :func:`stored_program`'s files or its key changes.
_STORED_FORMAT = 1
_SOURCE_HASH: str | None = None
_PROGRAMS: dict[str, object] = {}
#: This process's programs by (functions, tree structure, avals): a repeated call skips the key's hashing.
_MEMO: dict[tuple, object] = {}


def _source_hash() -> str:
    """SHA-256 of every ``.py`` file of the installed gcs_sysid package (path and bytes), once per process."""
    global _SOURCE_HASH
    if _SOURCE_HASH is None:
        import hashlib

        root = Path(__file__).resolve().parent
        h = hashlib.sha256()
        for f in sorted(root.rglob("*.py")):
            h.update(str(f.relative_to(root)).encode())
            h.update(f.read_bytes())
        _SOURCE_HASH = h.hexdigest()
    return _SOURCE_HASH


_NAMED: set[type] = set()


def _register_type(cls, empty) -> None:
    """Register one node type for ``jax.export``'s serialisation under ``module.qualname``: a NamedTuple as such, any
    other registered node with ``empty`` (``()`` or None) as its auxiliary data."""
    import jax

    if cls in _NAMED:
        return
    name = f"{cls.__module__}.{cls.__qualname__}"
    try:
        if issubclass(cls, tuple) and hasattr(cls, "_fields"):
            jax.export.register_namedtuple_serialization(cls, serialized_name=name)
        else:
            jax.export.register_pytree_node_serialization(
                cls, serialized_name=name, serialize_auxdata=lambda aux: b"",
                deserialize_auxdata=lambda b, empty=empty: empty)
    except ValueError:          # already registered (by another package, or an earlier call)
        pass
    _NAMED.add(cls)


def _node_types(tree) -> dict | None:
    """The custom node types of a PyTreeDef, ``{cls: its auxiliary data}``; None if one carries auxiliary data other
    than ``()`` or None (the serialisation could not restore it) and is not a NamedTuple."""
    found, todo = {}, [tree]
    while todo:
        node = todo.pop()
        data = node.node_data()
        if data is not None and data[0] not in (tuple, list, dict, type(None)):
            cls = data[0]
            if not (issubclass(cls, tuple) and hasattr(cls, "_fields")) and data[1] not in ((), None):
                return None
            found[cls] = data[1]
        todo.extend(node.children())
    return found


def _register_tree(tree) -> bool:
    """Register every custom node type of ``tree`` (:func:`_register_type`); False if one cannot be (:func:`_node_types`)."""
    types = _node_types(tree)
    if types is None:
        return False
    for cls, empty in types.items():
        _register_type(cls, empty)
    return True


def _register_listed(path: Path) -> None:
    """Register the node types named in a stored program's ``.types`` file (``module:qualname:tuple|none`` lines,
    written beside it) before it is read: :func:`jax.export.deserialize` must know every node type of the program's
    input and output trees."""
    import importlib

    for line in path.read_text().split():
        module, qualname, empty = line.split(":")
        cls = importlib.import_module(module)
        for part in qualname.split("."):
            cls = getattr(cls, part)
        _register_type(cls, () if empty == "tuple" else None)


def stored_program(fn, args: tuple, static: tuple = ()):
    """``fn`` traced and lowered once per machine: the traced program kept on disk, beside the compilation cache.

    JAX's persistent compilation cache (:func:`enable_compilation_cache`) skips XLA's compilation, but each process
    still traces the Python function and lowers it to StableHLO before it can look the program up: in a loaded
    profile of the replay, 4.5 of its main process's 27.6 busy seconds, 2.8 of them the GP's Adam steps (the gradient
    of the bound; ``docs/benchmarks.md``, "Twenty-seventh session, speed27"). Here the lowered program is
    exported with :func:`jax.export.export` and serialised (``Exported.serialize``, flatbuffers) into ``<cache>/traced/`` and later processes deserialise it instead
    of tracing (the JAX manual, "Exporting and serializing staged-out computations"). The program is the same
    StableHLO, so XLA compiles (or loads) the same computation and the results are identical.

    The file's key is the module and name of ``fn`` and of each ``static`` function, the tree structure and the
    shape, dtype and weak type of every leaf of ``args``, the SHA-256 of the gcs_sysid package's source, the JAX,
    jaxlib, optax and NumPy versions, the backend and the 64-bit and matmul-precision flags; any change of the code
    gives a new key (old files are left, unused). The files are trusted as the compilation cache's are (written by
    this package on this machine).

    Args:
        fn: a module-level function, called as ``fn(*static, *args)`` (no closure: what it computes must follow
            from its code and ``args``' structure alone).
        args: the positional arguments of one call (arrays, Python scalars, None, tuples, lists and dicts of them).
        static: module-level functions passed first (e.g. the loss of an optimiser step), each part of the key.

    Returns:
        A callable ``program(*args)`` (arguments of the same structure, shapes and dtypes) returning what
        ``fn(*static, *args)`` returns; None when the compilation cache is off (no directory: the caller calls
        its jitted function as before), ``fn`` has a closure, or the export or the file fails (then this process
        keeps using the caller's path for that key).

    Raises:
        nothing: every failure returns None.
    """
    import jax

    cache = jax.config.jax_compilation_cache_dir
    funcs = (fn, *static)
    if not cache or any(getattr(f, "__closure__", True) is not None or "<locals>" in f.__qualname__ for f in funcs):
        return None
    try:
        import hashlib

        import jaxlib
        import numpy
        import optax

        leaves, tree = jax.tree_util.tree_flatten(args)
        avals = tuple(jax.typeof(x) for x in leaves)
        memo = (funcs, tree, avals)
        if memo in _MEMO:
            return _MEMO[memo]
        parts = [str(_STORED_FORMAT), *(f"{f.__module__}.{f.__qualname__}" for f in funcs), str(tree),
                 ";".join(f"{a.shape}:{a.dtype}:{a.weak_type}" for a in avals), _source_hash(), jax.__version__,
                 jaxlib.__version__, optax.__version__, numpy.__version__, jax.default_backend(),
                 str(jax.config.jax_enable_x64), str(jax.config.jax_default_matmul_precision)]
        key = hashlib.sha256("\n".join(parts).encode()).hexdigest()
    except Exception:
        return None
    if key in _PROGRAMS:
        _MEMO[memo] = _PROGRAMS[key]
        return _PROGRAMS[key]
    if not _register_tree(tree):     # a node type JAX's serialisation cannot restore: the caller's jit
        _PROGRAMS[key] = _MEMO[memo] = None
        return None
    path = Path(cache) / "traced" / f"{key}.jaxexport"
    exported = None
    try:
        if path.exists():
            _register_listed(path.with_suffix(".types"))
            exported = jax.export.deserialize(bytearray(path.read_bytes()))
    except Exception:          # unreadable or foreign: exported again below
        exported = None
    try:
        if exported is None:
            def staged(*xs):
                return fn(*static, *xs)

            specs = jax.tree_util.tree_unflatten(tree, [jax.ShapeDtypeStruct(a.shape, a.dtype, weak_type=a.weak_type)
                                                        for a in avals])
            # JAX's own serialisation (flatbuffers; no VJP: the stored program is only called, never differentiated)
            exported = jax.export.export(jax.jit(staged))(*specs)
            types = _node_types(exported.out_tree)
            if types is None or not _register_tree(exported.out_tree):
                raise ValueError("an output node with auxiliary data")
            types.update(_node_types(exported.in_tree))
            blob = exported.serialize()
            path.parent.mkdir(parents=True, exist_ok=True)
            listed = path.with_suffix(f".{os.getpid()}.types.tmp")    # the node types a later process registers first
            listed.write_text("\n".join(sorted(f"{c.__module__}:{c.__qualname__}:{'none' if e is None else 'tuple'}"
                                                for c, e in types.items())))
            os.replace(listed, path.with_suffix(".types"))
            exported = jax.export.deserialize(blob)
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_bytes(bytes(blob))
            os.replace(tmp, path)
        program = jax.jit(exported.call)
    except Exception:
        program = None
    _PROGRAMS[key] = _MEMO[memo] = program
    return program


class _StoredJit:
    """:func:`stored_jit`'s wrapper."""

    def __init__(self, fn):
        import functools

        import jax

        functools.update_wrapper(self, fn)
        self._fn, self._jit = fn, jax.jit(fn)

    def __call__(self, *args, **kwargs):
        program = None if kwargs else stored_program(self._fn, args)
        return self._jit(*args, **kwargs) if program is None else program(*args)


def stored_jit(fn):
    """``jax.jit(fn)`` whose traced program is kept on disk (:func:`stored_program`) when the compilation cache is on.

    Args:
        fn: a module-level function of arrays (and pytrees of them), no closure.

    Returns:
        A callable with ``fn``'s signature: positional calls use the stored program (traced once per machine and
        argument structure), keyword calls and calls without a cache directory the plain ``jax.jit(fn)``. The results
        are the same either way.

    Raises:
        what ``fn`` raises when traced.
    """
    return _StoredJit(fn)
