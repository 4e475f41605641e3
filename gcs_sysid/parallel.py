"""One spare process for the independent work of a replay (figures, a second smoother).

The replay is a chain of stages, and most of it runs on one core: XLA runs the GP's small
factorisations on one thread, and the smoothers and matplotlib hold the GIL. Some work
does not depend on what comes next: the report's figures of the data and states can be
drawn while the GP is fitted, the envelope figures while the maneuvers are designed, and
the specific-force smoother needs nothing from the velocity filter that runs beside it.
:class:`Helper` hands such work to one worker process so that a second core does it.

The worker is a fresh interpreter (``python -m gcs_sysid.parallel``), neither a fork (the
parent runs JAX, whose thread pools do not survive one) nor a ``multiprocessing`` spawn
(which re-imports the caller's main script: an unguarded script would run twice). Jobs and
results travel pickled over its stdin and stdout, in order, one job at a time. It imports
what it needs (``warm``) as soon as it starts, while the parent decodes the log. Jobs name
their function as ``"module:function"``, so the parent never imports what only the worker
needs (matplotlib, for the figures).

Nothing depends on the worker being there: with one CPU, with ``enabled=False`` or
``GCS_SYSID_PARALLEL=0``, or when the worker cannot be started or dies, each job runs in
the calling process instead, with the same result (the functions are pure).

One user keeps state in the worker between jobs: a live session's learner
(:mod:`gcs_sysid.live.remote`, jobs in order on one worker). Without a worker its jobs run here
as well; if the worker dies mid-session, the learner it held is gone and the next job says so
(:class:`~gcs_sysid.errors.SysidError`) instead of running here on a state it does not have.
"""

from __future__ import annotations

import importlib
import os
import pickle
import queue
import signal
import subprocess
import sys
import threading
from concurrent.futures import Future
from typing import Any, Sequence

from . import stopping

__all__ = ["Helper", "Job", "WorkerError", "call", "default_enabled"]

#: Set to ``0`` to run every job in the calling process (debugging, profiling).
PARALLEL_ENV = "GCS_SYSID_PARALLEL"
_HOLD_TERM_ENV = "GCS_SYSID_WORKER_HOLDS_SIGTERM"   # set by Helper(hold_sigterm=True) for its worker


class WorkerError(RuntimeError):
    """The worker process is gone or could not take or return a job (not an error of the job)."""


def default_enabled() -> bool:
    """True when more than one CPU is usable and ``$GCS_SYSID_PARALLEL`` is not ``0``."""
    if os.environ.get(PARALLEL_ENV, "").strip() == "0":
        return False
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        n = os.cpu_count() or 1
    return n > 1


def call(target: str, args: Sequence[Any] = (), kwargs: dict[str, Any] | None = None) -> Any:
    """Import ``target`` (``"package.module:function"``) and call it; what the worker runs.

    Raises:
        ValueError: ``target`` is not ``"module:function"``.
    """
    module, _, name = target.partition(":")
    if not module or not name:
        raise ValueError(f"parallel: job target must be 'module:function', got {target!r}")
    return getattr(importlib.import_module(module), name)(*args, **(kwargs or {}))


class Job:
    """A submitted call; :meth:`result` gives its value.

    When the worker failed (it could not start, died, or could not take or return the
    job), :meth:`result` runs the call in this process instead. Exceptions raised by the
    function itself are re-raised unchanged.
    """

    def __init__(self, target: str, args: tuple, kwargs: dict, future: Future | None):
        self.target, self._args, self._kwargs, self._future = target, args, kwargs, future
        self.ran_in_worker = False

    def result(self) -> Any:
        """The call's return value (waits for the worker)."""
        future, self._future = self._future, None
        if future is not None:
            try:
                value = future.result()
            except WorkerError:
                pass   # do it here
            else:
                self.ran_in_worker = True
                return value
        return call(self.target, self._args, self._kwargs)


