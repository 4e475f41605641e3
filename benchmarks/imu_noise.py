"""In-flight white-noise level of logged accelerometers and gyros, against the JSBSim harness's.

Question (closing note 10, Next item 5): the independent-engine harness
(``benchmarks/jsbsim_harness/sensors.py``) logs the IMU at 50 Hz with white noise of
``HARNESS_SIGMA["accel"]`` = 0.05 m/s^2 and ``HARNESS_SIGMA["gyro"]`` = 0.005 rad/s per sample. Is
that what an ArduPilot ground station records in flight, vibration included?

What a log carries. ArduPilot's RAW_IMU / SCALED_IMU2 / SCALED_IMU3 (and DataFlash IMU) are point
samples, at the stream rate, of the INS front end's latest *filtered* value: every raw sample (about
1 kHz) passes a 2-pole low-pass at ``INS_ACCEL_FILTER`` / ``INS_GYRO_FILTER`` (ArduPlane default
20 Hz) and the GCS message copies the newest output (``GCS_MAVLINK::send_raw_imu``:
``ins.get_accel(0)``, milli-g and mrad/s). Vibration above the filter is attenuated, and what is
left aliases into the logged band. A point sample's variance does not depend on the stream rate,
so the per-sample standard deviation ``sigma`` read from a 10 Hz log is the one a 50 Hz log of
the same flight would carry, and the white-noise density of that 50 Hz log would be
``sigma / sqrt(25 Hz)``: the per-sample ``sigma`` is compared with the harness's directly.

Estimators, per channel, on the in-flight samples (ground speed above ``--min-speed``):

* ``d2``: ``sqrt(var(diff(x, 2)) / 6)``: a white sequence's second difference has variance
  ``6 sigma^2``; a smooth motion's is small only well below ``fs / 6`` (upper bound where the log
  rate is low against the airframe's motion);
* ``psd``: :func:`psd_sigma` (as :func:`benchmarks.jsbsim_harness.scoring.white_noise_psd`), the median Welch PSD above
  0.6 x Nyquist (as ``benchmarks/force_floor.py`` reads the harness's noise), as
  ``sigma = sqrt(N fs / 2)``; above the rigid-body bandwidth on a 50 Hz log (15-25 Hz), inside it
  on a 10 Hz log (3-5 Hz), where it is an upper bound;
* ``ind``: with two IMUs snapshotted at the same instants (RAW_IMU and SCALED_IMU2 in one stream
  group), the part of each IMU's second difference the other IMU does not share:
  ``sqrt((var(d2_i) - cov(d2_1, d2_2)) / 6)``. Motion (the aerodynamic force included) and
  vibration seen alike by both sensors cancel; the sensor's own noise and the vibration each chip
  aliases differently remain. If the two chips see the shared content with different gains, the
  quieter-gain one's ``ind`` is biased low (0 where the shared part exceeds it) and the other's high;
* ``pair``: :func:`pair_sigma`, the two IMUs' difference, ``sqrt(var(d2_1 - d2_2) / 12)``: the RMS
  of the two sensors' own noise, symmetric, biased up by a gain mismatch.

``VIBRATION`` / ``VIBE`` (if logged) is reported as its median over the in-flight samples:
ArduPilot's RMS of the *raw* accelerometer (before ``INS_ACCEL_FILTER``) above a 5 Hz low-pass
(``AP_InertialSensor::calc_vibration_and_clipping``), m/s^2, with the clipping counts.

Segments: "all" in-flight samples, and, where the log has ``VFR_HUD.throttle`` and at least
``MIN_SEGMENT`` samples of each, "motor" (throttle > 5 %) and "glide" (throttle < 1 %) rows (the
reader gives the throttle as a fraction): the
glide rows carry no propeller vibration.

``--floor DIR``: what a noise level does to the measured force coefficient's Wiener floor
(``benchmarks/force_floor.py``'s formula, :func:`benchmarks.force_floor.attribute` with
``noise_sigma``) on eval_jsbsim's flights already in DIR, nothing re-flown.

Usage::

    python benchmarks/imu_noise.py                      # the project's sample flights in data/
    python benchmarks/imu_noise.py /work/shared/data/alfa/*.tlog /work/shared/data/ardupilot/*.bin
    python benchmarks/imu_noise.py --floor /tmp/baseline11/ej-b747 --floor-sigma 0.0185 0.05 0.1

Sources: ArduPilot ``libraries/GCS_MAVLink/GCS_Common.cpp`` (``send_raw_imu``),
``libraries/AP_InertialSensor/AP_InertialSensor.cpp`` (filter defaults, vibration); IEEE Std
952-1997, annex C (white noise and its difference/Allan estimators); Bendat and Piersol, *Random
Data*, 4th ed., 2010, sec. 5.2 (Welch PSD) and 6.1 (coherent and incoherent parts of two channels).
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gcs_sysid.errors import DataError, InputError  # noqa: E402
from gcs_sysid.telemetry import read_log  # noqa: E402

__all__ = ["HARNESS_SIGMA", "HARNESS_RATE_HZ", "ChannelNoise", "FlightNoise", "diff_sigma", "psd_sigma",
           "independent_sigma", "pair_sigma", "flight_noise", "main"]

#: The harness's white noise per sample (``benchmarks/jsbsim_harness/sensors.py``, ``make_sensors``:
#: ``noise(0.05, n)`` on ax ay az, ``noise(0.005, n)`` on p q r), SI; and its IMU rate, Hz.
HARNESS_SIGMA = {"accel": 0.05, "gyro": 0.005}
HARNESS_RATE_HZ = 50.0
ACCEL, GYRO = ("ax", "ay", "az"), ("p", "q", "r")
MIN_SEGMENT = 100
DEFAULT_LOGS = ("data/flights/sim-trainer-sysid.tlog", "data/logs/ardupilot-quadplane-sitl-vtol.tlog")


def diff_sigma(x: np.ndarray, ok: np.ndarray | None = None) -> float:
    """White-noise standard deviation from the second difference: ``sqrt(var(diff(x, 2)) / 6)``.

    Args:
        x: (n,) samples at a constant step.
        ok: (n - 2,) bool, which second differences to use (all three samples valid); default all.

    Returns:
        sigma in x's units (NaN with fewer than 8 usable differences).
    """
    d = np.diff(np.asarray(x, float), 2)
    if ok is not None:
        d = d[ok]
    return float(np.sqrt(np.var(d) / 6.0)) if len(d) >= 8 else math.nan


def psd_sigma(x: np.ndarray, dt: float) -> float:
    """White-noise standard deviation per sample from the PSD floor above 0.6 x Nyquist.

    Args:
        x: (n,) contiguous samples, n >= 64. dt: step, s.

    Returns:
        ``sqrt(N / (2 dt))``, ``N`` the median one-sided Welch PSD above 0.6 x Nyquist (segments of
        up to 256 samples): the noise reading of
        :func:`benchmarks.jsbsim_harness.scoring.white_noise_psd` (not imported: the harness
        package loads JSBSim); NaN for fewer than 64 samples.
    """
    from scipy.signal import welch

    x = np.asarray(x, float)
    if len(x) < 64:
        return math.nan
    f, S = welch(x - x.mean(), 1.0 / dt, nperseg=min(256, len(x)))
    return float(np.sqrt(np.median(S[f > 0.6 * 0.5 / dt]) / (2.0 * dt)))


def independent_sigma(x1: np.ndarray, x2: np.ndarray, ok: np.ndarray | None = None) -> tuple[float, float]:
    """Each of two co-sampled sensors' white noise that the other does not share.

    ``var(d2_i) - cov(d2_1, d2_2)`` over 6, with ``d2`` the second differences (Bendat and Piersol
    2010, sec. 6.1: the incoherent part of a channel). A common signal cancels exactly; independent
    white noises of sigma ``s_i`` give back ``s_i``.

    Args:
        x1, x2: (n,) the same axis from two sensors at the same instants.
        ok: (n - 2,) bool mask of usable second differences.

    Returns:
        (sigma_1, sigma_2); a negative variance (one sensor quieter than the shared part) gives 0.
    """
    d1, d2 = np.diff(np.asarray(x1, float), 2), np.diff(np.asarray(x2, float), 2)
    if ok is not None:
        d1, d2 = d1[ok], d2[ok]
    if len(d1) < 8:
        return math.nan, math.nan
    c = float(np.mean((d1 - d1.mean()) * (d2 - d2.mean())))
    return tuple(float(np.sqrt(max(np.var(d) - c, 0.0) / 6.0)) for d in (d1, d2))  # type: ignore[return-value]


def pair_sigma(x1: np.ndarray, x2: np.ndarray, ok: np.ndarray | None = None) -> float:
    """RMS of two co-sampled sensors' own white noises, from their difference: ``sqrt(var(d2_1 - d2_2) / 12)``.

    A common signal seen with the same gain cancels; with gains ``1`` and ``g`` it adds
    ``(1 - g)^2`` of its second-difference variance (an upper bias); independent white noises
    ``s_1``, ``s_2`` give back ``sqrt((s_1^2 + s_2^2) / 2)``.

    Args:
        x1, x2: (n,) the same axis from two sensors at the same instants.
        ok: (n - 2,) bool mask of usable second differences.
    """
    d = np.diff(np.asarray(x1, float) - np.asarray(x2, float), 2)
    if ok is not None:
        d = d[ok]
    return float(np.sqrt(np.var(d) / 12.0)) if len(d) >= 8 else math.nan


@dataclass
class ChannelNoise:
    """One channel's estimates; sigma per sample in SI (m/s^2 or rad/s)."""

    stream: str
    source: str
    segment: str
    channel: str
    rate_hz: float
    n: int
    d2: float
    psd: float
    ind: float = math.nan
    pair: float = math.nan

    @property
    def kind(self) -> str:
        return "accel" if self.channel in ACCEL else "gyro"

    @property
    def harness(self) -> float:
        return HARNESS_SIGMA[self.kind]


