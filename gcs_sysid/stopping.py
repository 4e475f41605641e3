"""Ending a command at once on Ctrl-C (SIGINT) or SIGTERM, whatever it is doing.

Python turns SIGINT into a ``KeyboardInterrupt`` raised wherever the main thread happens to be,
which is not always somewhere that can stop the program: raised inside a garbage-collection
callback (JAX registers one) or a ``__del__``, it is printed as "Exception ignored" and the run goes
on; raised inside a long compiled call (an XLA program, a BLAS factorisation), it waits for the call
to return. So the CLI does not raise: :func:`install` lets the C-level signal handler write the
signal number to a pipe (:func:`signal.set_wakeup_fd`), and a watcher thread, which does not wait
for the main thread to reach Python code, runs the registered clean-ups (remove a half-written
output folder, stop the worker process), prints one line and ends the process with ``128 + signal``
(130 for SIGINT, 143 for SIGTERM).

Before the clean-ups run, the main thread is stopped at its next Python instruction: the watcher
raises :class:`Stopped` in it (CPython's asynchronous exception), and the command's entry point
catches it and :func:`park` s, so that no writer puts back a folder the clean-up just removed; from
then on only the one line reaches stderr (the rest goes to the null device). The one place the
main thread is not interrupted is an import: an exception raised in the Python code that an extension
module's initialisation calls (jaxlib's ``xla_extension``, imported while the worker decodes) crashed
the process with SIGSEGV or SIGABRT instead of ending it with 143 (16 of 30 SIGTERMs sent 0.1-0.5 s
into a replay, measured 2026-11-22). So the watcher first takes the interpreter's import lock, which
it keeps until the process ends (no import can start in another thread), and raises :class:`Stopped`
only if the main thread is not inside one; a main thread inside an import writes no output and
ends with the process. Clean-ups are
registered by what creates something to clean (:mod:`gcs_sysid.outdir`,
:mod:`gcs_sysid.parallel`); :func:`critical` marks a short section that must not be cut in half
(moving finished outputs into place): a stop waits for it to end. A forked child (a ``multiprocessing``
worker) starts with none of this: default handlers, no wakeup pipe (which it would share with the
parent, so that a SIGTERM sent to the child stopped the parent), no clean-ups.

References:
    Python documentation, ``signal.set_wakeup_fd`` and "Note on Signal Handlers and Exceptions",
    https://docs.python.org/3/library/signal.html; C API ``PyThreadState_SetAsyncExc``; ``_imp.acquire_lock``
    (the global import lock that ``importlib._bootstrap`` takes before every module lock).
"""

from __future__ import annotations

import _imp
import itertools
import os
import signal
import sys
import threading
from contextlib import contextmanager
from typing import Callable, Iterator

__all__ = ["install", "uninstall", "installed", "register", "unregister", "critical", "park", "Stopped",
           "EXIT_SIGINT", "EXIT_SIGTERM"]

EXIT_SIGINT = 128 + signal.SIGINT     # 130
EXIT_SIGTERM = 128 + signal.SIGTERM   # 143

_cleanups: dict[int, Callable[[], str | None]] = {}
_ids = itertools.count()
_lock = threading.Lock()                 # guards _cleanups
_critical = threading.RLock()            # held while outputs are moved into place
_installed = False
_stopping = threading.Event()
_parked = threading.Event()              # the main thread has stopped working (:func:`park`)

#: How long the watcher waits for the main thread to park before it cleans up anyway (a thread inside
#: a long compiled call writes no files; it is stopped at its next Python instruction).
PARK_WAIT_S = 0.5


class Stopped(BaseException):
    """Raised in the main thread by a stop, so that it writes nothing more while its outputs are removed.

    Not an :class:`Exception`: no ``except Exception`` on the way up catches it. The command's entry
    point catches it and calls :func:`park`.
    """


def park() -> None:
    """Called by the main thread that caught :class:`Stopped`: wait here until the watcher ends the process."""
    _parked.set()
    while True:
        threading.Event().wait(3600.0)


def _importing(ident: int) -> bool:
    """Whether the thread ``ident`` is inside an import (a frame of ``importlib._bootstrap`` on its stack)."""
    frame = sys._current_frames().get(ident)
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _interrupt_main() -> bool:
    """Raise :class:`Stopped` in the main thread at its next bytecode (CPython's asynchronous exception),
    unless it is inside an import; returns whether it was raised.

    Takes the interpreter's import lock first and never releases it (the process is ending), so the main
    thread cannot enter an import between the check and the exception.
    """
    import ctypes

    main = threading.main_thread()
    if threading.current_thread() is main or main.ident is None:
        return False
    _imp.acquire_lock()
    if _importing(main.ident):
        return False
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(main.ident), ctypes.py_object(Stopped))
    return True


def register(cleanup: Callable[[], str | None]) -> int:
    """Run ``cleanup()`` if the process is stopped by a signal; returns a token for :func:`unregister`.

    A clean-up may return a few words for the one line printed at the stop (e.g. "report: left as it
    was"). Clean-ups run in the watcher thread, newest first, each at most once; an exception in one is
    ignored. They must be quick (well under a second) and must not take locks the main thread may hold.
    """
    with _lock:
        key = next(_ids)
        _cleanups[key] = cleanup
    return key


def unregister(token: int) -> None:
    """Forget a clean-up registered with :func:`register` (no error if it is gone)."""
    with _lock:
        _cleanups.pop(token, None)


@contextmanager
def critical() -> Iterator[None]:
    """A section a stop must not cut in half (it waits until the section ends, then stops)."""
    with _critical:
        yield


