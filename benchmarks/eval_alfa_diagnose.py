"""Evaluation (not a test): diagnose the ALFA Carbon-Z T-28 flights with labelled faults.

For each ``*failure*.tlog`` in ``/work/shared/data/alfa`` (or the directory given), a model is
fitted by ``run_fit`` on the part of the flight before the labelled fault is likely (the first
half, or the matching ``no_failure`` flight when given with ``--reference``), then ``run_diagnose``
holds that model against the whole flight. Prints what diagnose names (expected: ``stuck:delta_e``
for an elevator failure, ``stuck:delta_r`` for a rudder failure, ``stuck:delta_a`` for an aileron
failure; an engine failure is outside the catalogue and should come out as ``unexplained`` in CX)
and what it could not tell. The ALFA logs stream servos and attitude at about 3 Hz, so delays
and fast dynamics are not identifiable; the script says so rather than pretending.

Usage: ``python benchmarks/eval_alfa_diagnose.py [DIR] [--airframe data/airframes/carbon-z-t28.toml]``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXPECT = {"elevator": "stuck:delta_e", "rudder": "stuck:delta_r", "aileron": "stuck:delta_a", "engine": None}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("dir", nargs="?", default="/work/shared/data/alfa")
    ap.add_argument("--airframe", default=str(ROOT / "data" / "airframes" / "carbon-z-t28.toml"))
    args = ap.parse_args()
    from gcs_sysid.diagnose.run import load_measurements, run_diagnose, run_fit
    from gcs_sysid.errors import SysidError

    logs = sorted(Path(args.dir).glob("*failure*.tlog"))
    logs = [p for p in logs if "no_failure" not in p.name]
    if not logs:
        print(f"no *failure*.tlog in {args.dir}")
        return
    for log in logs:
        kind = next((k for k in EXPECT if k in log.name), None)
        print(f"== {log.name} (expected: {EXPECT.get(kind) or 'outside the catalogue: unexplained'})")
        t0 = time.perf_counter()
        try:
            meas = load_measurements(log, args.airframe)
            marks = [(t, txt) for t, txt in meas.flight.statustext
                     if any(w in txt.lower() for w in ("fail", "fault", "emerg", "engine", "stuck"))]
            print("   log messages naming a failure: " + ("; ".join(f"{t:.1f} s '{txt}'" for t, txt in marks[:5])
                                                       if marks else "none (no labelled fault time in the tlog)"))
            tv = meas.table.t[meas.table.valid]
            if len(tv) < 100:
                print(f"   only {len(tv)} valid rows: cannot diagnose")
                continue
            t_mid = float(tv[0] + 0.5 * (tv[-1] - tv[0]))
            with tempfile.TemporaryDirectory() as tmp:
                model_path = Path(tmp) / "fitted.toml"
                run_fit(log, args.airframe, model_path, t_to=t_mid)
                d = run_diagnose(log, args.airframe, model_path, Path(tmp) / "diag", min_rows=100)
                doc = json.loads((Path(tmp) / "diag" / "diagnosis.json").read_text())
        except SysidError as e:
            print(f"   error: {e}")
            continue
        print(f"   valid rows {doc['data']['n_valid']} over {doc['data']['t_range_s'][0]:.0f}-"
              f"{doc['data']['t_range_s'][1]:.0f} s at {doc['data']['rate_hz']:.0f} Hz; turbulence projection "
              f"{'on' if doc['data'].get('turbulence', {}).get('active') else 'off'}")
        for f in doc["findings"]:
            print(f"   finding {f['cause']:16s} estimate {f['estimate']:.4g} +- {f['std_error']:.2g} "
                  f"gain {f['gain'].get('percent', 0):.0f} % onset {f.get('onset_s', '')}")
        for u in doc["unexplained"]:
            if u["above_threshold"]:
                print(f"   unexplained {u['coefficient']}: rms {u['rms']:.3g}, "
                      f"structured {u['structured_percent']:.0f} %, "
                      f"worst time {u['where']['time_s']}")
        for s in doc["data"].get("notes", []):
            if "left out" in s or "not identifiable" in s:
                print(f"   note: {s}")
        for s in doc["data"].get("separation", []):
            print(f"   note: {s}")
        print(f"   ({time.perf_counter() - t0:.1f} s; fitted on t < {t_mid:.0f} s)")


if __name__ == "__main__":
    main()