@dataclass
class FlightNoise:
    """A log's in-flight noise: channels, the filter settings found and the vibration metric."""

    path: str
    seconds: float
    settings: dict[str, str]
    channels: list[ChannelNoise] = field(default_factory=list)
    vibration: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _settings(params: dict[str, float]) -> dict[str, str]:
    out = {}
    for k in ("INS_ACCEL_FILTER", "INS_GYRO_FILTER"):
        out[k] = f"{params[k]:g} Hz" if k in params else "not in log (ArduPlane's default: 20 Hz)"
    for k in ("SCHED_LOOP_RATE", "SR0_RAW_SENS", "INS_FAST_SAMPLE", "INS_HNTCH_ENABLE", "SIM_ACC1_RND",
              "SIM_GYR1_RND", "SIM_VIB_FREQ_X"):
        if k in params:
            out[k] = f"{params[k]:g}"
    return out


def _vibration(path: str, t0: float, t1: float) -> dict[str, float]:
    """Median VIBRATION (tlog) / VIBE (bin, instance 0) between the vehicle times t0..t1, s."""
    from pymavlink import mavutil

    rows = []
    try:
        m = mavutil.mavlink_connection(path, dialect="ardupilotmega") if not path.endswith(".bin") \
            else mavutil.mavlink_connection(path)
    except Exception:  # noqa: BLE001 - vibration is optional context
        return {}
    while True:
        try:
            x = m.recv_match(type=["VIBRATION", "VIBE"])
        except Exception:  # noqa: BLE001 - a corrupt tail ends the scan
            break
        if x is None:
            break
        if x.get_type() == "VIBRATION":
            t = x.time_usec * 1e-6
            rows.append((t, x.vibration_x, x.vibration_y, x.vibration_z, x.clipping_0, x.clipping_1))
        elif getattr(x, "IMU", 0) == 0:
            rows.append((x.TimeUS * 1e-6, x.VibeX, x.VibeY, x.VibeZ, x.Clip0 if hasattr(x, "Clip0") else x.Clip,
                         math.nan))
    if not rows:
        return {}
    a = np.array(rows, float)
    sel = (a[:, 0] >= t0) & (a[:, 0] <= t1)
    if sel.sum() < 3:      # clocks that do not match the vehicle time (e.g. a rebuilt capture): whole log
        sel = np.ones(len(a), bool)
    return {"x": float(np.median(a[sel, 1])), "y": float(np.median(a[sel, 2])), "z": float(np.median(a[sel, 3])),
            "clip0": float(a[-1, 4]), "clip1": float(a[-1, 5])}


