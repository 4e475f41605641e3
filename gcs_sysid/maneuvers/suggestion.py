"""What a suggestion is: one maneuver to fly, as data (JSON round trip), and the list with its context."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Suggestion", "SuggestionList", "SURFACE_NAMES"]

SURFACE_NAMES = {"delta_e": "elevator", "delta_a": "aileron", "delta_r": "rudder"}


@dataclass
class Suggestion:
    """One maneuver to fly next.

    Attributes:
        rank: 1 = fly first.
        coefficients: targeted coefficients, weakest first.
        kind: ``"doublet"``, ``"3211"`` or ``"multisine"`` (:data:`gcs_sysid.signals.KINDS`).
        controls: controls excited, e.g. ``("delta_e",)``.
        amplitude_rad, amplitude_deg: peak input of the first control.
        amplitudes_rad: control -> peak input, rad.
        pulse_width_s: unit pulse width (doublet, 3211); for a multisine its shortest half period.
        duration_s: the whole maneuver including trim lead-in and settling, s.
        flight_condition: 1-g trim: ``V`` m/s, ``alpha`` rad, ``alpha_deg``, ``load_factor`` (1),
            ``delta_e_trim`` rad, ``rho`` kg/m^3, ``density_altitude_m``, ``altitude_band_m`` [lo, hi].
        expected_reduction: mean relative reduction of predictive variance at the region's points
            over the targeted coefficients, 0..1.
        reductions: coefficient -> relative reduction.
        priority: ranking key (reduction weighted towards the weakest, moment-first coefficients).
        reason: why, naming coefficient, region and sigma.
        region: the (weakest coefficient's) region: ``axes``, ``bounds``, ``center``, ``mean_rel_sigma``.
        mode_hz: natural frequency (Hz) of the excited mode(s), control -> Hz.
        band_hz: multisine band (lo, hi) in Hz, else None.
        t: waveform time, s, shape (K,). u: control -> input deviation from trim, rad, shape (K,).
        assumed: derivatives taken from typical values rather than these data.
        expected: predicted peaks of the response (linear model of the identified derivatives):
            ``p_max_dps q_max_dps r_max_dps`` (|rate|, deg/s), ``alpha_max_deg alpha_min_deg``,
            ``beta_max_deg``, ``bank_max_deg``, ``n_max n_min`` (g), ``V_mps``, and per control
            ``deflection_max_deg.<control>`` (|trim + input|) and ``surface_rate_max_dps.<control>``.
        lead_s: trim time before the input, s. input_s: length of the input itself, s.
        fix: what the maneuver fixes, e.g. ``"aileron inputs at 16 m/s"`` (its group of regions).
        notes: limit and reach remarks (amplitude cut by a limit, region out of reach ...).
    """

    rank: int
    coefficients: tuple[str, ...]
    kind: str
    controls: tuple[str, ...]
    amplitude_rad: float
    amplitude_deg: float
    amplitudes_rad: dict[str, float]
    pulse_width_s: float
    duration_s: float
    flight_condition: dict[str, Any]
    expected_reduction: float
    reductions: dict[str, float]
    priority: float
    reason: str
    region: dict[str, Any]
    mode_hz: dict[str, float] = field(default_factory=dict)
    band_hz: tuple[float, float] | None = None
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    u: dict[str, np.ndarray] = field(default_factory=dict)
    assumed: list[str] = field(default_factory=list)
    expected: dict[str, float] = field(default_factory=dict)
    lead_s: float = 1.0
    input_s: float = 0.0
    fix: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def control(self) -> str:
        """The first (main) control."""
        return self.controls[0]

    @property
    def surfaces(self) -> list[str]:
        """Surface names of the controls."""
        return [SURFACE_NAMES[c] for c in self.controls]

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict (waveform as lists)."""
        r = lambda x: round(float(x), 6)  # noqa: E731
        fc = {k: ([r(x) for x in v] if isinstance(v, (list, tuple)) else r(v))
              for k, v in self.flight_condition.items()}
        return {
            "rank": self.rank, "coefficients": list(self.coefficients), "kind": self.kind,
            "controls": list(self.controls), "surfaces": self.surfaces,
            "amplitude_rad": r(self.amplitude_rad), "amplitude_deg": r(self.amplitude_deg),
            "amplitudes_rad": {k: r(v) for k, v in self.amplitudes_rad.items()},
            "amplitudes_deg": {k: r(np.degrees(r(v))) for k, v in self.amplitudes_rad.items()},
            "pulse_width_s": r(self.pulse_width_s), "duration_s": r(self.duration_s),
            "lead_s": r(self.lead_s), "input_s": r(self.input_s),
            "flight_condition": fc,
            "expected_reduction": r(self.expected_reduction),
            "reductions": {k: r(v) for k, v in self.reductions.items()},
            "priority": r(self.priority), "reason": self.reason, "region": self.region,
            "mode_hz": {k: r(v) for k, v in self.mode_hz.items()},
            "band_hz": None if self.band_hz is None else [r(x) for x in self.band_hz],
            "expected": {k: r(v) for k, v in self.expected.items()},
            "fix": self.fix, "notes": list(self.notes),
            "waveform": {"t": np.round(self.t, 4).tolist(), **{k: np.round(v, 6).tolist() for k, v in self.u.items()}},
            "assumed": list(self.assumed),
        }

    @staticmethod
    def from_dict(d: dict[str, Any]) -> "Suggestion":
        """Inverse of :meth:`to_dict`."""
        wf = dict(d.get("waveform", {}))
        t = np.asarray(wf.pop("t", []), float)
        return Suggestion(int(d["rank"]), tuple(d["coefficients"]), d["kind"], tuple(d["controls"]),
                          float(d["amplitude_rad"]), float(d["amplitude_deg"]), dict(d["amplitudes_rad"]),
                          float(d["pulse_width_s"]), float(d["duration_s"]), dict(d["flight_condition"]),
                          float(d["expected_reduction"]), dict(d["reductions"]), float(d["priority"]), d["reason"],
                          dict(d["region"]), dict(d.get("mode_hz", {})),
                          None if d.get("band_hz") is None else tuple(d["band_hz"]), t,
                          {k: np.asarray(v, float) for k, v in wf.items()}, list(d.get("assumed", [])),
                          {k: float(v) for k, v in d.get("expected", {}).items()}, float(d.get("lead_s", 1.0)),
                          float(d.get("input_s", 0.0)), str(d.get("fix", "")), list(d.get("notes", [])))


class SuggestionList(list):
    """The ranked suggestions (a list of :class:`Suggestion`) and what the report says around them.

    Attributes:
        context: JSON-able dict: ``limits`` (:meth:`EffectiveLimits.to_dict`), ``gated``
            (coefficient -> {"why", "fix"}: not ranked because the model failed its held-out check),
            ``out_of_reach`` (one line per flagged region outside the limits, with the nearest safe
            condition flown instead), ``groups`` (flagged regions grouped by what would fix them),
            ``modes`` (the modes at the reference condition, Hz), ``weights`` (coefficient ->
            ranking weight), ``targets`` (coefficients the user targeted, or all).
    """

    def __init__(self, items=(), context: dict[str, Any] | None = None):
        super().__init__(items)
        self.context: dict[str, Any] = dict(context or {})
