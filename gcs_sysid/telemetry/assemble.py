"""Last step shared by every log reader: order streams, drop repeats, summarise, note what is missing."""

from __future__ import annotations

from gcs_sysid.telemetry.clock import sort_unique
from gcs_sysid.telemetry.types import Flight, Stream, StreamSummary

__all__ = ["finish_flight", "GAP_STREAMS"]

#: Streams whose gaps count as damage (the ones every estimate needs).
GAP_STREAMS = ("imu", "attitude", "servo", "airspeed")


def finish_flight(path: str, fmt: str, streams: dict[str, Stream], dropped: dict[str, int],
                  vehicle: dict[str, object], params: dict[str, float], messages: dict[str, int],
                  warnings: list[str], statustext: list[tuple[float, str]],
                  imu_sources: str, servo_sources: str, damage: list[str] | None = None) -> Flight:
    """Sort every stream by vehicle time, drop repeated times, and build the :class:`Flight`.

    Args:
        path, fmt: as in :class:`Flight`.
        streams: canonical name -> stream with times in any order.
        dropped: source message -> samples already dropped upstream (byte-identical packets).
        vehicle, params, messages, warnings, statustext: as in :class:`Flight`.
        imu_sources, servo_sources: message names quoted in the "missing" warnings.
        damage: the reader's notes on damage to the file (corrupt packets, truncation, clock jumps);
            the dropped samples and the gaps of the main streams are added here. Every damage note
            is also one of the warnings.

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
    damage = list(damage or [])
    if total_dropped:
        damage.append("dropped duplicated or out-of-order samples: "
                      + ", ".join(f"{k} {v}" for k, v in total_dropped.items()))
    gaps = []
    for name in GAP_STREAMS:
        g = summaries[name].gaps if name in summaries else []
        if g:
            a, b = max(g, key=lambda ab: ab[1] - ab[0])
            gaps.append(f"{name} {len(g)} (longest {b - a:.1f} s from {a:.1f} s)")
    if gaps:
        damage.append("time gaps in the data (no samples for more than 5 periods and 0.5 s): " + ", ".join(gaps))
    warnings.extend(d for d in damage if d not in warnings)
    if "imu" not in out:
        warnings.append(f"no IMU data ({imu_sources}): accelerations and body rates are missing")
    if "servo" not in out:
        warnings.append(f"no servo output data ({servo_sources}): control deflections are missing")
    return Flight(path, fmt, out, summaries, vehicle, params, messages, warnings,
                  sorted(statustext, key=lambda x: x[0]), damage)