def _runs(mask: np.ndarray) -> list[slice]:
    idx = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    return [slice(a, b) for a, b in zip(idx[::2], idx[1::2])]


def flight_noise(path: str | Path, min_speed: float = 8.0, decimate: int = 1) -> FlightNoise:
    """In-flight noise of every IMU stream of a log (module docstring).

    Args:
        path: a .tlog or DataFlash .bin.
        min_speed: in-flight threshold on the GPS ground speed, m/s (without GPS: every sample).
        decimate: keep every ``decimate``-th IMU sample (point sampling, as a slower stream rate
            would log the same flight): e.g. 5 reads a 50 Hz harness log as a 10 Hz one.

    Returns:
        :class:`FlightNoise` (one :class:`ChannelNoise` per stream, segment and channel).

    Raises:
        InputError / DataError: from :func:`gcs_sysid.telemetry.read_log`; DataError also when the
            log has no IMU stream.
        ValueError: ``decimate`` < 1.
    """
    if decimate < 1:
        raise ValueError(f"decimate must be 1 or more, got {decimate}")
    from gcs_sysid.telemetry import Stream

    path = str(path)
    f = read_log(path)
    imus = [k for k in sorted(f.streams) if k.startswith("imu")]
    if not imus:
        raise DataError(f"{path}: no IMU stream (RAW_IMU / SCALED_IMU* / HIGHRES_IMU / IMU); expected one")
    if decimate > 1:
        for k in imus:
            s = f.streams[k]
            f.streams[k] = Stream(k, s.source, s.t[::decimate], {c: v[::decimate] for c, v in s.fields.items()})
    ref = f.streams[imus[0]]
    t = ref.t
    dt = float(np.median(np.diff(t)))
    fly = np.ones(len(t), bool)
    notes = []
    if f.has("gps") and len(f["gps"]) > 2:
        g = f["gps"]
        fly = np.interp(t, g.t, np.hypot(g["vn"], g["ve"])) > min_speed
    else:
        notes.append("no GPS: every sample counted as in flight")
    segs = {"all": fly}
    if f.has("vfr_hud") and "throttle" in f["vfr_hud"]:
        v = f["vfr_hud"]
        thr = np.interp(t, v.t, v["throttle"])
        motor, glide = fly & (thr > 0.05), fly & (thr < 0.01)
        if min(motor.sum(), glide.sum()) >= MIN_SEGMENT:
            segs.update(motor=motor, glide=glide)
    out = FlightNoise(path, float(fly.sum() * dt), _settings(f.params), notes=notes)
    if fly.any():
        out.vibration = _vibration(path, float(t[fly][0]), float(t[fly][-1]))
    # a second IMU co-sampled with the first (same instants within a quarter step)
    twin = None
    if len(imus) > 1:
        s2 = f.streams[imus[1]]
        j = np.searchsorted(s2.t, t).clip(1, len(s2.t) - 1)
        j = np.where(np.abs(s2.t[j - 1] - t) < np.abs(s2.t[j] - t), j - 1, j)
        if np.mean(np.abs(s2.t[j] - t) < 0.25 * dt) > 0.9:
            twin = (s2, j, np.abs(s2.t[j] - t) < 0.25 * dt)
        else:
            notes.append(f"{imus[1]} not sampled with {imus[0]}: no independent part")
    for seg, m in segs.items():
        gap_ok = np.diff(t) < 1.5 * dt
        ok = m[:-2] & m[1:-1] & m[2:] & gap_ok[:-1] & gap_ok[1:]
        run = max(_runs(m & np.r_[gap_ok, True]), key=lambda s: s.stop - s.start, default=slice(0, 0))
        members = [(imus[0], None)] + ([(imus[1], twin[1])] if twin is not None else [])
        for si, (name, idx) in enumerate(members):
            s = f.streams[name]
            for ch in ACCEL + GYRO:
                if ch not in s:
                    continue
                x = s[ch] if idx is None else s[ch][idx]
                cn = ChannelNoise(name, s.source, seg, ch, 1.0 / dt, int(m.sum()), diff_sigma(x, ok),
                                  psd_sigma(x[run], dt))
                if twin is not None:
                    okt = ok & twin[2][:-2] & twin[2][1:-1] & twin[2][2:]
                    x1, x2 = ref[ch], twin[0][ch][twin[1]]
                    cn.ind = independent_sigma(x1, x2, okt)[si]
                    cn.pair = pair_sigma(x1, x2, okt)
                out.channels.append(cn)
    return out


