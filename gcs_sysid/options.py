"""Checks of command options and input paths, done before any work.

Every check raises :class:`~gcs_sysid.errors.InputError` with one line that names the option and
says what was expected and what was got, so that a command refuses bad options in a fraction of a
second instead of after decoding a log. The job functions (``run_replay``, ``run_fit`` ...) call the
same checks, so that they hold for callers other than the CLI too.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

from .errors import InputError

__all__ = ["check_rate", "check_holdout", "check_window", "check_positive_int", "check_input_file",
           "check_log", "check_model_state", "MAX_RATE_HZ"]

#: Highest estimation grid rate accepted, Hz (faster than any autopilot logs its IMU).
MAX_RATE_HZ = 1000.0


def _finite(value, option: str, expected: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{option} must be {expected}, got {value!r}") from None
    if not math.isfinite(x):
        raise InputError(f"{option} must be {expected}, got {value!r}")
    return x


def check_rate(rate_hz, option: str = "--rate") -> float:
    """The estimation grid rate: a finite number in (0, :data:`MAX_RATE_HZ`] Hz."""
    x = _finite(rate_hz, option, f"a rate in Hz above 0 and at most {MAX_RATE_HZ:g} (e.g. 50)")
    if not 0.0 < x <= MAX_RATE_HZ:
        raise InputError(f"{option} must be a rate in Hz above 0 and at most {MAX_RATE_HZ:g} (e.g. 50), got {x:g}")
    return x


def check_holdout(fraction, option: str = "--holdout") -> float:
    """The held-out fraction of the flight: a number in [0, 0.9]."""
    x = _finite(fraction, option, "a fraction of the flight in [0, 0.9] (e.g. 0.2)")
    if not 0.0 <= x <= 0.9:
        raise InputError(f"{option} must be a fraction of the flight in [0, 0.9] (e.g. 0.2), got {x:g}")
    return x


def check_window(t_from, t_to) -> tuple[float | None, float | None]:
    """``--from``/``--to``: finite vehicle times in s, ``--to`` after ``--from`` (either may be None)."""
    a = None if t_from is None else _finite(t_from, "--from", "a vehicle time in s")
    b = None if t_to is None else _finite(t_to, "--to", "a vehicle time in s")
    if a is not None and b is not None and b <= a:
        raise InputError(f"--to ({b:g} s) must be after --from ({a:g} s)")
    return a, b


def check_positive_int(value, option: str) -> int | None:
    """A positive integer (None passes)."""
    if value is None:
        return None
    if isinstance(value, bool) or int(value) != value or int(value) < 1:
        raise InputError(f"{option} must be a positive integer, got {value!r}")
    return int(value)


def check_input_file(path, option: str, what: str) -> Path:
    """An existing, readable file.

    Args:
        path: the path given. option: the option (or argument name) for messages.
        what: what the file should be, e.g. "an airframe TOML file (docs/airframe.md)".
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{option} {p}: no such file; expected {what}")
    if p.is_dir():
        raise InputError(f"{option} {p}: is a folder; expected {what}")
    if not os.access(p, os.R_OK):
        raise InputError(f"{option} {p}: cannot be read (permission denied); expected {what}")
    return p


def check_log(path) -> str:
    """A flight log: exists, is readable, and its first bytes are a .tlog or a DataFlash .bin.

    Returns:
        ``"tlog"`` or ``"bin"`` (:func:`gcs_sysid.telemetry.detect_format`; reads at most 64 KiB).
    """
    from .telemetry import detect_format

    return detect_format(path)


def check_model_state(path, option: str = "--model") -> Path:
    """A GP model state saved by an earlier replay: ``<path>.npz`` and ``<path>.json`` exist.

    ``DIR`` (an earlier replay's output folder) is taken as ``DIR/model``.
    """
    p = Path(path)
    if p.suffix in (".npz", ".json"):
        p = p.with_suffix("")
    if p.is_dir() and (p / "model.json").is_file():
        p = p / "model"
    npz, js = p.with_name(p.name + ".npz"), p.with_name(p.name + ".json")
    if not (npz.is_file() and js.is_file()):
        missing = " and ".join(str(f) for f in (npz, js) if not f.is_file())
        raise InputError(f"{option} {path}: no saved model ({missing} not found); expected DIR/model from an "
                         "earlier replay's output folder DIR")
    return p
