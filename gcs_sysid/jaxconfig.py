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
#: This process's compiled executables by the same key (:func:`_load_executable`, :func:`_store_executable`).
_EXECUTABLES: dict[str, object] = {}
#: This process's programs by (functions, tree structure, avals, concrete): a repeated call skips the key's hashing.
_MEMO: dict[tuple, object] = {}
#: Bumped when the layout of the compiled executables' files (:func:`_store_executable`) changes.
_EXECUTABLE_FORMAT = 1


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
    """Register every custom node type of ``tree`` (:func:`_register_type`); False if one cannot be
    (:func:`_node_types`)."""
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


def _ensure_lapack() -> None:
    """Register jaxlib's LAPACK kernels (the custom calls of the CPU executables' Cholesky factors and triangular
    solves), as lowering a linear-algebra operation (or calling an exported program) does.

    An executable loaded from disk is never lowered in this process, and calling its LAPACK custom calls before they
    are registered crashed the process (a segmentation fault, jax 0.10.2, CPU). This is JAX's private
    ``jax._src.lax.linalg.initialize_lapack`` (what ``jax.export``'s call lowering runs); if it is missing the caller
    does not load executables.

    Raises:
        AttributeError, ImportError: this JAX has no such function.
    """
    from jax._src.lax import linalg

    linalg.initialize_lapack()


def _executable_header(key: str) -> dict:
    """What a stored executable must match to be loaded: the program's key (:func:`stored_program`: its code, the
    argument structure and avals, the package source, the versions, the backend, the 64-bit flag) and, beside it,
    the format, the JAX and jaxlib versions, the backend and its platform version, the first device's kind, the
    device count, the 64-bit flag and ``XLA_FLAGS`` (an executable is machine code for one backend and device)."""
    import jax
    import jaxlib

    device = jax.devices()[0]
    return {"format": _EXECUTABLE_FORMAT, "key": key, "jax": jax.__version__, "jaxlib": jaxlib.__version__,
            "backend": jax.default_backend(), "platform_version": str(device.client.platform_version),
            "device_kind": str(device.device_kind), "devices": jax.device_count(),
            "x64": bool(jax.config.jax_enable_x64), "xla_flags": os.environ.get("XLA_FLAGS", "")}


def _executable_path(cache: str | os.PathLike, header: dict) -> Path:
    """``<cache>/compiled/<sha256 of the header>.jaxexe``: a different JAX, device or flag gives another file."""
    import hashlib
    import json

    name = hashlib.sha256(json.dumps(header, sort_keys=True).encode()).hexdigest()
    return Path(cache) / "compiled" / f"{name}.jaxexe"


def _load_executable(cache: str | os.PathLike, key: str):
    """The compiled executable stored for ``key`` by an earlier process (:func:`_store_executable`), loaded.

    The file is a pickle of ``(header, sha256 of the payload, payload, input tree, output tree)``; it is used only
    if its header equals this process's (:func:`_executable_header`) and the payload's hash matches (a truncated or
    altered file is never handed to XLA). The payload is :func:`jax.experimental.serialize_executable.serialize`'s:
    the executable XLA compiled, which ``deserialize_and_load`` loads without tracing, lowering or looking the
    program up in the compilation cache.

    Returns:
        ``(compiled, path)``: the :class:`jax.stages.Compiled` and its file; None when there is no file or it cannot
        be used (no error is raised: the caller compiles as before).
    """
    import hashlib
    import pickle

    try:
        header = _executable_header(key)
        path = _executable_path(cache, header)
        if not path.exists():
            return None
        from jax.experimental import serialize_executable

        stored, digest, payload, in_tree, out_tree = pickle.loads(path.read_bytes())
        if stored != header or hashlib.sha256(payload).hexdigest() != digest:
            return None
        _ensure_lapack()
        return serialize_executable.deserialize_and_load(payload, in_tree, out_tree), path
    except Exception:
        return None


_CACHE_HITS = [0]          # persistent-cache hits seen by :func:`_count_hit` (registered once)
_COUNTING: list = []


def _count_hit(event: str, **_) -> None:
    """A :mod:`jax.monitoring` listener: counts the compilation cache's hits (``/jax/compilation_cache/cache_hits``)."""
    if event == "/jax/compilation_cache/cache_hits":
        _CACHE_HITS[0] += 1


