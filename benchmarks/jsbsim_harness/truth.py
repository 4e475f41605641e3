"""Exact truth of a JSBSim flight: coefficients, regressors and states, saved apart from the log.

Definitions (``docs/conventions.md``; ``docs/jsbsim.md``): body axes, SI,
``CX CY CZ = F_aero / (qbar S)``, ``Cl Cn = M_aero / (qbar S b)``, ``Cm = M_aero / (qbar S c)``
with JSBSim's aerodynamic forces and moments about the CG and JSBSim's ``qbar = 0.5 rho V^2``
(V the true airspeed relative to the turbulent air); regressors ``alpha beta`` (JSBSim's, air
relative, turbulence included), ``p_hat = p b / (2V)`` etc. with the inertial body rates (what a
gyro measures; JSBSim's aerodynamics uses ``p-aero``, the rates relative to the air, also saved
as ``p_aero q_aero r_aero``), deflections in the project's signs, ``delta_t = 0`` (gliding).
The pipeline never reads these files.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS

from .flight import Recording

__all__ = ["truth_coefficients", "truth_regressors", "save_truth", "load_truth", "Truth"]


def truth_coefficients(rec: Recording, kind: str = "aero") -> np.ndarray:
    """True coefficients (T, 6) in :data:`COEFFICIENTS` order.

    Args:
        rec: the flight.
        kind: ``"aero"`` (JSBSim's aerodynamic forces and moments) or ``"total"`` (all non-gravity
            forces and moments: aero + propulsion + gear; equal to aero in a glide).
    """
    tr, c = rec.truth, rec.constants
    qS = tr["qbar"] * c["S"]
    F = [tr[f"F{a}_{kind}"] / qS for a in "xyz"]
    return np.stack([F[0], F[1], F[2], tr[f"L_{kind}"] / (qS * c["b"]), tr[f"M_{kind}"] / (qS * c["c"]),
                     tr[f"N_{kind}"] / (qS * c["b"])], 1)


def truth_regressors(rec: Recording) -> np.ndarray:
    """True regressors (T, 10) in :data:`REGRESSORS` order (SI, rad)."""
    tr, c = rec.truth, rec.constants
    V = tr["V"]
    return np.stack([tr["alpha"], tr["beta"], tr["p"] * c["b"] / (2 * V), tr["q"] * c["c"] / (2 * V),
                     tr["r"] * c["b"] / (2 * V), tr["delta_e"], tr["delta_a"], tr["delta_r"], tr["delta_t"], V], 1)


def save_truth(rec: Recording, path: str | Path) -> None:
    """Write the truth to a compressed ``.npz``: ``t``, ``X`` (T, 10), ``Y`` (T, 6), ``Y_total``,
    every truth field of the recording, and ``meta`` (JSON: constants, config, names)."""
    meta = dict(rec.meta, constants=rec.constants, regressors=list(REGRESSORS), coefficients=list(COEFFICIENTS))
    np.savez_compressed(path, meta=json.dumps(meta, default=str), t=rec.t, X=truth_regressors(rec),
                        Y=truth_coefficients(rec, "aero"), Y_total=truth_coefficients(rec, "total"), **rec.truth)


class Truth:
    """A saved truth file: ``t`` (T,), ``X`` (T, 10), ``Y`` (T, 6), ``fields`` dict, ``meta`` dict."""

    def __init__(self, path: str | Path):
        with np.load(path) as z:
            self.meta = json.loads(str(z["meta"]))
            self.t, self.X, self.Y = z["t"], z["X"], z["Y"]
            self.fields = {k: z[k] for k in z.files if k not in ("meta", "t", "X", "Y")}

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Truth regressors and coefficients linearly interpolated to times ``t`` (s), (N, 10), (N, 6);
        NaN outside the recorded span."""
        X = np.stack([np.interp(t, self.t, c, left=np.nan, right=np.nan) for c in self.X.T], 1)
        Y = np.stack([np.interp(t, self.t, c, left=np.nan, right=np.nan) for c in self.Y.T], 1)
        return X, Y


def load_truth(path: str | Path) -> Truth:
    """Read a truth file written by :func:`save_truth`."""
    return Truth(path)
