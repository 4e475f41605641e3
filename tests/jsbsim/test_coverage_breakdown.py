"""benchmarks/coverage_breakdown.py: the coverage criterion per coefficient, from eval_jsbsim's JSON lines."""

import json

import pytest

from benchmarks import coverage_breakdown as cb

COEFFS = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")


def _row(turb, each, err, sigma):
    terms = {"latent": [0.1] * 6, "input": [0.2] * 6, "coloured": sigma, "sigma": sigma}
    return {"aircraft": "f4n", "turbulence": turb, "seed": 1, "cov_gp": sum(each) / 6, "cov_gp_each": each,
            "gp": dict(zip(COEFFS, err)), "band_terms": {"gp": terms}}


def test_flags_name_the_coefficients_outside_the_range_and_their_band(tmp_path, capsys):
    p = tmp_path / "r.jsonl"
    light = _row("light", [99.0, 95.0, 57.0, 90.0, 70.0, 100.0], [1.4, 3.5, 3.7, 3.3, 12.7, 3.3],
                 [1.8, 3.6, 0.9, 2.8, 6.5, 11.6])
    p.write_text(json.dumps(light) + "\n" + json.dumps(_row("moderate", [95.0] * 6, [1.0] * 6, [1.0] * 6)) + "\n")
    rows = cb.rows_of([str(p)], "light")
    assert len(rows) == 1
    b = {x["coef"]: x for x in cb.breakdown(rows[0])}
    assert b["CZ"]["cov"] == 57.0 and b["CZ"]["err"] == 3.7 and b["CZ"]["sigma"] == 0.9
    assert b["Cn"]["largest"] == "coloured"
    cb.main([str(p), "--turbulence", "light", "--flags"])
    out = capsys.readouterr().out
    for c in ("CX 99%", "CZ 57%", "Cm 70%", "Cn 100%"):
        assert c in out
    assert "CY 95%" not in out and "Cl 90%" not in out       # inside 90-98 %: not flagged


def test_missing_file_and_old_rows_say_what_is_wrong(tmp_path):
    with pytest.raises(SystemExit, match="no such file"):
        cb.rows_of([str(tmp_path / "none.jsonl")], None)
    p = tmp_path / "old.jsonl"
    p.write_text(json.dumps({"aircraft": "c172x", "turbulence": "light"}) + "\n")
    with pytest.raises(SystemExit, match="cov_gp_each"):
        cb.rows_of([str(p)], None)
