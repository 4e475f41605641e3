"""Outputs that appear whole or not at all: a staging folder or file beside the target, moved into place.

A command writes its outputs into a hidden staging folder created next to ``--out`` (same parent,
so same file system) and, once everything is written, moves it into place: a new folder is
renamed, an existing one is exchanged with the staging folder in one step (Linux
``renameat2(RENAME_EXCHANGE)``; elsewhere two renames a few microseconds apart) and the old
content is deleted. So

* an interrupted or failed run leaves the previous outputs exactly as they were, and nothing
  half-written (the staging folder is removed, also on Ctrl-C: :mod:`gcs_sysid.stopping`);
* no file of an earlier run survives next to the new ones (a run that fits no model leaves no
  model of an earlier run behind).

Single-file outputs (``simulate --out flight.tlog``, ``fit --out model.toml``) are written to a
hidden temporary file in the same folder and renamed over the target (:class:`StagedFiles`).

Because the whole folder is replaced, an existing ``--out`` folder is only accepted when it is
empty, carries the marker file :data:`MARKER` of an earlier gcs-sysid run, or holds nothing but the
names the command itself writes; anything else is refused (exit 2) rather than deleted.

All checks happen when the stage is created, before any work, so that a bad ``--out`` ends the
command at once with one line (:class:`~gcs_sysid.errors.InputError`) naming the option.

Usage::

    with StagedDir(out, command="replay", owned=REPLAY_OUTPUTS) as stage:
        write_everything(stage.path)
    # here ``out`` holds exactly what was written (or, after an exception, what it held before)
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import shutil
import signal
import tempfile
import time
from pathlib import Path
from typing import Iterable

from . import stopping
from .errors import InputError

__all__ = ["MARKER", "StagedDir", "StagedFiles", "check_out_dir", "check_out_file"]

#: File written into every output folder: what wrote it and when (JSON).
MARKER = ".gcs-sysid-output"
_PARTIAL = ".partial-"


def _why(exc: OSError) -> str:
    return exc.strerror or exc.__class__.__name__


def _nearest_existing(p: Path) -> Path:
    q = p
    while not q.exists() and q.parent != q:
        q = q.parent
    return q


def _check_parent(path: Path, option: str, what: str) -> None:
    """The folder that will hold ``path`` exists or can be created, and is writable."""
    parent = path.parent
    base = _nearest_existing(parent)
    if not base.is_dir():
        raise InputError(f"{option} {path}: {base} is a file, not a folder; expected a path to {what} "
                         "in a writable folder")
    if not os.access(base, os.W_OK | os.X_OK):
        raise InputError(f"{option} {path}: cannot write in {base} (permission denied); expected a path "
                         f"to {what} in a writable folder")


def check_out_dir(path: str | os.PathLike, option: str = "--out", owned: Iterable[str] = ()) -> Path:
    """Check that ``path`` can receive a command's output folder, without creating anything.

    Args:
        path: the output folder.
        option: the option that named it, for messages.
        owned: the names the command writes into the folder; an existing folder holding only these
            (an output of an earlier version without :data:`MARKER`) may be replaced.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        InputError: ``path`` is an existing file, an existing folder holding files gcs-sysid did not
            write, or lies where nothing can be written.
    """
    p = Path(path)
    if str(path).strip() == "":
        raise InputError(f"{option}: empty path; expected an output folder")
    if p.exists() and not p.is_dir():
        raise InputError(f"{option} {p}: is an existing file; expected a folder (new, empty, or the output "
                         "of an earlier gcs-sysid run)")
    if p.is_dir():
        if p.resolve() == Path.cwd().resolve() or p.resolve() == p.resolve().parent:
            raise InputError(f"{option} {p}: is the current or root folder, which would be replaced; "
                             "expected a folder of its own for the outputs")
        try:
            entries = [e.name for e in os.scandir(p)]
        except OSError as exc:
            raise InputError(f"{option} {p}: cannot be read ({_why(exc)}); expected a writable folder") from None
        if entries and MARKER not in entries:
            foreign = sorted(set(entries) - set(owned))
            if foreign:
                shown = ", ".join(foreign[:3]) + (" ..." if len(foreign) > 3 else "")
                raise InputError(f"{option} {p}: holds files gcs-sysid did not write ({shown}), and the "
                                 "whole folder is replaced by the new outputs; expected a new or empty "
                                 "folder, or the output of an earlier run")
    _check_parent(p, option, "a folder")
    return p


def check_out_file(path: str | os.PathLike, option: str = "--out") -> Path:
    """Check that ``path`` can receive an output file, without creating anything.

    Raises:
        InputError: ``path`` is an existing folder, or lies where nothing can be written.
    """
    p = Path(path)
    if str(path).strip() == "":
        raise InputError(f"{option}: empty path; expected an output file")
    if p.is_dir():
        raise InputError(f"{option} {p}: is a folder; expected the path of a file to write")
    if p.exists() and not os.access(p, os.W_OK) and not os.access(p.parent, os.W_OK):
        raise InputError(f"{option} {p}: cannot be replaced (permission denied)")
    _check_parent(p, option, "a file")
    return p


def _umask() -> int:
    old = os.umask(0o022)
    os.umask(old)
    return old


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def _remove_stale(parent: Path, name: str) -> None:
    """Remove staging leftovers of ``name`` from processes that no longer run (a power cut, SIGKILL)."""
    prefix = f".{name}{_PARTIAL}"
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return
    for e in entries:
        if not e.name.startswith(prefix):
            continue
        try:
            pid = int(e.name[len(prefix):].split("-", 1)[0])
        except ValueError:
            continue
        if pid != os.getpid() and not _pid_alive(pid):
            shutil.rmtree(e.path, ignore_errors=True) if e.is_dir(follow_symlinks=False) else _unlink(e.path)


def _unlink(path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux ``renameat2``); False where that is not available."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    rc = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP if hasattr(errno, "ENOTSUP") else errno.EINVAL):
        return False
    raise OSError(err, os.strerror(err), str(a))


class _Blocked:
    """Block SIGINT and SIGTERM for a few lines (they are delivered when the block ends)."""

    def __enter__(self):
        self._old = None
        if hasattr(signal, "pthread_sigmask"):
            try:
                self._old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
            except (OSError, ValueError):
                self._old = None
        return self

    def __exit__(self, *exc):
        if self._old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, self._old)


class _Staged:
    """Context manager of the staged outputs: ``commit()`` on success, ``abort()`` on any exception."""

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.abort()


class StagedDir(_Staged):
    """An output folder written beside its place and moved there when complete.

    Args:
        out: the output folder (``--out``).
        command: the command writing it (recorded in :data:`MARKER`).
        owned: names the command writes (see :func:`check_out_dir`).
        option: the option that named ``out``, for messages.

    Attributes:
        out: the final folder. path: the staging folder to write into.

    Raises:
        InputError: as :func:`check_out_dir`, or the staging folder cannot be created.
    """

    def __init__(self, out: str | os.PathLike, command: str, owned: Iterable[str] = (), option: str = "--out"):
        self.out = check_out_dir(out, option, owned).absolute()
        self.command = command
        self.committed = False
        parent = self.out.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            _remove_stale(parent, self.out.name)
            self.path = Path(tempfile.mkdtemp(prefix=f".{self.out.name}{_PARTIAL}{os.getpid()}-", dir=parent))
        except OSError as exc:
            raise InputError(f"{option} {out}: cannot write in {parent} ({_why(exc)}); expected a writable "
                             "location") from None
        self._token = stopping.register(self._on_stop)

    def _on_stop(self) -> str | None:
        if self.committed:
            return None
        shutil.rmtree(self.path, ignore_errors=True)
        return f"{self.out}: left as it was"

    def commit(self) -> Path:
        """Move the staging folder into place (replacing ``out``); returns ``out``."""
        (self.path / MARKER).write_text(json.dumps({"command": self.command, "written_utc": time.strftime(
            "%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "pid": os.getpid()}) + "\n")
        os.chmod(self.path, 0o777 & ~_umask())   # mkdtemp made it private
        with stopping.critical(), _Blocked():
            if not self.out.exists():
                os.rename(self.path, self.out)
                old = None
            elif _exchange(self.path, self.out):
                old = self.path          # now holds the previous outputs
            else:
                old = self.out.with_name(f".{self.out.name}{_PARTIAL}{os.getpid()}-old")
                os.rename(self.out, old)
                os.rename(self.path, self.out)
            self.committed = True
        stopping.unregister(self._token)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return self.out

    def abort(self) -> None:
        """Remove the staging folder; ``out`` stays as it was."""
        stopping.unregister(self._token)
        if not self.committed:
            shutil.rmtree(self.path, ignore_errors=True)


class StagedFiles(_Staged):
    """Output files written to temporary names beside them and renamed into place together.

    Args:
        paths: the final files.
        option: the option that named the first, for messages.

    Use ``stage.path(final)`` for the temporary path to write ``final`` to.

    Raises:
        InputError: as :func:`check_out_file`, or a temporary file cannot be created.
    """

    def __init__(self, *paths: str | os.PathLike, option: str = "--out"):
        self._tmp: dict[Path, Path] = {}
        self.committed = False
        finals = [check_out_file(p, option).absolute() for p in paths]
        for final in finals:
            try:
                final.parent.mkdir(parents=True, exist_ok=True)
                _remove_stale(final.parent, final.name)
                fd, tmp = tempfile.mkstemp(prefix=f".{final.name}{_PARTIAL}{os.getpid()}-", suffix=final.suffix,
                                           dir=final.parent)
                os.close(fd)
            except OSError as exc:
                self._drop()
                raise InputError(f"{option} {final}: cannot write in {final.parent} ({_why(exc)}); expected "
                                 "a writable location") from None
            self._tmp[final] = Path(tmp)
        self._token = stopping.register(self._on_stop)

    def path(self, final: str | os.PathLike) -> Path:
        """The temporary path standing for ``final`` until :meth:`commit`."""
        return self._tmp[Path(final).absolute()]

    def _drop(self) -> None:
        for tmp in self._tmp.values():
            _unlink(tmp)

    def _on_stop(self) -> str | None:
        if self.committed:
            return None
        self._drop()
        return ", ".join(str(p) for p in self._tmp) + ": left as it was"

    def commit(self) -> None:
        """Rename every temporary file over its final path."""
        mode = 0o666 & ~_umask()   # mkstemp made them private
        for tmp in self._tmp.values():
            os.chmod(tmp, mode)
        with stopping.critical(), _Blocked():
            for final, tmp in self._tmp.items():
                os.replace(tmp, final)
            self.committed = True
        stopping.unregister(self._token)

    def abort(self) -> None:
        """Remove the temporary files; the final paths stay as they were."""
        stopping.unregister(self._token)
        if not self.committed:
            self._drop()
