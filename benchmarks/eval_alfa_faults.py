"""Evaluation (not a test): actuator and engine faults on all ALFA flights, blindfolded.

For every ``*.tlog`` in DIR (the ALFA Carbon-Z T-28 flights, ``../shared/data/alfa``; they stay
there, nothing is copied):

1. the ground truth: the vehicle time of the first ``PARAM_VALUE DISABLE_*`` with a non-zero value in
   the *unstripped* log (mapped from the capture clock to vehicle time through the nearest ATTITUDE
   message); the expected cause comes from the file name's label;
2. the log is rewritten without PARAM_VALUE and STATUSTEXT (:func:`gcs_sysid.diagnose.strip.strip_tlog`);
3. a model is fitted (``run_fit``) on the nearest fault-free flight in time (same day where there is
   one; for a fault-free flight, the nearest *other* fault-free flight);
4. ``run_diagnose`` runs on the stripped log; its fault findings (``kind = "fault"``) are checked:
   a fault flight passes with exactly one fault finding, of the right cause, with onset within
   ``--tol`` s (3) of the truth; a fault-free flight passes with no fault finding.

Prints a Markdown table (for docs/benchmarks.md) and a summary line. The other findings of the
diagnosis (aero and sensor causes) are listed too, as measured.

Usage: ``python benchmarks/eval_alfa_faults.py DIR [--airframe data/airframes/carbon-z-t28.toml] [--json out.json]``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXPECT = (("both_ailerons", "stuck:delta_a"), ("aileron", "stuck:delta_a"), ("elevator", "stuck:delta_e"),
          ("rudder", "stuck:delta_r"), ("engine", "thrust_loss"), ("no_failure", None))
#: the fault flight kept out of all tuning of the thresholds (FaultThresholds)
HELD_OUT = "carbonZ_2018-10-05-14-37-22_3_left_aileron_failure.tlog"


def expected(name: str) -> str | None:
    """Expected cause from an ALFA file name (None: no fault)."""
    for key, cause in EXPECT:
        if key in name:
            return cause
    raise SystemExit(f"{name}: no known fault label in the name")


def when(name: str) -> datetime:
    """Recording time from an ALFA file name (``carbonZ_YYYY-MM-DD-HH-MM-SS_...``)."""
    m = re.search(r"(\d{4})-(\d\d)-(\d\d)-(\d\d)-(\d\d)-(\d\d)", name)
    if not m:
        raise SystemExit(f"{name}: no date-time in the name")
    return datetime(*map(int, m.groups()))


def truth_onset(path: Path) -> tuple[float | None, str | None]:
    """(vehicle time s, parameter name) of the first non-zero PARAM_VALUE DISABLE_* in the unstripped log."""
    from pymavlink import mavutil

    m = mavutil.mavlink_connection(str(path), dialect="ardupilotmega", robust_parsing=True)
    last_att = None
    found = None
    while True:
        msg = m.recv_match()
        if msg is None:
            break
        kind = msg.get_type()
        if kind == "ATTITUDE":
            last_att = (msg._timestamp, msg.time_boot_ms / 1000.0)
            if found is not None:                   # nearest ATTITUDE after the parameter
                ts, pid, before = found
                after = last_att
                ref = min((x for x in (before, after) if x is not None), key=lambda x: abs(x[0] - ts))
                m.close()
                return ref[1] + (ts - ref[0]), pid
        elif kind == "PARAM_VALUE" and msg.param_id.startswith("DISABLE_") and msg.param_value != 0 and found is None:
            found = (msg._timestamp, msg.param_id, last_att)
    m.close()
    if found is not None and found[2] is not None:
        ts, pid, ref = found
        return ref[1] + (ts - ref[0]), pid
    return None, None


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", help="directory of the ALFA .tlog files")
    ap.add_argument("--airframe", default=str(ROOT / "data" / "airframes" / "carbon-z-t28.toml"))
    ap.add_argument("--tol", type=float, default=3.0, help="onset tolerance, s")
    ap.add_argument("--json", default=None, help="also write the rows as JSON here")
    args = ap.parse_args()
    from gcs_sysid.diagnose.run import run_diagnose, run_fit
    from gcs_sysid.diagnose.strip import strip_tlog
    from gcs_sysid.errors import SysidError

    logs = sorted(Path(args.dir).glob("*.tlog"))
    if not logs:
        print(f"no .tlog in {args.dir}", file=sys.stderr)
        return 2
    clean = [p for p in logs if expected(p.name) is None]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        models: dict[Path, Path] = {}
        for log in logs:
            t_start = time.perf_counter()
            exp = expected(log.name)
            refs = [p for p in clean if p != log]
            ref = min(refs, key=lambda p: abs((when(p.name) - when(log.name)).total_seconds()))
            row = {"flight": log.name, "expected": exp, "reference": ref.name, "held_out": log.name == HELD_OUT}
            row["truth_onset_s"], row["truth_param"] = truth_onset(log)
            try:
                if ref not in models:
                    models[ref] = tmp / f"model-{ref.stem}.toml"
                    run_fit(ref, args.airframe, models[ref])
                stripped = tmp / f"stripped-{log.name}"
                row["stripped"] = strip_tlog(log, stripped)
                run_diagnose(stripped, args.airframe, models[ref], tmp / f"diag-{log.stem}")
                doc = json.loads((tmp / f"diag-{log.stem}" / "diagnosis.json").read_text())
            except SysidError as e:
                row.update(error=str(e), passed=False)
                rows.append(row)
                print(f"{log.name}: error: {e}", file=sys.stderr)
                continue
            faults = [f for f in doc["findings"] if f.get("kind") == "fault"]
            row["faults"] = [{"cause": f["cause"], "onset_s": f["onset_s"], "channels": f["evidence"].get("channels")}
                             for f in faults]
            row["other_findings"] = [f["cause"] for f in doc["findings"] if f.get("kind") != "fault"]
            row["diagnose_s"] = doc["data"]["timings"].get("total_s")
            if exp is None:
                row["passed"] = not faults
            else:
                ok = len(faults) == 1 and faults[0]["cause"] == exp and row["truth_onset_s"] is not None \
                    and abs(faults[0]["onset_s"] - row["truth_onset_s"]) <= args.tol
                row["onset_error_s"] = (faults[0]["onset_s"] - row["truth_onset_s"]) \
                    if faults and row["truth_onset_s"] is not None else None
                row["passed"] = bool(ok)
            row["wall_s"] = time.perf_counter() - t_start
            rows.append(row)
            print(f"{log.name}: {'PASS' if row['passed'] else 'FAIL'} {row['faults']}", file=sys.stderr)
    print("| flight | label (truth) | reference flight (fit) | fault findings (channel, onset s) | "
          "onset error (s) | other findings | result |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        name = r["flight"].replace("carbonZ_", "").replace(".tlog", "")
        truth = r["expected"] or "no failure"
        if r["truth_onset_s"] is not None:
            truth += f" at {r['truth_onset_s']:.2f} ({r['truth_param']})"
        if r.get("held_out"):
            name += " (held out)"
        found = "; ".join(f"{f['cause']} (ch {','.join(map(str, f['channels']))}, {f['onset_s']:.2f})"
                          for f in r.get("faults", [])) or ("error: " + r["error"] if "error" in r else "none")
        err = f"{r['onset_error_s']:+.2f}" if r.get("onset_error_s") is not None else ""
        print(f"| {name} | {truth} | {r['reference'].replace('carbonZ_', '').replace('.tlog', '')} | {found} | {err} | "
              f"{', '.join(r.get('other_findings', [])) or 'none'} | {'pass' if r['passed'] else 'FAIL'} |")
    nf = [r for r in rows if r["expected"]]
    nc = [r for r in rows if not r["expected"]]
    print(f"\nfault flights located: {sum(r['passed'] for r in nf)} / {len(nf)}; "
          f"fault-free flights without a fault finding: {sum(r['passed'] for r in nc)} / {len(nc)}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1, default=str))
    return 0 if all(r["passed"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
