"""The limits a suggested maneuver must respect, and the nearest safe flight condition.

The airframe file's ``[limits]`` table (:class:`gcs_sysid.airframe.Limits`) gives them; a field it
lacks is taken from the flown envelope, with margins that keep inside what was flown (a maneuver
designer must not push an aircraft past what it has been seen to do without the engineer's word):

==============  ===========================================================================
V_min           the 1 % quantile of the flown airspeed (never lower)
V_max           the 99 % quantile of the flown airspeed x 1.05
alpha_max       the 99.5 % quantile of the flown alpha + 1 deg
n_max           the 99.5 % quantile of the flown load factor ``-CZ qbar S / (m g)``, at least 1.3 g
throw           0.75 x the servos' travel (limit_deg x mix), and at least the flown deflection
rate            the 99 % quantile of the flown surface rate, at least 60 deg/s
==============  ===========================================================================

The push-over side is limited to ``n_min = max(0, 2 - n_max)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..aero.table import CoefficientTable
from ..airframe import CONTROLS, Airframe
from ..errors import InputError
from .linear import G

__all__ = ["EffectiveLimits", "effective_limits", "check_peaks"]


@dataclass(frozen=True)
class EffectiveLimits:
    """The limits in force (SI) and where each came from.

    Attributes:
        V_min, V_max: m/s. n_max, n_min: g. alpha_max: rad.
        throw: control -> rad (largest deflection from neutral). rate: control -> rad/s.
        source: field -> ``"airframe file"`` or ``"flown envelope (...)"``.
    """

    V_min: float
    V_max: float
    n_max: float
    n_min: float
    alpha_max: float
    throw: dict[str, float]
    rate: dict[str, float]
    source: dict[str, str] = field(default_factory=dict)

    @property
    def defaulted(self) -> list[str]:
        """Fields not given by the airframe file."""
        return [k for k, v in self.source.items() if v != "airframe file"]

    def to_dict(self) -> dict[str, Any]:
        """JSON-able, in the units an engineer reads (m/s, g, deg, deg/s) plus the sources."""
        return {"V_min_mps": self.V_min, "V_max_mps": self.V_max, "n_max": self.n_max, "n_min": self.n_min,
                "alpha_max_deg": math.degrees(self.alpha_max),
                "throw_deg": {k: math.degrees(v) for k, v in self.throw.items()},
                "rate_dps": {k: math.degrees(v) for k, v in self.rate.items()}, "source": dict(self.source)}

    @staticmethod
    def from_dict(d: dict[str, Any]) -> "EffectiveLimits":
        """Inverse of :meth:`to_dict`."""
        return EffectiveLimits(float(d["V_min_mps"]), float(d["V_max_mps"]), float(d["n_max"]), float(d["n_min"]),
                               math.radians(d["alpha_max_deg"]),
                               {k: math.radians(v) for k, v in d["throw_deg"].items()},
                               {k: math.radians(v) for k, v in d["rate_dps"].items()}, dict(d.get("source", {})))


def effective_limits(airframe: Airframe, table: CoefficientTable | None = None,
                     rows: np.ndarray | None = None) -> EffectiveLimits:
    """The airframe's ``[limits]``, missing fields defaulted from the flown envelope (module docstring).

    Args:
        airframe: the airframe (its ``limits`` may be None).
        table: the coefficient table of the flight; needed only for fields the airframe lacks.
        rows: (T,) bool rows of ``table`` that were flown (default: its valid rows).

    Returns:
        :class:`EffectiveLimits`.

    Raises:
        InputError: a field is missing from the airframe and there are no flown data to default it
            from, or the result contradicts itself (V_min >= V_max after defaulting).
    """
    lim = airframe.limits
    src: dict[str, str] = {}
    auth = airframe.authority
    flown: dict[str, np.ndarray] = {}
    if table is not None:
        m = table.valid.copy() if rows is None else rows.copy()
        m &= np.all(np.isfinite(table.X), axis=1)
        flown = {n: table.x(n)[m] for n in ("V", "alpha", *CONTROLS)}
        cz = table.y("CZ")[m]
        ok = np.isfinite(cz) & np.isfinite(table.qbar[m])
        flown["n"] = -cz[ok] * table.qbar[m][ok] * airframe.S / (airframe.mass * G)
        dt = np.diff(table.t[m])
        for c in CONTROLS:
            dd = np.abs(np.diff(flown[c]))
            good = (dt > 0) & (dt < 0.2)
            flown[f"rate_{c}"] = dd[good] / dt[good]

    def pick(name: str, given: float | None, default, why: str) -> float:
        if given is not None:
            src[name] = "airframe file"
            return float(given)
        if not flown or len(flown.get("V", [])) < 10:
            raise InputError(f"{airframe.source or airframe.name}: [limits] {name} is not given and there is no "
                             f"flown envelope to take it from; add it to the airframe file")
        src[name] = f"flown envelope ({why})"
        return float(default())

    q = lambda k, p: float(np.quantile(flown[k], p)) if len(flown.get(k, [])) else float("nan")  # noqa: E731
    V_min = pick("V_min", lim and lim.V_min, lambda: q("V", 0.01), "1 % quantile of the flown airspeed")
    V_max = pick("V_max", lim and lim.V_max, lambda: 1.05 * q("V", 0.99), "99 % quantile x 1.05")
    alpha_max = pick("alpha_max", lim and lim.alpha_max, lambda: q("alpha", 0.995) + math.radians(1.0),
                     "99.5 % quantile + 1 deg")
    n_max = pick("n_max", lim and lim.n_max, lambda: max(1.3, q("n", 0.995) if len(flown.get("n", [])) else 1.3),
                 "99.5 % quantile of -CZ qbar S / (m g), at least 1.3 g")
    throw, rate = {}, {}
    for c in CONTROLS:
        if auth[c] <= 0:
            continue
        given = (lim.throw.get(c) if lim else None)
        throw[c] = pick(f"throw.{c}", given,
                        lambda c=c: max(0.75 * auth[c], min(auth[c], q(c, 0.995) if len(flown.get(c, [])) else 0.0)),
                        "0.75 x servo travel")
        given = (lim.rate.get(c) if lim else None)
        rate[c] = pick(f"rate.{c}", given,
                       lambda c=c: max(math.radians(60.0),
                                       q(f"rate_{c}", 0.99) if len(flown.get(f"rate_{c}", [])) else 0.0),
                       "99 % quantile of the flown surface rate, at least 60 deg/s")
    if not V_min < V_max:
        raise InputError(f"limits contradict each other: V_min {V_min:.1f} m/s is not below V_max {V_max:.1f} m/s "
                         f"({src['V_min']}; {src['V_max']}); set both in the airframe's [limits]")
    if not alpha_max > 0:
        raise InputError(f"limits: alpha_max {math.degrees(alpha_max):.1f} deg must be positive; set alpha_max_deg "
                         f"in the airframe's [limits]")
    return EffectiveLimits(V_min, V_max, n_max, max(0.0, 2.0 - n_max), alpha_max, throw, rate, src)


def check_peaks(expected: dict[str, float], lim: EffectiveLimits, tol: float = 1e-6) -> list[str]:
    """The limits an expected response breaks, one phrase each (empty when inside all of them).

    Args:
        expected: as :attr:`gcs_sysid.maneuvers.Suggestion.expected` (``V_mps``, ``alpha_max_deg``,
            ``n_max``, ``n_min``, ``deflection_max_deg`` and ``surface_rate_max_dps`` per control).
        lim: the limits.
    """
    out = []
    V = expected.get("V_mps", float("nan"))
    if not lim.V_min - tol <= V <= lim.V_max + tol:
        out.append(f"V {V:.1f} m/s outside {lim.V_min:.1f}-{lim.V_max:.1f} m/s")
    if expected["alpha_max_deg"] > math.degrees(lim.alpha_max) + tol:
        out.append(f"alpha {expected['alpha_max_deg']:.1f} deg above {math.degrees(lim.alpha_max):.1f} deg")
    if expected["n_max"] > lim.n_max + tol:
        out.append(f"load factor {expected['n_max']:.2f} g above {lim.n_max:.2f} g")
    if expected["n_min"] < lim.n_min - tol:
        out.append(f"load factor {expected['n_min']:.2f} g below {lim.n_min:.2f} g")
    for c, th in lim.throw.items():
        v = expected.get(f"deflection_max_deg.{c}")
        if v is not None and v > math.degrees(th) + 1e-4:
            out.append(f"{c} {v:.1f} deg beyond its {math.degrees(th):.1f} deg throw")
        r = expected.get(f"surface_rate_max_dps.{c}")
        if r is not None and r > math.degrees(lim.rate[c]) + 1e-3:
            out.append(f"{c} rate {r:.0f} deg/s above {math.degrees(lim.rate[c]):.0f} deg/s")
    return out