def _store_executable(cache: str | os.PathLike, key: str, program, args: tuple):
    """Compile ``program`` (a jitted function) for ``args`` as its call would, and write the executable atomically
    (a temporary file renamed) for :func:`_load_executable`.

    ``program.lower(*args).compile()`` is the path ``program(*args)`` takes (trace, lower, compile or load from the
    compilation cache), so the executable is the one the call would run. Only an executable XLA compiled in this
    process is written: one that the compilation cache loaded serialises without its code (jax 0.10.2, CPU: a later
    process's call failed with "NOT_FOUND: Function convert_copy_fusion not found"). A cache hit (the same program
    under a new key: the package's source changed, the program did not) is therefore compiled once more without the
    cache (:func:`_compile_uncached`) and that executable is written; without it every later process traced, lowered
    and looked the program up again (about 0.5 s of the benchmark replay's main process, thirty-third session,
    speed33). Writing is best effort.

    Returns:
        The :class:`jax.stages.Compiled` (also when nothing was written), or None when this program cannot be
        compiled ahead (the caller keeps ``program``).
    """
    import hashlib
    import pickle

    import jax

    try:
        if not _COUNTING:
            jax.monitoring.register_event_listener(_count_hit)
            _COUNTING.append(True)
        hits = _CACHE_HITS[0]
        compiled = program.lower(*args).compile()
    except Exception:
        return None
    if _CACHE_HITS[0] != hits:
        fresh = _compile_uncached(program, args)
        if fresh is None:
            return compiled                   # as loaded from the cache: nothing to write
        compiled = fresh
    try:
        from jax.experimental import serialize_executable

        payload, in_tree, out_tree = serialize_executable.serialize(compiled)
        header = _executable_header(key)
        blob = pickle.dumps((header, hashlib.sha256(payload).hexdigest(), payload, in_tree, out_tree),
                            protocol=pickle.HIGHEST_PROTOCOL)
        path = _executable_path(cache, header)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_bytes(blob)
        os.replace(tmp, path)
    except Exception:
        pass
    return compiled


def _compile_uncached(program, args: tuple):
    """``program`` (a jitted function) compiled for ``args`` by XLA in this process, not loaded from JAX's
    persistent compilation cache: for this one compilation the cache is off (``jax_enable_compilation_cache``; JAX
    decides once per process whether it uses the cache, so its private ``compilation_cache.reset_cache`` makes it
    decide again, before and after) and JAX's in-memory caches are cleared (:func:`jax.clear_caches`: else the
    lowering and the executable just loaded would be handed back). The same program compiled by the same XLA: the
    executable that a run with an empty cache compiles and writes.

    Returns:
        The :class:`jax.stages.Compiled`, or None when this JAX lacks ``reset_cache`` or the compilation fails
        (nothing is raised; the cache is on again either way).
    """
    import jax

    try:
        from jax._src import compilation_cache
    except ImportError:
        return None
    reset = getattr(compilation_cache, "reset_cache", None)
    if reset is None:
        return None
    was = jax.config.jax_enable_compilation_cache
    try:
        jax.config.update("jax_enable_compilation_cache", False)
        reset()
        jax.clear_caches()
        return program.lower(*args).compile()
    except Exception:
        return None
    finally:
        jax.config.update("jax_enable_compilation_cache", was)
        reset()


class _Loaded:
    """A loaded executable (:func:`_load_executable`) that gives way to ``fallback()`` (a zero-argument callable
    returning the exported program, or ``jax.jit`` of the function) if its first call raises: the file is then removed
    and the call made again by the fallback, so a stored executable that loads but cannot run costs one failed call,
    never a missing result."""

    __slots__ = ("_call", "_compiled", "_fallback", "_path")

    def __init__(self, compiled, fallback, path: Path):
        self._compiled, self._fallback, self._path = compiled, fallback, path
        self._call = self._first

    def __call__(self, *args):
        return self._call(*args)

    def _first(self, *args):
        try:
            out = self._compiled(*args)
        except Exception:
            try:
                self._path.unlink()
            except OSError:
                pass
            self._call = self._fallback()
            return self._call(*args)
        self._call = self._compiled
        return out