def _fmt(v: float, w: int = 4) -> str:
    return "-" if not np.isfinite(v) else f"{v:.{w}f}"


def print_flight(r: FlightNoise) -> None:
    """Print one flight's settings and table (markdown)."""
    print(f"\n### {Path(r.path).name}: {r.seconds:.0f} s in flight")
    print("settings: " + ", ".join(f"{k} {v}" for k, v in r.settings.items()))
    if r.vibration:
        v = r.vibration
        print(f"VIBRATION (raw accel RMS above 5 Hz, before the INS filter), median: x {v['x']:.2f} y {v['y']:.2f} "
              f"z {v['z']:.2f} m/s^2; clipping {v['clip0']:.0f}/{_fmt(v['clip1'], 0)}")
    for n in r.notes:
        print("note: " + n)
    print("| stream (message) | segment | ch | rate Hz | n | d2 sigma | psd sigma | ind sigma | pair sigma | harness | "
          "d2 / harness | ind / harness | 50 Hz density (d2) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for c in r.channels:
        unit = "m/s^2" if c.kind == "accel" else "rad/s"
        print(f"| {c.stream} ({c.source}) | {c.segment} | {c.channel} | {c.rate_hz:.1f} | {c.n} | {_fmt(c.d2)} | "
              f"{_fmt(c.psd)} | {_fmt(c.ind)} | {_fmt(c.pair)} | {c.harness:g} {unit} | {c.d2 / c.harness:.2f} | "
              f"{_fmt(c.ind / c.harness, 2)} | {_fmt(c.d2 / math.sqrt(HARNESS_RATE_HZ / 2), 5)} |")


def print_summary(results: list[FlightNoise], segment: str = "all") -> None:
    """Median [min-max] over flights, per stream and channel, of each estimator, as a ratio to the harness."""
    print(f"\n### Summary over {len(results)} logs, segment '{segment}': sigma / harness, median [min-max]")
    print("| stream | ch | flights | d2 | psd | ind | pair |")
    print("|---|---|---|---|---|---|---|")
    keys = sorted({(c.stream, c.channel) for r in results for c in r.channels if c.segment == segment},
                  key=lambda k: (k[0], (ACCEL + GYRO).index(k[1])))
    for st, ch in keys:
        cs = [c for r in results for c in r.channels if c.segment == segment and (c.stream, c.channel) == (st, ch)]

        def agg(vals: list[float]) -> str:
            v = np.array([x for x in vals if np.isfinite(x)])
            return "-" if not len(v) else f"{np.median(v):.2f} [{v.min():.2f}-{v.max():.2f}]"
        h = cs[0].harness
        print(f"| {st} | {ch} | {len(cs)} | " + " | ".join(agg([getattr(c, k) / h for c in cs])
                                                            for k in ("d2", "psd", "ind", "pair")) + " |")


def print_floor(work: list[str], sigmas: list[float], coef: str, turbulence: str) -> None:
    """The measured coefficient's Wiener floor (%) at each accelerometer sigma, on eval_jsbsim's flights."""
    from benchmarks.force_floor import attribute

    print(f"\n| flight | {coef} meas % | floor at the log's noise % | "
          + " | ".join(f"floor at {s:g} m/s^2 %" for s in sigmas) + " |")
    print("|---|---|---|" + "---|" * len(sigmas))
    for w in work:
        for p in sorted(Path(w).glob(f"*-{turbulence}-s*-truth.npz")):
            stem = Path(str(p)[: -len("-truth.npz")])
            if not Path(f"{stem}-replay/coefficients.csv").exists():
                continue
            base = attribute(stem, coef)
            row = [attribute(stem, coef, noise_sigma=s)["floor"] for s in sigmas]
            print(f"| {base['flight']} | {base['meas']:.2f} | {base['floor']:.2f} (noise {base['noise']:.3f}) | "
                  + " | ".join(f"{v:.2f}" for v in row) + " |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("logs", nargs="*", help=f"tlog / .bin files (default: {' '.join(DEFAULT_LOGS)})")
    ap.add_argument("--min-speed", type=float, default=8.0, help="in-flight ground speed, m/s (default 8)")
    ap.add_argument("--decimate", type=int, default=1, help="keep every K-th IMU sample (default 1)")
    ap.add_argument("--floor", nargs="+", default=[], metavar="DIR",
                    help="eval_jsbsim work directories: print the Wiener floor at --floor-sigma instead")
    ap.add_argument("--floor-sigma", nargs="+", type=float, default=[0.0185, 0.05, 0.1])
    ap.add_argument("--coef", default="CY", choices=("CX", "CY", "CZ"))
    ap.add_argument("--turbulence", default="light")
    a = ap.parse_args(argv)
    if a.decimate < 1:
        ap.error(f"--decimate must be 1 or more, got {a.decimate}")
    if a.floor:
        print_floor(a.floor, a.floor_sigma, a.coef, a.turbulence)
        return 0
    root = Path(__file__).resolve().parents[1]
    logs = a.logs or [str(root / p) for p in DEFAULT_LOGS]
    print(f"harness: accel {HARNESS_SIGMA['accel']} m/s^2, gyro {HARNESS_SIGMA['gyro']} rad/s per sample at "
          f"{HARNESS_RATE_HZ:g} Hz (density {HARNESS_SIGMA['accel'] / math.sqrt(HARNESS_RATE_HZ / 2):.4f} "
          f"m/s^2/rtHz, {HARNESS_SIGMA['gyro'] / math.sqrt(HARNESS_RATE_HZ / 2):.5f} rad/s/rtHz)")
    rc, results = 0, []
    for p in logs:
        try:
            results.append(flight_noise(p, a.min_speed, a.decimate))
            print_flight(results[-1])
        except (InputError, DataError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            rc = 1
    if len(results) > 1:
        for seg in ("all", "motor", "glide"):
            if any(c.segment == seg for r in results for c in r.channels):
                print_summary(results, seg)
    return rc


if __name__ == "__main__":
    sys.exit(main())
