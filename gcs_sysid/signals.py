"""Maneuver input waveforms for system identification: doublet, 3-2-1-1, multisine.

Used by the simulation (``gcs_sysid.sim``) to fly a maneuver plan and by the
maneuver-suggestion module to describe what to fly. Every waveform is a plain
numpy function of a time array: it is zero before ``start`` and after the
maneuver ends, so waveforms of several maneuvers can be summed.

References:
    Morelli, E. A. and Klein, V., *Aircraft System Identification: Theory and
    Practice*, 2nd ed., Sunflyte, 2016, ch. 9 (input design: doublets, 3-2-1-1,
    orthogonal optimised multisines).
    Morelli, E. A., "Multiple input design for real-time parameter estimation in
    the frequency domain", 13th IFAC Symposium on System Identification, 2003
    (harmonics distributed among inputs so that the inputs are mutually
    orthogonal in time and frequency; phases optimised for a low relative peak
    factor).
    Schroeder, M. R., "Synthesis of low-peak-factor signals and binary sequences
    with low autocorrelation", IEEE Trans. Inf. Theory 16(1), 1970, 85-89.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.optimize import minimize

from .errors import InputError

__all__ = [
    "KINDS",
    "doublet",
    "three_two_one_one",
    "multisine",
    "multisine_frequencies",
    "multisine_phases",
    "relative_peak_factor",
    "duration_of",
    "waveform",
    "check_amplitudes",
]

#: Maneuver kinds understood by :func:`waveform` and :func:`duration_of`.
KINDS = ("doublet", "3211", "multisine")


def _pulses(t: np.ndarray, start: float, pulse_width: float, pattern, amplitude: float) -> np.ndarray:
    if not pulse_width > 0:
        raise InputError(f"pulse width must be > 0 s, got {pulse_width!r}")
    t = np.asarray(t, dtype=float)
    k = np.floor((t - start) / pulse_width).astype(np.int64)
    levels = np.concatenate([[0.0], np.repeat(pattern[:, 1], pattern[:, 0].astype(int)), [0.0]])
    n = int(pattern[:, 0].sum())
    idx = np.where((k >= 0) & (k < n), k + 1, 0)
    return amplitude * levels[idx]


def doublet(t: np.ndarray, start: float, pulse_width: float, amplitude: float) -> np.ndarray:
    """Doublet: ``+amplitude`` for one pulse width, then ``-amplitude`` for one.

    Args:
        t: time, s, shape (T,).
        start: start time, s (same clock as ``t``).
        pulse_width: width of each pulse, s (total duration ``2 * pulse_width``).
        amplitude: pulse height (rad for a surface, fraction for throttle).

    Returns:
        input, shape (T,), zero outside ``[start, start + 2 pulse_width)``.

    Raises:
        InputError: ``pulse_width <= 0``.

    Source: Morelli and Klein (2016), sec. 9.2.
    """
    return _pulses(t, start, pulse_width, np.array([[1, 1.0], [1, -1.0]]), amplitude)


def three_two_one_one(t: np.ndarray, start: float, pulse_width: float, amplitude: float) -> np.ndarray:
    """3-2-1-1: pulses of 3, 2, 1 and 1 widths with alternating sign (+, -, +, -).

    Args:
        t: time, s, shape (T,).
        start: start time, s.
        pulse_width: unit pulse width, s (total duration ``7 * pulse_width``).
        amplitude: pulse height (rad, or fraction for throttle).

    Returns:
        input, shape (T,), zero outside ``[start, start + 7 pulse_width)``.

    Raises:
        InputError: ``pulse_width <= 0``.

    Source: Morelli and Klein (2016), sec. 9.2 (Koehler's 3-2-1-1 input).
    """
    return _pulses(t, start, pulse_width, np.array([[3, 1.0], [2, -1.0], [1, 1.0], [1, -1.0]]), amplitude)


def multisine_frequencies(duration: float, band: tuple[float, float], n_inputs: int = 1,
                          index: int = 0) -> np.ndarray:
    """Harmonic frequencies (Hz) given to input ``index`` of ``n_inputs`` orthogonal multisines.

    The harmonics ``k / duration`` inside ``band`` are dealt out to the inputs in
    turn (k = k0, k0+n, ... for input 0, k0+1, ... for input 1), so the inputs
    share no frequency and are mutually orthogonal over one period (Morelli 2003).

    Args:
        duration: period of the multisine, s.
        band: (f_low, f_high), Hz.
        n_inputs: number of inputs excited at the same time.
        index: which input (0-based).

    Returns:
        frequencies in Hz, shape (K,), K >= 1.

    Raises:
        InputError: the band holds fewer than ``n_inputs`` harmonics of ``1/duration``.
    """
    f_lo, f_hi = float(band[0]), float(band[1])
    if not (duration > 0 and 0 < f_lo < f_hi):
        raise InputError(f"multisine needs duration > 0 and a band 0 < f_low < f_high Hz, got {duration!r}, {band!r}")
    if not 0 <= index < n_inputs:
        raise InputError(f"multisine input index {index} must lie in 0..{n_inputs - 1}")
    k = np.arange(int(np.ceil(f_lo * duration - 1e-9)), int(np.floor(f_hi * duration + 1e-9)) + 1)
    k = k[k >= 1]
    if k.size < n_inputs:
        raise InputError(
            f"multisine band {f_lo:g}-{f_hi:g} Hz over {duration:g} s holds {k.size} harmonics, fewer than "
            f"the {n_inputs} inputs; lengthen the duration or widen the band"
        )
    return k[index::n_inputs] / duration


def relative_peak_factor(u: np.ndarray) -> float:
    """Relative peak factor ``(max - min) / (2 sqrt(2) rms)``; 1 for a single sinusoid.

    Source: Morelli and Klein (2016), eq. 9.23.
    """
    u = np.asarray(u, float)
    rms = np.sqrt(np.mean(u**2))
    return float((u.max() - u.min()) / (2.0 * np.sqrt(2.0) * rms)) if rms > 0 else float("inf")


def multisine_phases(freqs: np.ndarray, duration: float, optimize: bool = True) -> np.ndarray:
    """Phases (rad) of equal-amplitude harmonics giving a low peak factor.

    Starts from Schroeder's phases ``phi_k = -pi k (k - 1) / K`` and, if
    ``optimize``, lowers the relative peak factor further by minimising a smooth
    p-norm of the signal over one period (BFGS), as in Morelli (2003), whose
    phases are optimised for minimum relative peak factor.

    Args:
        freqs: harmonic frequencies, Hz, shape (K,).
        duration: period, s.
        optimize: refine Schroeder's phases.

    Returns:
        phases, rad, shape (K,).
    """
    return np.array(_phases(tuple(float(f) for f in freqs), float(duration), bool(optimize)))


@lru_cache(maxsize=256)
def _phases(freqs: tuple[float, ...], duration: float, optimize: bool) -> tuple[float, ...]:
    freqs = np.asarray(freqs)
    K = len(freqs)
    kk = np.arange(1, K + 1)
    phi0 = -np.pi * kk * (kk - 1) / K
    if not optimize or K < 2:
        return tuple(phi0)
    tau = np.linspace(0.0, duration, 512, endpoint=False)
    arg = 2 * np.pi * np.outer(tau, freqs)                    # (N, K)
    c, s = np.cos(arg), np.sin(arg)
    p = 16.0

    def cost(phi):
        cp, sp = np.cos(phi), np.sin(phi)
        u = c @ cp - s @ sp                                   # sum_k cos(arg + phi)
        m = np.abs(u).max()
        w = (np.abs(u) / m) ** p
        val = m * np.mean(w) ** (1 / p)
        # gradient of the p-norm: d/dphi_k of mean(|u|^p)^(1/p)
        du = -(c * sp) - (s * cp)                             # (N, K)
        g_u = (np.mean(w) ** (1 / p - 1)) * (w / np.where(u == 0, 1, u)) / len(u)
        grad = (g_u * m) @ du
        return val, grad

    res = minimize(cost, phi0, jac=True, method="BFGS", options={"maxiter": 60})
    phi = res.x
    u_opt = np.cos(arg + phi).sum(1)
    u_sch = np.cos(arg + phi0).sum(1)
    return tuple(phi if relative_peak_factor(u_opt) < relative_peak_factor(u_sch) else phi0)


def multisine(t: np.ndarray, start: float, duration: float, band: tuple[float, float], amplitude: float,
              n_inputs: int = 1, index: int = 0, optimize: bool = True) -> np.ndarray:
    """Orthogonal, phase-optimised multisine of one period.

    ``u(t) = A * sum_k cos(2 pi f_k (t - start - tau0) + phi_k) / peak`` on
    ``[start, start + duration)``, zero elsewhere, with the frequencies of
    :func:`multisine_frequencies`, the phases of :func:`multisine_phases`, the
    time origin ``tau0`` moved to a zero crossing of the periodic signal so the
    input starts and ends near zero (Morelli 2003), and the peak scaled to
    ``amplitude``.

    Args:
        t: time, s, shape (T,).
        start: start, s.
        duration: one period, s; its harmonics ``k / duration`` are the frequencies.
        band: (f_low, f_high), Hz.
        amplitude: peak value (rad, or fraction for throttle).
        n_inputs: inputs excited together (each gets its own harmonics).
        index: this input, 0-based.
        optimize: optimise phases beyond Schroeder's.

    Returns:
        input, shape (T,).

    Raises:
        InputError: bad band or duration (see :func:`multisine_frequencies`).
    """
    f = multisine_frequencies(duration, band, n_inputs, index)
    phi = multisine_phases(f, duration, optimize)
    tau = np.linspace(0.0, duration, 2048, endpoint=False)
    u_ref = np.cos(2 * np.pi * np.outer(tau, f) + phi).sum(1)
    crossing = np.nonzero((u_ref[:-1] <= 0) & (u_ref[1:] > 0))[0]
    tau0 = tau[crossing[0]] if crossing.size else 0.0
    peak = np.abs(u_ref).max()
    t = np.asarray(t, float)
    rel = t - start
    inside = (rel >= 0) & (rel < duration)
    out = np.zeros(t.shape)
    out[inside] = amplitude * np.cos(2 * np.pi * np.outer(rel[inside] + tau0, f) + phi).sum(1) / peak
    return out


def duration_of(kind: str, pulse_width: float) -> float:
    """Length of a maneuver in s.

    Args:
        kind: ``"doublet"`` (2 pulse widths), ``"3211"`` (7 pulse widths) or
            ``"multisine"`` (``pulse_width`` is then the multisine period itself).
        pulse_width: s.

    Raises:
        InputError: unknown kind.
    """
    n = {"doublet": 2.0, "3211": 7.0, "multisine": 1.0}.get(kind)
    if n is None:
        raise InputError(f"unknown maneuver kind '{kind}' (expected one of {', '.join(KINDS)})")
    return n * float(pulse_width)


def waveform(kind: str, t: np.ndarray, start: float, amplitude: float, pulse_width: float | None = None,
             duration: float | None = None, band: tuple[float, float] | None = None, n_inputs: int = 1,
             index: int = 0) -> np.ndarray:
    """Dispatch on ``kind`` (see :data:`KINDS`); arguments as for the single waveforms.

    Raises:
        InputError: unknown kind or a missing pulse width / duration / band.
    """
    if kind in ("doublet", "3211"):
        if pulse_width is None:
            raise InputError(f"maneuver '{kind}' needs a pulse width (pulse_s)")
        fn = doublet if kind == "doublet" else three_two_one_one
        return fn(t, start, pulse_width, amplitude)
    if kind == "multisine":
        if duration is None or band is None:
            raise InputError("maneuver 'multisine' needs duration_s and band_hz = [f_low, f_high]")
        return multisine(t, start, duration, band, amplitude, n_inputs, index)
    raise InputError(f"unknown maneuver kind '{kind}' (expected one of {', '.join(KINDS)})")


def check_amplitudes(maneuvers, authority: dict[str, float], where: str, airframe_name: str = "") -> None:
    """Refuse inputs that ask a surface for more than its servos can give.

    Args:
        maneuvers: objects with ``controls`` (names) and ``amplitude`` (rad per control), e.g. the
            ``maneuvers`` of a :class:`gcs_sysid.sim.Plan`.
        authority: control -> travel in rad (:attr:`gcs_sysid.airframe.Airframe.authority`); controls
            not in it (throttle) are not checked here.
        where: the plan's name for the message. airframe_name: for the message.

    Raises:
        InputError: one line naming the maneuver, the control, the amplitude asked and the travel, or a
            surface that no servo drives.
    """
    for i, m in enumerate(maneuvers):
        for c, a in zip(m.controls, m.amplitude):
            if c not in authority:
                continue
            w = f"{where}: [[maneuver]] #{i + 1}"
            if authority[c] <= 0:
                raise InputError(f"{w} excites {c}, but no servo of airframe '{airframe_name}' drives it")
            if abs(a) > authority[c] + 1e-9:
                raise InputError(f"{w} asks {c} for {np.degrees(abs(a)):.1f} deg, beyond the surface's travel of "
                                 f"{np.degrees(authority[c]):.1f} deg (airframe '{airframe_name}': limit_deg x mix)")
