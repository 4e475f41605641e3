"""Speed of the 6-DOF simulation: real-time factor after jit, against a numpy baseline measured in the same run.

Run: ``python benchmarks/bench_sim.py``. Prints

- compile + first run of the shipped 4-minute sysid plan (``data/plans/sysid-trainer.toml``);
- the median of 3 further runs (new seeds, no recompiling) and the real-time factor
  (flight seconds per wall second; target: at least 200x), and the same per CPU second;
- ``propagate`` of 64 windows of 3 s at once (vmap), windows per second;
- the baseline: the same dynamics (RK4 at the same 200 Hz, model.evaluate in numpy) stepped
  in a plain Python loop for 5 s of flight, and the speed-up of the compiled loop over it.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from gcs_sysid.airframe import load_airframe
from gcs_sysid.jaxconfig import enable_x64
from gcs_sysid.sim import load_model, load_plan, propagate, simulate, state_from_measurements
from gcs_sysid.sim.environment import isa

ROOT = Path(__file__).resolve().parents[1]


def numpy_baseline(af, model, seconds: float, rate: float = 200.0) -> float:
    """Wall time of a plain numpy RK4 (Euler-angle 6-DOF) over ``seconds`` of flight."""
    J, Jinv = af.inertia, np.linalg.inv(af.inertia)
    d = np.array([0.0, 0.0, 0.0, 0.57])

    def f(s):
        u, v, w, phi, the, psi, p, q, r = s[3:12]
        cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(the), np.sin(the), np.cos(psi), np.sin(psi)
        C = np.array([[ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
                      [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp], [-st, sf * ct, cf * ct]])
        V = np.sqrt(u * u + v * v + w * w)
        X = np.array([np.arctan2(w, u), np.arcsin(v / V), p * af.b / (2 * V), q * af.c / (2 * V), r * af.b / (2 * V),
                      *d, V])
        Y = model.evaluate(X[None])[0]
        qS = 0.5 * isa(-s[2])[2] * V * V * af.S
        F = qS * Y[:3] + np.array([af.thrust.thrust(d[3], V), 0, 0])
        M = qS * np.array([af.b * Y[3], af.c * Y[4], af.b * Y[5]])
        om = s[9:12]
        vdot = F / af.mass + 9.80665 * np.array([-st, sf * ct, cf * ct]) - np.cross(om, s[3:6])
        eul = [p + st / ct * (q * sf + r * cf), q * cf - r * sf, (q * sf + r * cf) / ct]
        return np.concatenate([C @ s[3:6], vdot, eul, Jinv @ (M - np.cross(om, J @ om))])

    s = np.array([0, 0, -150, 20, 0, 0.5, 0, 0.025, 0, 0, 0, 0], float)
    h = 1.0 / rate
    t0 = time.perf_counter()
    for _ in range(int(seconds * rate)):
        k1 = f(s)
        k2 = f(s + 0.5 * h * k1)
        k3 = f(s + 0.5 * h * k2)
        k4 = f(s + h * k3)
        s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return time.perf_counter() - t0


def main() -> None:
    enable_x64()
    af = load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml")
    model = load_model(ROOT / "data" / "models" / "sim-trainer.toml")
    plan = load_plan(ROOT / "data" / "plans" / "sysid-trainer.toml")
    t0 = time.perf_counter()
    simulate(af, model, plan)
    first = time.perf_counter() - t0
    runs, cpu = [], []
    for seed in (1, 2, 3):
        t0, c0 = time.perf_counter(), time.process_time()
        simulate(af, model, plan, seed=seed)
        runs.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    warm, warm_cpu = float(np.median(runs)), float(np.median(cpu))
    print(f"plan: {plan.name}, {plan.duration:.0f} s of flight, {plan.rate_hz:.0f} Hz out, "
          f"{plan.internal_rate_hz:.0f} Hz RK4")
    print(f"simulate, compile + first run: {first:.2f} s")
    print(f"simulate, after jit (median of 3): {warm:.3f} s  ->  {plan.duration / warm:.0f}x real time "
          f"(target >= 200x): {'PASS' if plan.duration / warm >= 200 else 'FAIL'}")
    print(f"simulate, process CPU time (median of 3): {warm_cpu:.3f} s  ->  {plan.duration / warm_cpu:.0f}x real time "
          f"per CPU second (wall time suffers when other jobs share the cores)")
    n, T = 64, 150
    t = np.arange(T) * 0.02
    x0 = np.tile(state_from_measurements(0, 0.025, 0, 0, 0, 0, 150.0, V=20.0, alpha=0.025, beta=0.0), (n, 1))
    U = np.tile([0.0116, 0.0, 0.0, 0.575], (n, T, 1))
    U[:, 20:40, 0] += np.linspace(-0.03, 0.03, n)[:, None]
    propagate(af, model, x0, t, U)
    t0 = time.perf_counter()
    propagate(af, model, x0, t, U)
    dt_p = time.perf_counter() - t0
    print(f"propagate, {n} windows of {T * 0.02:.0f} s (vmap): {dt_p:.3f} s  ->  {n * T * 0.02 / dt_p:.0f}x real time")
    base_s = 5.0
    base = numpy_baseline(af, model, base_s)
    print(f"baseline, numpy RK4 loop at 200 Hz: {base_s / base:.1f}x real time "
          f"(compiled simulate is {base / base_s * plan.duration / warm:.0f}x faster)")


if __name__ == "__main__":
    main()