class Helper:
    """A spare worker process for independent jobs, with an in-process fallback.

    Args:
        enabled: start a worker (None: :func:`default_enabled`).
        warm: modules the worker imports as soon as it starts.
        hold_sigterm: the worker ignores SIGTERM (sent to the whole process group by ``timeout``, a
            service manager, ``kill -TERM -PGID``), so that a caller which ends cleanly on SIGTERM can
            still collect what the worker holds (a live session's learner); the caller stops it with
            :meth:`close`, and the kernel kills it if the caller dies.

    Use as a context manager, or call :meth:`close`::

        with Helper(warm=["gcs_sysid.report.plots"]) as h:
            job = h.submit("gcs_sysid.report.plots:streams_figure", summaries)
            ...
            png = job.result()
    """

    def __init__(self, enabled: bool | None = None, warm: Sequence[str] = (), hold_sigterm: bool = False):
        self._proc: subprocess.Popen | None = None
        self._pending: dict[int, Future] = {}
        self._lock = threading.Lock()
        self._outbox: queue.Queue = queue.Queue()
        self._next = 0
        if enabled is None:
            enabled = default_enabled()
        if not enabled:
            return
        try:
            # the caller's import path, so that the worker imports the same gcs_sysid; no nested workers
            # and one BLAS thread: it is the spare core, the caller keeps the other one busy
            env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p), **{PARALLEL_ENV: "0"},
                       OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
                       PYTHONWARNINGS="ignore",   # the caller reports problems; the worker's console stays quiet
                       **{_HOLD_TERM_ENV: "1" if hold_sigterm else "0"})
            self._proc = subprocess.Popen([sys.executable, "-m", "gcs_sysid.parallel"], stdin=subprocess.PIPE,
                                          stdout=subprocess.PIPE, env=env)
        except OSError:
            self._proc = None
            return
        # stopped by a signal (gcs_sysid.stopping): the worker goes at once, with the caller
        self._stop_token = stopping.register(self._kill)
        # the writer pickles and sends in the background (a large job must not block the caller while the
        # worker is busy); the reader hands results to the futures
        threading.Thread(target=self._write, name="gcs-sysid-helper-writer", daemon=True).start()
        threading.Thread(target=self._read, name="gcs-sysid-helper-reader", daemon=True).start()
        self.preload(warm)

    @property
    def parallel(self) -> bool:
        """Whether jobs go to a worker process."""
        return self._proc is not None

    def preload(self, modules: Sequence[str]) -> None:
        """Have the worker import ``modules`` now (between jobs), so that later jobs start at once."""
        if self._proc is not None and modules:
            self._send("gcs_sysid.parallel:_import", (tuple(modules),), {})

    def submit(self, target: str, *args: Any, **kwargs: Any) -> Job:
        """Start ``target(*args, **kwargs)`` (``target`` as ``"module:function"``) in the worker.

        Without a worker nothing runs until :meth:`Job.result`, which then runs it here.
        """
        return Job(target, args, kwargs, self._send(target, args, kwargs) if self._proc is not None else None)

    def _send(self, target: str, args: tuple, kwargs: dict) -> Future:
        fut: Future = Future()
        with self._lock:
            key, self._next = self._next, self._next + 1
            self._pending[key] = fut
        self._outbox.put((key, target, args, kwargs))
        return fut

    def _write(self) -> None:
        proc = self._proc
        while True:
            item = self._outbox.get()
            if item is None:
                break
            try:
                data = pickle.dumps(item, protocol=pickle.HIGHEST_PROTOCOL)
            except Exception as e:   # an argument that cannot be pickled: that job runs in the caller
                self._finish(item[0], WorkerError(f"job {item[1]} could not be sent: {e}"))
                continue
            try:
                proc.stdin.write(data)
                proc.stdin.flush()
            except (OSError, ValueError):
                self._fail_all("the worker process stopped")
                break
        try:
            proc.stdin.close()
        except (OSError, ValueError):
            pass

    def _read(self) -> None:
        stream = self._proc.stdout
        while True:
            try:
                key, ok, value = pickle.load(stream)
            except Exception:   # EOF or a broken stream: the worker is gone
                self._fail_all("the worker process stopped")
                return
            self._finish(key, value, ok)

    def _finish(self, key: int, value: Any, ok: bool = False) -> None:
        with self._lock:
            fut = self._pending.pop(key, None)
        if fut is None:
            return
        if ok:
            fut.set_result(value)
        else:
            fut.set_exception(value)

    def _fail_all(self, why: str) -> None:
        with self._lock:
            pending, self._pending = self._pending, {}
        for fut in pending.values():
            fut.set_exception(WorkerError(why))

    def _kill(self) -> None:
        proc = self._proc
        if proc is not None:
            try:
                proc.kill()
                proc.wait(timeout=0.5)
            except (OSError, subprocess.TimeoutExpired):
                pass

    def close(self, wait: bool = True) -> None:
        """Stop the worker.

        Args:
            wait: let it finish the jobs already sent (their results can still be collected);
                False stops it at once (jobs not yet collected then run in the caller).
        """
        proc, self._proc = self._proc, None
        if proc is None:
            return
        stopping.unregister(self._stop_token)
        self._outbox.put(None)
        if not wait:
            proc.kill()
        try:
            proc.wait(timeout=120)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()

    def __enter__(self) -> "Helper":
        return self

    def __exit__(self, exc_type, *exc) -> None:
        self.close(wait=exc_type is None)


def _import(modules: Sequence[str]) -> int:
    for m in modules:
        importlib.import_module(m)
    return os.getpid()


def _die_with_parent() -> None:
    """Linux: have the kernel send SIGKILL to this worker when its parent dies (no stray worker)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL, 0, 0, 0)   # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _serve() -> None:
    """The worker's loop: read a job from stdin, run it, write ``(key, ok, value)`` to stdout.

    It ends quietly (no traceback) at EOF, when its pipes break (the caller is gone) and on SIGTERM
    (unless started with ``hold_sigterm``).
    """
    # Ctrl-C reaches the whole process group: the caller handles it (and stops this worker); the worker
    # must not die of it mid-job with a traceback of its own. It ends at EOF, when the caller closes or dies.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    hold = os.environ.get(_HOLD_TERM_ENV, "0") == "1"   # the caller ends cleanly on SIGTERM and needs this worker
    signal.signal(signal.SIGTERM, signal.SIG_IGN if hold else signal.SIG_DFL)
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)   # a write to a closed pipe ends the worker silently
    _die_with_parent()
    import warnings

    warnings.simplefilter("ignore")
    try:
        _loop()
    except (BrokenPipeError, EOFError, OSError, pickle.UnpicklingError):
        pass   # the caller went away
    finally:
        try:
            sys.stderr.flush()
        except (OSError, ValueError):
            pass
        os._exit(0)


def _loop() -> None:
    inp = sys.stdin.buffer
    out = os.fdopen(os.dup(sys.stdout.fileno()), "wb")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())   # stray prints go to stderr, not into the results
    sys.stdout = sys.stderr
    while True:
        try:
            key, target, args, kwargs = pickle.load(inp)
        except EOFError:
            return
        try:
            reply = (key, True, call(target, args, kwargs))
        except Exception as e:   # the job's own error, re-raised in the caller
            reply = (key, False, e)
        try:
            data = pickle.dumps(reply, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as e:
            data = pickle.dumps((key, False, WorkerError(f"result of {target} could not be returned: {e}")))
        out.write(data)
        out.flush()


if __name__ == "__main__":
    _serve()
