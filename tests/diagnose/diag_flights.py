"""Simulated test flights for the diagnosis tests: a dense-excitation plan and hidden effects.

The plan flies ~90 s of multisines on all three surfaces plus throttle, with
3-2-1-1s and doublets in between (surface amplitudes 4-7 deg, as
``data/plans/sysid-trainer.toml``), two airspeeds and two headings (so wind,
airspeed and alpha-dependent causes are all excited), calm-morning Dryden
turbulence (W20 = 1.5 m/s: sysid flights are flown in calm air) and the default
sensor noise.
"""

from __future__ import annotations

from pathlib import Path

from gcs_sysid.sim import Effects, plan_from_dict

ROOT = Path(__file__).resolve().parents[2]
AIRFRAME = ROOT / "data" / "airframes" / "sim-trainer.toml"
MODEL = ROOT / "data" / "models" / "sim-trainer.toml"


def plan_doc(duration: float = 90.0, seed: int = 7, turbulence: str | float = 1.5) -> dict:
    """A plan document (``docs/sim.md``) with dense excitation from t = 30 s."""
    t0 = 30.0
    man = []
    k = 0
    t = t0 + 2.0
    while t + 12.0 <= t0 + duration - 1.0:
        if k % 3 == 0:
            man.append({"kind": "multisine", "controls": ["delta_e", "delta_a", "delta_r"], "start_s": t,
                        "duration_s": 10.0, "band_hz": [0.2, 2.0], "amplitude_deg": [4.0, 5.0, 6.0]})
        elif k % 3 == 1:
            man.append({"kind": "3211", "control": "delta_e", "start_s": t, "pulse_s": 0.35, "amplitude_deg": 5.0})
            man.append({"kind": "3211", "control": "delta_a", "start_s": t + 3.0, "pulse_s": 0.3,
                        "amplitude_deg": 6.0})
            man.append({"kind": "3211", "control": "delta_r", "start_s": t + 6.0, "pulse_s": 0.35,
                        "amplitude_deg": 7.0})
        else:
            man.append({"kind": "multisine", "controls": ["delta_e", "delta_a", "delta_r", "delta_t"], "start_s": t,
                        "duration_s": 10.0, "band_hz": [0.15, 1.5], "amplitude_deg": [4.0, 5.0, 6.0, 0.0]})
            man[-1].pop("amplitude_deg")
            man[-1]["amplitude"] = [0.07, 0.09, 0.1, 0.12]
        t += 12.0
        k += 1
    return {
        "name": "diagnose-test", "duration_s": duration, "rate_hz": 50.0, "start_time_s": t0, "seed": seed,
        "initial": {"airspeed_mps": 17.0, "altitude_m": 150.0, "heading_deg": 0.0},
        "setpoint": [{"start_s": t0 + duration * 0.5, "airspeed_mps": 21.0, "heading_deg": 120.0}],
        "maneuver": man,
        "turbulence": {"intensity": turbulence} if isinstance(turbulence, str) else {"w20_mps": float(turbulence)},
    }


def effects(cause: str, value) -> Effects:
    """An Effects with one hidden cause (catalogue name) of size ``value``."""
    if cause is None:
        return Effects()
    if ":" in cause and cause.split(":")[0] in ("CX", "CY", "CZ", "Cl", "Cm", "Cn"):
        c, term = cause.split(":", 1)
        return Effects(aero=((c, term, float(value)),))
    names = ("delta_e", "delta_a", "delta_r", "delta_t")
    if cause.startswith("delay:"):
        d = [0.0] * 4
        d[names.index(cause[6:])] = value
        return Effects(delay=tuple(d))
    if cause.startswith("stuck:"):
        s = [float("inf")] * 4
        s[names.index(cause[6:])] = value
        return Effects(stuck=tuple(s))
    if cause == "bias:airspeed":
        return Effects(airspeed_bias=value)
    if cause == "scale:airspeed":
        return Effects(airspeed_scale=value)
    if cause == "bias:alpha":
        return Effects(alpha_bias=value)
    if cause == "bias:beta":
        return Effects(beta_bias=value)
    if cause.startswith("bias:gyro_") or cause.startswith("bias:accel_"):
        v = [0.0, 0.0, 0.0]
        v["xyz".index(cause[-1])] = value
        return Effects(gyro_bias=tuple(v)) if "gyro" in cause else Effects(accel_bias=tuple(v))
    if cause == "wind":
        return Effects(wind_ned=tuple(value))
    if cause == "mass":
        return Effects(mass_delta=value)
    if cause == "cg_offset":
        return Effects(cg_offset=tuple(value))
    raise ValueError(cause)


class TruthStates:
    """FlightStates-like view of a SimResult's truth with the logged commands as controls (sim-truth path)."""

    def __init__(self, result):
        self.t = result.t
        self.rate_hz = result.rate_hz
        self.data = {k: v for k, v in result.truth.items()}
        for c, u in result.commands.items():
            self.data[c] = u
        self.notes, self.missing = [], []

    def __getitem__(self, k):
        return self.data[k]

    def __contains__(self, k):
        return k in self.data

    def __len__(self):
        return len(self.t)


def truth_table(result, seed=0, noise=(0.003, 0.003, 0.01, 0.001, 0.003, 0.001)):
    """CoefficientTable from the truth with the logged commands as control regressors, plus white noise."""
    import numpy as np

    from gcs_sysid.aero.table import REGRESSORS, CoefficientTable

    rng = np.random.default_rng(seed)
    X = result.X.copy()
    for c, u in result.commands.items():
        X[:, REGRESSORS.index(c)] = u
    Y = result.Y + rng.normal(size=result.Y.shape) * np.asarray(noise)
    return CoefficientTable(result.t, X, Y, np.ones(len(result.t), bool), result.truth["qbar"], [])
