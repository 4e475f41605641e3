"""What the rate smoother left in the gyro: a Wiener correction chosen from the residual's spectrum.

The rate smoother (:mod:`.rates`) models the angular acceleration as a smooth part
of one bandwidth (per axis, maximum likelihood, typically 1-2.5 Hz) plus the
controls' responses. Signal it cannot follow (gust-driven moments at 2-5 Hz, a
response shape outside its transient basis) stays in the *residual*
``z - w_hat`` (gyro minus smoothed rate), where it sits on top of the gyro's
white noise. That residual says per axis and per flight how much signal is
left and at which frequencies: its power spectral density ``S_r(f)`` (Welch)
against the white-noise floor ``N`` (the same spectrum's median level far above
any flight dynamics) gives the Wiener gain ``G(f) = 1 - N / S_r(f)``, used only
where the excess is significant, ``S_r > N (1 + k / sqrt(n_avg))`` (about ``k``
standard errors of a periodogram averaged over ``n_avg`` half-overlapping Hann segments),
and below ``f_max``. ``G`` applied to the
residual's Fourier transform gives the missed rate, ``j 2 pi f G`` its angular
acceleration (zero phase, non-causal: offline). Where the residual is white
(light turbulence on aircraft whose dynamics the smoother follows) nothing
changes; where it is not, the bandwidth is widened exactly where the data show
signal over the noise floor.

Measured on JSBSim (docs/estimation.md, docs/benchmarks.md): light turbulence on the
tuning aircraft (c172x, sgs) Cl Cm Cn unchanged or up to 0.4 points better; moderate
turbulence Cl 1.2-1.7 points better; the held-out pa28 Cl 13.3 -> 7.8 % (light).

References:
    Wiener filter and spectral subtraction: Bendat and Piersol, *Random Data*, 4th ed., Wiley 2010,
    sec. 6.1 and 11.5 (Welch estimates and their random error, ``1 / sqrt(n_avg)``); Morelli and
    Klein, *Aircraft System Identification*, 2nd ed., 2016, sec. 11.1 (smoothing in the frequency
    domain from the signal and noise spectra, and numerical differentiation of the smoothed signal);
    Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., AIAA 2015, sec. 10.3 (data
    compatibility: numerical differentiation of measured rates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import welch

__all__ = ["WINDOW_S", "K_SIGMA", "F_MAX_HZ", "ResidualCorrection", "residual_wiener"]

#: Welch segment length, s (0.39 Hz resolution; a 90 s flight averages about 70 half-overlapping segments).
WINDOW_S = 2.56
#: Significance of the excess over the noise floor, standard errors of the averaged periodogram.
K_SIGMA = 3.0
#: Highest frequency corrected, Hz (flight dynamics; above it the residual is taken as noise).
F_MAX_HZ = 8.0


@dataclass
class ResidualCorrection:
    """The part of the rate the smoother missed, and its derivative.

    Attributes:
        rate: (n,) correction to the smoothed rate, rad/s.
        accel: (n,) correction to its angular acceleration, rad/s^2.
        accel_var: variance the correction's own error adds to the acceleration, (rad/s^2)^2 (the
            Wiener error ``G N (2 pi f)^2`` integrated over the corrected band; 0 if none).
        freq: (nf,) frequencies of the Welch estimate, Hz.
        gain: (nf,) Wiener gain applied there (0 where the residual is at the noise floor).
        noise_psd: white-noise floor of the residual, one-sided PSD, (rad/s)^2/Hz.
    """

    rate: np.ndarray
    accel: np.ndarray
    accel_var: float
    freq: np.ndarray
    gain: np.ndarray
    noise_psd: float

    @property
    def band_hz(self) -> tuple[float, float]:
        """Lowest and highest frequency with a non-zero gain, Hz; NaN, NaN if none."""
        f = self.freq[self.gain > 0]
        return (float(f.min()), float(f.max())) if len(f) else (float("nan"), float("nan"))


def residual_wiener(dt: float, residual: np.ndarray, window_s: float = WINDOW_S, k_sigma: float = K_SIGMA,
                    f_max_hz: float = F_MAX_HZ) -> ResidualCorrection | None:
    """Wiener estimate of the signal left in a smoother's residual, and of its derivative.

    Args:
        dt: grid step, s.
        residual: (n,) measured minus smoothed rate, rad/s, no NaN (one gap-free piece).
        window_s: Welch segment length, s.
        k_sigma: a frequency is corrected only where the residual's PSD exceeds the noise floor by
            ``k_sigma`` standard errors of the averaged periodogram.
        f_max_hz: highest frequency corrected, Hz.

    Returns:
        :class:`ResidualCorrection`, or None when the piece is shorter than four windows (too short to
        tell signal from noise), not finite, or sampled too slowly to read the noise floor above the
        flight dynamics (``0.6 x Nyquist < f_max_hz``: a grid below about 27 Hz for the default 8 Hz;
        at 10 Hz the band above 3 Hz still holds roll motion, and the floor read there is not white
        noise).

    Source: module docstring (Wiener gain ``1 - N / S`` from the measured spectrum: Bendat and Piersol
    2010 sec. 6.1; Morelli and Klein 2016 sec. 11.1).
    """
    r = np.asarray(residual, float)
    n = len(r)
    nper = max(int(round(window_s / dt)), 8)
    nyq = 0.5 / dt
    if n < 4 * nper or not np.isfinite(r).all() or 0.6 * nyq < f_max_hz:
        return None
    f, S = welch(r, 1.0 / dt, nperseg=nper)          # Hann, 50 % overlap, mean removed per segment
    N = float(np.median(S[f > 0.6 * nyq]))             # white floor, read far above the flight dynamics
    n_avg = 2.0 * n / nper - 1.0                      # half-overlapping segments averaged
    thr = N * (1.0 + k_sigma / np.sqrt(n_avg))
    band = (f > 0) & (f <= f_max_hz)
    G = np.where(band & (S > thr), 1.0 - N / np.maximum(S, 1e-300), 0.0)
    if not (G > 0).any():
        z = np.zeros(n)
        return ResidualCorrection(z, z.copy(), 0.0, f, G, N)
    nf = 1 << int(np.ceil(np.log2(2 * n)))              # zero padded: no wrap-around of the response
    ff = np.fft.rfftfreq(nf, dt)
    Gi = np.interp(ff, f, G)
    R = np.fft.rfft(r - r.mean(), nf)
    rate = np.fft.irfft(Gi * R, nf)[:n]
    accel = np.fft.irfft(Gi * R * (2j * np.pi * ff), nf)[:n]
    df = f[1] - f[0]
    accel_var = float(np.sum(G * N * (2 * np.pi * f) ** 2) * df)
    return ResidualCorrection(rate, accel, accel_var, f, G, N)
