"""Evaluation on real third-party logs (not part of the test suite: their licences keep them out of data/).

Runs ``gcs-sysid replay`` on every log in ``../shared/data`` (ALFA Carbon-Z T-28 flights, the
ArduPilot QuadPlane SITL telemetry log, the ArduPlane SITL DataFlash log), writes each report under
``benchmarks/out/real/``, and prints per flight: stream rates, what was identified or not (and why),
held-out errors, and physical plausibility checks of the measured coefficients for a 2 m trainer
(trim lift coefficient, lift-curve slope, pitch stiffness and damping signs from a least-squares
fit of the measured coefficients).

    python benchmarks/eval_real_logs.py [--shared ../shared/data] [--only alfa]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from gcs_sysid.errors import SysidError  # noqa: E402
from gcs_sysid.jaxconfig import enable_x64  # noqa: E402
from gcs_sysid.pipeline import ReplayOptions, run_replay  # noqa: E402

AIRFRAMES = {
    "alfa": REPO / "data/airframes/carbon-z-t28.toml",
    "vtol": REPO / "data/airframes/arduplane-sitl-vtol.toml",
    "arduplane": REPO / "data/airframes/arduplane-sitl-plane.toml",
}


def plausibility(result) -> list[str]:
    """Checks of the measured coefficients against what a 2 m trainer should show."""
    t = result.table
    v = t.valid & np.all(np.isfinite(t.X), axis=1) & np.all(np.isfinite(t.Y[:, :3]), axis=1)
    lines = []
    if v.sum() < 50:
        return ["too few valid samples for plausibility checks"]
    alpha, CZ, CX = t.x("alpha")[v], t.y("CZ")[v], t.y("CX")[v]
    CL = -CZ  # near level flight, small alpha
    lines.append(f"median CL (-CZ) {np.median(CL):.2f} (trainer cruise 0.2-0.8)")
    A = np.column_stack([np.ones(v.sum()), alpha])
    if np.std(alpha) > 0.01:
        coef, *_ = np.linalg.lstsq(A, CL, rcond=None)
        lines.append(f"CL_alpha {coef[1]:.2f} /rad from {np.degrees(np.std(alpha)):.1f} deg alpha spread "
                     f"(plausible 3.5-5.5 /rad)")
    else:
        lines.append(f"alpha spread {np.degrees(np.std(alpha)):.2f} deg: too little to fit CL_alpha")
    lines.append(f"median CX {np.median(CX):+.3f} "
                 f"({'includes thrust' if any('includes thrust' in n for n in t.notes) else 'thrust removed'})")
    if result.identifiable.get("Cm", (False, ""))[0]:
        Cm = t.y("Cm")[v]
        M = np.column_stack([np.ones(v.sum()), alpha, t.x("q_hat")[v], t.x("delta_e")[v]])
        ok = np.all(np.isfinite(M), axis=1) & np.isfinite(Cm)
        c, *_ = np.linalg.lstsq(M[ok], Cm[ok], rcond=None)
        lines.append(f"Cm_alpha {c[1]:+.2f}, Cm_q {c[2]:+.1f}, Cm_delta_e {c[3]:+.2f} (expected <0, <0, <0)")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--shared", default=str(REPO.parent / "shared" / "data"))
    ap.add_argument("--only", default=None, help="substring of the log paths to run")
    a = ap.parse_args()
    enable_x64()
    shared = Path(a.shared)
    logs = sorted(shared.glob("alfa/*.tlog")) + sorted(shared.glob("ardupilot/*"))
    if a.only:
        logs = [p for p in logs if a.only in str(p)]
    for log in logs:
        key = "alfa" if "alfa" in str(log) else ("vtol" if "vtol" in log.name else "arduplane")
        out = REPO / "benchmarks/out/real" / log.stem
        print(f"\n=== {log.relative_to(shared)}  (airframe {AIRFRAMES[key].name})")
        t0 = time.perf_counter()
        try:
            r = run_replay(log, AIRFRAMES[key], out, ReplayOptions(progress=False))
        except SysidError as e:
            print(f"  error: {e}")
            continue
        rates = {k: round(s.rate_hz, 1) for k, s in r.summaries.items()
                 if k in ("imu", "attitude", "servo", "airspeed", "gps")}
        print(f"  {time.perf_counter() - t0:.1f} s; stream rates (Hz): {rates}; valid rows {int(r.table.valid.sum())}")
        for c, (ok, why) in r.identifiable.items():
            m = r.metrics[c]
            print(f"  {c:3s} "
                  + (f"held-out error {m['error_pct_heldout']:6.1f} %" if ok else f"not identified: {why}"))
        for line in plausibility(r):
            print("  " + line)
        for n in r.notes[:6]:
            print("  note: " + n)
        print(f"  report: {out / 'report.html'}")


if __name__ == "__main__":
    main()
