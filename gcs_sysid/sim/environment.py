"""Atmosphere and turbulence: ISA troposphere and Dryden gust forming filters.

ISA (ICAO standard atmosphere, troposphere below 11 km)::

    T = 288.15 - 0.0065 h,  p = 101325 (T / 288.15)^5.25588,  rho = p / (287.053 T)

Dryden turbulence, low-altitude form of MIL-F-8785C / MIL-HDBK-1797 (sec. 3.7),
h the height above ground in ft::

    L_w = h,  L_u = L_v = h / (0.177 + 0.000823 h)^1.2
    sigma_w = 0.1 W20,  sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4
    H_u(s) = sigma_u sqrt(2 L_u / V) / (1 + (L_u / V) s)
    H_v(s) = sigma_v sqrt(L_v / V) (1 + sqrt(3) (L_v / V) s) / (1 + (L_v / V) s)^2   (H_w alike)

with unit-intensity white noise inputs (gains chosen so the output variance is
sigma^2), W20 the wind speed at 20 ft: 15 kt light, 30 kt moderate, 45 kt
severe. Gusts are applied along the body axes (linear gusts only).

References:
    MIL-HDBK-1797, *Flying Qualities of Piloted Aircraft*, 1997, sec. 3.7 and app. A.
    Beard and McLain, *Small Unmanned Aircraft*, 2012, sec. 4.4 (Dryden gust model).
"""

from __future__ import annotations

import numpy as np

__all__ = ["RHO0", "G0", "isa", "isa_jax", "W20_BY_INTENSITY", "dryden_scales"]

RHO0 = 1.225          # kg/m^3, sea-level ISA density
G0 = 9.80665          # m/s^2
_T0, _P0, _LAPSE, _R = 288.15, 101325.0, 0.0065, 287.053
_EXP = 5.25588
_KT = 0.514444
_FT = 0.3048

#: W20 (wind at 20 ft, m/s) of the MIL-HDBK-1797 intensity levels.
W20_BY_INTENSITY = {"none": 0.0, "light": 15 * _KT, "moderate": 30 * _KT, "severe": 45 * _KT}


def isa(alt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ISA at geometric altitude ``alt`` (m, any shape): (pressure Pa, temperature K, density kg/m^3)."""
    T = _T0 - _LAPSE * np.asarray(alt, float)
    p = _P0 * (T / _T0) ** _EXP
    return p, T, p / (_R * T)


def isa_jax(alt):
    """ISA density (kg/m^3) at altitude ``alt`` (m), JAX-traceable."""
    T = _T0 - _LAPSE * alt
    return _P0 * (T / _T0) ** _EXP / (_R * T)


def dryden_scales(agl: float, w20: float) -> tuple[np.ndarray, np.ndarray]:
    """Dryden scale lengths and intensities at low altitude.

    Args:
        agl: height above ground, m (floored at 10 ft).
        w20: wind speed at 20 ft, m/s.

    Returns:
        (L, sigma): scale lengths (L_u, L_v, L_w) in m and rms gusts
        (sigma_u, sigma_v, sigma_w) in m/s, each of shape (3,).

    Source: MIL-HDBK-1797 sec. 3.7 (low-altitude, h < 1000 ft; used up to 1000 ft
    and held constant above).
    """
    h = min(max(agl / _FT, 10.0), 1000.0)
    d = 0.177 + 0.000823 * h
    L = np.array([h / d**1.2, h / d**1.2, h]) * _FT
    sw = 0.1 * w20
    sigma = np.array([sw / d**0.4, sw / d**0.4, sw])
    return L, sigma
