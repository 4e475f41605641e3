"""Benchmark: ``diagnose`` of a 10-minute 50 Hz flight (target: under 60 s on 2 cores).

Simulates a 600-s sysid flight of the sample trainer with a hidden ``Cm:alpha`` error
(calm-morning turbulence W20 = 1.5 m/s, default sensor noise), writes the tlog, then times ``run_diagnose``
end to end and by stage, with bare pymavlink decoding of the same log as the baseline
measured in the same run. Usage: ``python benchmarks/bench_diagnose.py [--minutes 10] [--search]``.

The flight is simulated once and kept in ``benchmarks/out/diagnose-<minutes>min.tlog`` (``--fresh``
simulates it again). The diagnosis runs as ``gcs-sysid diagnose`` sets it up: 64-bit JAX, one BLAS
thread, JAX's persistent compilation cache (the first run on a machine compiles, later ones load;
``GCS_SYSID_JAX_CACHE=<new dir>`` times a cold run).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "diagnose"))


def bare_decode(path) -> tuple[float, int]:
    from pymavlink import mavutil

    t0 = time.perf_counter()
    m = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
    n = 0
    while m.recv_match() is not None:
        n += 1
    return time.perf_counter() - t0, n


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--search", action="store_true", help="also the wide-library and sparse searches (--search)")
    ap.add_argument("--fresh", action="store_true", help="simulate the flight again (else the cached one)")
    args = ap.parse_args()
    from diag_flights import AIRFRAME, MODEL, effects, plan_doc

    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.diagnose.run import run_diagnose
    from gcs_sysid.jaxconfig import enable_compilation_cache, enable_x64, limit_blas_threads
    from gcs_sysid.sim import load_model, plan_from_dict, simulate, write_tlog

    enable_x64()
    limit_blas_threads(1)          # as the CLI does before every command but replay and listen
    enable_compilation_cache()
    af, m = load_airframe(AIRFRAME), load_model(MODEL)
    log = ROOT / "benchmarks" / "out" / f"diagnose-{args.minutes:g}min.tlog"
    t0 = time.perf_counter()
    if args.fresh or not log.exists():
        r = simulate(af, m, plan_from_dict(plan_doc(duration=60.0 * args.minutes, seed=3, turbulence=1.5)),
                     effects=effects("Cm:alpha", 0.3))
        log.parent.mkdir(parents=True, exist_ok=True)
        write_tlog(r, log, af)
    t_sim = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:
        t_dec, n_msg = bare_decode(log)
        t0 = time.perf_counter()
        d = run_diagnose(log, AIRFRAME, MODEL, Path(tmp) / "out", search=args.search)
        t_diag = time.perf_counter() - t0
    print(f"flight: {args.minutes:g} min at 50 Hz, {log.name}, {n_msg} MAVLink messages "
          f"(simulated and written or found in {t_sim:.1f} s)")
    print(f"bare pymavlink decode: {t_dec:.2f} s")
    print(f"diagnose end to end:   {t_diag:.2f} s  ({t_diag / t_dec:.1f}x bare decode; target < 60 s: "
          f"{'met' if t_diag < 60 else 'NOT met'})")
    for k, v in d.data["timings"].items():
        print(f"  {k:18s} {v:7.2f} s")
    print("findings:", [(f["cause"], round(f["estimate"], 3), round(f["gain"]["percent"])) for f in d.findings])


if __name__ == "__main__":
    main()