def stored_program(fn, args: tuple, static: tuple = ()):
    """``fn`` traced, lowered and compiled once per machine: the traced program and the compiled executable kept on
    disk, beside the compilation cache.

    JAX's persistent compilation cache (:func:`enable_compilation_cache`) skips XLA's compilation, but each process
    still traces the Python function and lowers it to StableHLO before it can look the program up: in a loaded
    profile of the replay, 4.5 of its main process's 27.6 busy seconds, 2.8 of them the GP's Adam steps (the gradient
    of the bound; ``docs/benchmarks.md``, "Twenty-seventh session, speed27"). Here the lowered program is
    exported with :func:`jax.export.export` and serialised (``Exported.serialize``, flatbuffers) into
    ``<cache>/traced/`` and later processes deserialise it instead of tracing (the JAX manual, "Exporting and
    serializing staged-out computations"). The program is the same StableHLO, so XLA compiles (or loads) the same
    computation and the results are identical.

    Calling the exported program still traces and lowers a wrapper of it and looks it up in the compilation cache
    (about 0.9 s for the replay's 23 stored programs; ``docs/benchmarks.md``, "Thirtieth session, speed30"). So
    the executable compiled for a concrete call is also serialised
    (:func:`jax.experimental.serialize_executable.serialize`) into ``<cache>/compiled/`` (:func:`_store_executable`),
    and later processes load it (:func:`_load_executable`; 0.35 s for the same programs): the same executable, so the
    same bits. Calls with tracers (``fn`` called inside another traced function) and other backends than the CPU use
    the exported program.

    The file's key is the module and name of ``fn`` and of each ``static`` function, the tree structure and the
    shape, dtype and weak type of every leaf of ``args``, the SHA-256 of the gcs_sysid package's source, the JAX,
    jaxlib, optax and NumPy versions, the backend and the 64-bit and matmul-precision flags; any change of the code
    gives a new key (old files are left, unused). An executable's file is keyed by that key and the device
    (:func:`_executable_header`). The files are trusted as the compilation cache's are (written by this package on
    this machine; an executable's loader runs what it loads).

    Args:
        fn: a module-level function, called as ``fn(*static, *args)`` (no closure: what it computes must follow
            from its code and ``args``' structure alone).
        args: the positional arguments of one call (arrays, Python scalars, None, tuples, lists and dicts of them).
        static: module-level functions passed first (e.g. the loss of an optimiser step), each part of the key.

    Returns:
        A callable ``program(*args)`` (arguments of the same structure, shapes and dtypes) returning what
        ``fn(*static, *args)`` returns; None when the compilation cache is off (no directory: the caller calls
        its jitted function as before, and nothing is stored), ``fn`` has a closure, or the export or the file fails
        (then this process keeps using the caller's path for that key). An executable that cannot be loaded, compiled
        or written is skipped silently (the exported program is returned).

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
        # executables only for concrete calls on the CPU (the backend whose custom calls _ensure_lapack registers)
        concrete = jax.default_backend() == "cpu" and not any(isinstance(x, jax.core.Tracer) for x in leaves)
        memo = (funcs, tree, avals, concrete)
        if memo in _MEMO:
            return _MEMO[memo]
        parts = [str(_STORED_FORMAT), *(f"{f.__module__}.{f.__qualname__}" for f in funcs), str(tree),
                 ";".join(f"{a.shape}:{a.dtype}:{a.weak_type}" for a in avals), _source_hash(), jax.__version__,
                 jaxlib.__version__, optax.__version__, numpy.__version__, jax.default_backend(),
                 str(jax.config.jax_enable_x64), str(jax.config.jax_default_matmul_precision)]
        key = hashlib.sha256("\n".join(parts).encode()).hexdigest()
    except Exception:
        return None
    def exported():
        if key not in _PROGRAMS:
            _PROGRAMS[key] = _exported_program(fn, static, tree, avals, cache, key)
        return _PROGRAMS[key]

    def fallback():             # a stored executable failed on its first call: the exported program, else a plain jit
        import functools

        return exported() or jax.jit(functools.partial(fn, *static))

    if concrete:
        if key not in _EXECUTABLES:
            loaded = _load_executable(cache, key)
            _EXECUTABLES[key] = None if loaded is None else _Loaded(loaded[0], fallback, loaded[1])
        if _EXECUTABLES[key] is not None:
            _MEMO[memo] = _EXECUTABLES[key]
            return _EXECUTABLES[key]
    program = exported()
    if concrete and program is not None:
        _EXECUTABLES[key] = _store_executable(cache, key, program, args)
        if _EXECUTABLES[key] is not None:
            program = _EXECUTABLES[key]
    _MEMO[memo] = program
    return program


def _exported_program(fn, static: tuple, tree, avals: tuple, cache: str, key: str):
    """:func:`stored_program`'s traced program for ``key``: ``jax.jit`` of the exported program read from
    ``<cache>/traced/``, or exported and written there; None when ``tree`` or the output cannot be serialised or the
    export fails."""
    import jax

    if not _register_tree(tree):     # a node type JAX's serialisation cannot restore: the caller's jit
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
        return jax.jit(exported.call)
    except Exception:
        return None


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
