"""Last step shared by every log reader: order streams, drop repeats, summarise, note what is missing."""

from __future__ import annotations

from gcs_sysid.telemetry.clock import sort_unique
from gcs_sysid.telemetry.types import Flight, Stream, StreamSummary

__all__ = ["finish_flight"]


def finish_flight(path: str, fmt: str, streams: dict[str, Stream], dropped: dict[str, int],
                  vehicle: dict[str, object], params: dict[str, float], messages: dict[str, int],
                  warnings: list[str], statustext: list[tuple[float, str]],
                  imu_sources: str, servo_sources: str) -> Flight:
    """Sort every stream by vehicle time, drop repeated times, and build the :class:`Flight`.

    Args:
        path, fmt: as in :class:`Flight`.
        streams: canonical name -> stream with times in any order.
        dropped: source message -> samples already dropped upstream (byte-identical packets).
        vehicle, params, messages, warnings, statustext: as in :class:`Flight`.
        imu_sources, servo_sources: message names quoted in the "missing" warnings.

    Returns:
        The flight, with :attr:`Flight.summaries` filled; ``dropped`` in each summary counts the
        duplicated and out-of-order samples removed.
    """
    out: dict[str, Stream] = {}
    summaries: dict[str, StreamSummary] = {}
    total_dropped: dict[str, int] = {}
    for name, s in streams.items():
        idx, n_drop = sort_unique(s.t)
        n_drop += dropped.get(s.source, 0)
        if n_drop or len(idx) != len(s.t) or (len(idx) > 1 and (idx[1:] < idx[:-1]).any()):
            s = Stream(s.name, s.source, s.t[idx], {k: v[idx] for k, v in s.fields.items()})
        out[name] = s
        summaries[name] = StreamSummary.of(s, n_drop)
        if n_drop:
            total_dropped[name] = n_drop
    if total_dropped:
        warnings.append("dropped duplicated or out-of-order samples: "
                        + ", ".join(f"{k} {v}" for k, v in total_dropped.items()))
    if "imu" not in out:
        warnings.append(f"no IMU data ({imu_sources}): accelerations and body rates are missing")
    if "servo" not in out:
        warnings.append(f"no servo output data ({servo_sources}): control deflections are missing")
    return Flight(path, fmt, out, summaries, vehicle, params, messages, warnings,
                  sorted(statustext, key=lambda x: x[0]))