def installed() -> bool:
    """Whether :func:`install` has set up the handlers in this process."""
    return _installed


def _stop(signum: int) -> None:
    """Clean up, say so in one line and end the process with ``128 + signum``."""
    if _stopping.is_set():
        return
    _stopping.set()
    try:   # from here on only this line reaches the console: the main thread, stopped in the middle of
        # whatever it did (a garbage-collection callback, a __del__), may print "Exception ignored ..."
        err = os.dup(2)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 2)
    except OSError:
        err = 2
    with _critical:   # a commit in progress finishes first (it takes milliseconds)
        # the main thread stops writing before its staging outputs are removed: otherwise a writer that
        # creates its folder (mkdir(parents=True)) puts the staging folder back after the clean-up
        if _interrupt_main():
            _parked.wait(PARK_WAIT_S)
        with _lock:
            todo = list(_cleanups.values())[::-1]
            _cleanups.clear()
        notes = []
        for fn in todo:
            try:
                note = fn()
            except BaseException:   # noqa: BLE001 - nothing may stop the stop
                note = None
            if note:
                notes.append(str(note))
        what = "interrupted (Ctrl-C)" if signum == signal.SIGINT else \
            f"stopped by {signal.Signals(signum).name}"
        if notes:
            what += "; " + "; ".join(notes)
        try:
            if sys.stdout is not None and sys.stdout.isatty():
                os.write(sys.stdout.fileno(), b"\x1b[?25h\n")   # show the cursor a progress bar hid
        except (OSError, ValueError):
            pass
        try:
            os.write(err, f"gcs-sysid: {what}\n".encode())
        except OSError:
            pass
        os._exit(128 + signum)


def _watch(fd: int) -> None:
    while True:
        try:
            data = os.read(fd, 64)
        except InterruptedError:
            continue
        except OSError:
            return
        if not data:
            return
        for b in data:
            if b in (signal.SIGINT, signal.SIGTERM):
                _stop(b)
            elif b == _QUIT:   # :func:`uninstall`
                return


def _python_handler(signum, frame) -> None:
    # The watcher does the work; this handler only replaces Python's default (KeyboardInterrupt), and
    # covers a watcher that is not running.
    if not _watcher_alive():
        _stop(signum)


_watcher: threading.Thread | None = None
_fds: tuple[int, int] | None = None      # the wakeup pipe (read end, write end)
_previous: dict | None = None            # what install() replaced: the two handlers and the wakeup fd
_fork_hook_registered = False
_QUIT = 0                                # the byte that ends the watcher (no signal has number 0)


def _watcher_alive() -> bool:
    return _watcher is not None and _watcher.is_alive()


def install() -> None:
    """Handle SIGINT and SIGTERM as described above (main thread only; idempotent)."""
    global _installed, _watcher, _fds, _fork_hook_registered, _previous
    if _installed:
        return
    r, w = os.pipe()
    os.set_blocking(w, False)
    _watcher = threading.Thread(target=_watch, args=(r,), name="gcs-sysid-signals", daemon=True)
    _watcher.start()
    previous = {sig: signal.signal(sig, _python_handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    previous["wakeup_fd"] = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
    _installed = True
    _fds = (r, w)
    _previous = previous
    if not _fork_hook_registered:
        os.register_at_fork(after_in_child=_forget_in_child)
        _fork_hook_registered = True


def uninstall() -> None:
    """Undo :func:`install` in this process (a no-op when not installed): the handlers and the wakeup fd it
    replaced are put back, the watcher ends and the registered clean-ups are forgotten.

    For callers that run a command in-process and carry on (the test suite runs CLI commands inside its
    worker processes, which later tests fork or signal). Main thread only.

    Raises:
        ValueError: called from another thread (as :func:`signal.signal`).
    """
    global _installed, _watcher, _fds, _previous
    if not _installed:
        return
    prev = _previous or {}
    signal.set_wakeup_fd(prev.get("wakeup_fd", -1))
    for sig in (signal.SIGINT, signal.SIGTERM):
        handler = prev.get(sig)
        signal.signal(sig, signal.SIG_DFL if handler is None else handler)   # None: not set from Python
    if _fds is not None:
        r, w = _fds
        try:
            os.write(w, bytes([_QUIT]))
        except OSError:
            pass
        if _watcher is not None:
            _watcher.join(timeout=5.0)
        _close_pipe()
    with _lock:
        _cleanups.clear()
    _fds = _previous = _watcher = None
    _installed = False


def _close_pipe() -> None:
    """Close both ends of the wakeup pipe (already closed ends are ignored)."""
    for fd in _fds or ():
        try:
            os.close(fd)
        except OSError:
            pass


def _forget_in_child() -> None:
    """After a fork: the child is not the command and must not share its stop.

    A forked child (a ``multiprocessing`` worker) inherits the wakeup pipe: a SIGTERM sent to the child
    (``Pool.terminate``) would write the signal number into the pipe that the parent's watcher reads, and
    the parent would stop itself (seen 2026-11-26: a test's pool ended the pytest worker that had run a
    command in-process). The child also inherits the parent's clean-ups, which remove the parent's
    outputs. So the child gets the default handlers back, no wakeup fd and no clean-ups.
    """
    global _installed, _watcher, _fds, _previous
    if not _installed:
        return
    try:
        signal.set_wakeup_fd(-1)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    except ValueError:   # not the main thread (cannot happen after a fork: the forking thread is the main one)
        pass
    _close_pipe()
    _fds = _previous = _watcher = None
    _cleanups.clear()
    _installed = False
