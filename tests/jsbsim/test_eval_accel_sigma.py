"""benchmarks/eval_accel_sigma.py: its summary, and (slow) one flight's stated sigma against the truth."""

import json

import numpy as np
import pytest

from benchmarks import eval_accel_sigma

AXES = ("p_dot", "q_dot", "r_dot")


def _row(ac, seed, ratios):
    ax = {a: {"ratio": r, "err": 0.01, "noise": 0.005, "rest": 0.008, "st_noise": 0.005, "st_dist": 0.004,
              "above3": 0.5, "above8": 0.2} for a, r in zip(AXES, ratios)}
    return {"ac": ac, "turb": "light", "seed": seed, **ax}


def test_summary_counts_the_axes_within_range(tmp_path):
    p = tmp_path / "r.jsonl"
    p.write_text("\n".join(json.dumps(r) for r in (_row("f16", 1, (1.0, 0.5, 1.3)), _row("f16", 2, (0.9, 0.79, 1.25))))
                 + "\n")
    text = eval_accel_sigma.summarize(p)
    row = next(ln for ln in text.splitlines() if ln.startswith("| f16 | light"))
    cells = [c.strip() for c in row.split("|")]
    assert cells[3:6] == ["1.00/0.90", "0.50/0.79", "1.30/1.25"]
    assert cells[8] == "1.00 1.00 1.00" and cells[9] == "0.50 0.50 0.50"
    # 1.0, 0.9 and 1.25 lie within 0.8-1.25; 0.5, 0.79 and 1.3 do not
    assert "6 axis-flights: median ratio 0.95, within 0.8-1.25: 3, range 0.50-1.30" in text


@pytest.mark.slow
def test_one_flight_against_the_truth(fast_flight):
    work = fast_flight.tlog.parent
    ac, turb, seed = fast_flight.tlog.stem.split("-")[:3]
    cap = eval_accel_sigma._capture_rates()
    r = eval_accel_sigma.measure(work, ac, turb, int(seed[1:]), cap)
    for a in AXES:
        row = r[a]
        assert 0.1 < row["ratio"] < 10.0
        # the split of the true error recomposes it (FIR regression: orthogonal parts)
        assert row["noise"] ** 2 + row["rest"] ** 2 == pytest.approx(row["err"] ** 2, rel=0.15)
        assert np.isfinite(row["st_noise"]) and np.isfinite(row["st_dist"])
