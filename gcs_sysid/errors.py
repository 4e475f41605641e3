"""Exceptions raised by gcs-sysid.

Every error a user can cause (a bad file, a missing field, data that cannot
support an estimate) is a :class:`SysidError`. Its message is one line that
names the file, field or message and what was expected; the CLI prints it
without a traceback and exits non-zero.
"""

__all__ = ["SysidError", "InputError", "DataError"]


class SysidError(Exception):
    """Base class of the errors the CLI reports as one line (exit code 2)."""


class InputError(SysidError, ValueError):
    """A file, field or message is malformed or not what was expected.

    Example: ``airframe.toml: [servo.elevator] pwm_trim must lie between pwm_min
    and pwm_max, got 2100``.
    """


class DataError(SysidError, RuntimeError):
    """The data are well formed but cannot support the requested estimate.

    Example: ``flight.tlog: no IMU stream (RAW_IMU, SCALED_IMU*, HIGHRES_IMU)``.
    """
