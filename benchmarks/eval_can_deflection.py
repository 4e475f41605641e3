"""Measured deflection (DroneCAN actuator status) against commanded PWM on the lagging-servo flight.

Builds the flight of ``tests/estimation/test_measured_deflection.py`` (the project's simulation, 20 s,
every actuator a 0.04 s delay plus a 0.12 s first-order lag; the tlog has the commanded PWM, a ``.blf``
written by python-can's ``can.Logger`` the true surface positions as 50 Hz DroneCAN actuator Status on
the ground station's clock), estimates states and coefficients from PWM and from the merged CAN log,
fits an ordinary least-squares linear model to each coefficient table and prints: the RMS error of the
control regressors against the truth, the model's error at the true regressors against the true
coefficients (``100 RMS(err) / RMS(truth)``), and the control derivatives Cm_delta_e, Cl_delta_a,
Cn_delta_r (truth -0.9, -0.25, -0.06).

    python benchmarks/eval_can_deflection.py
"""

from __future__ import annotations

import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "estimation"))

import test_measured_deflection as T  # noqa: E402


class _Tmp:
    def mktemp(self, name):
        return Path(tempfile.mkdtemp(prefix=f"gcs-sysid-{name}-"))


def main() -> int:
    sim, tlog, can_log, af = T.flown.__wrapped__(_Tmp())
    flight = T.read_log(tlog)
    merged = T.merge_can_log(flight, tlog, can_log)
    print(merged.warnings[-1])
    print("source | RMS error delta_e delta_a delta_r (deg) | model error CX CY CZ Cl Cm Cn (%) | Cm_de Cl_da Cn_dr")
    for name, f, a in (("commanded PWM", flight, replace(af, can_actuators=())), ("measured (DroneCAN)", merged, af)):
        reg, model, W = T._evaluate(sim, T.estimate_states(f, a), af)
        print(f"{name} | {' '.join(f'{reg[c]:.3f}' for c in T.CONTROLS)} | {' '.join(f'{e:.1f}' for e in model)} | "
              f"{W[6, 4]:.3f} {W[7, 3]:.3f} {W[8, 5]:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
