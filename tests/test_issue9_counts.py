"""benchmarks/issue9_counts.py: issue 9's roster counts on small hand-made ``eval_jsbsim_diagnose`` records."""

import json

import pytest

from benchmarks import issue9_counts as ic


def _case(ac="sgs", seed=1, effect="Cn:delta_a", value=-0.06, top=True, est=True, gain=True, named=None):
    rows = [{"cause": effect, "value": value, "found": top or est or gain, "top": top, "est": est, "gain": gain}]
    return {"aircraft": ac, "seed": seed, "effects": [[effect, value]],
            "score": {"ok": top and est and gain, "effects": rows, "named": named or ([effect] if top else [])}}


def _clean(ac="sgs", seed=11, named=()):
    return {"aircraft": ac, "seed": seed, "effects": [], "score": {"ok": not named, "named": list(named)}}


def _write(path, recs):
    path.write_text("".join(json.dumps(r) + "\n" for r in recs))
    return str(path)


def test_cells_clean_flights_and_envelope_exits(tmp_path):
    recs = [_case(), _case(value=-0.03, est=False), _case(effect="CY:scale", value=1.6, top=False, named=["CY:beta"]),
            _clean(), _clean(seed=12, named=["CZ:alpha_dot_hat"]),
            {"aircraft": "sgs", "seed": 1, "effects": [["Cm:alpha^2", -8.0]],
             "score": {"ok": False, "error": "left the envelope"}}]
    t = ic.tally(ic.load([_write(tmp_path / "r.jsonl", recs)]))
    assert t["cells"][("sgs", "Cn:delta_a")] == {"n": 2, "top": 2, "est": 1, "gain": 2, "all": 1}
    assert t["cells"][("sgs", "CY:scale")] == {"n": 1, "top": 0, "est": 1, "gain": 1, "all": 0}
    assert t["cells"][("sgs", "Cm:alpha^2")] == {"n": 1, "top": 0, "est": 0, "gain": 0, "all": 0}   # a miss
    assert t["clean"]["sgs"] == [1, 2] and t["named_clean"]["sgs"] == [(12, ["CZ:alpha_dot_hat"])]
    tot = ic.effect_totals(t)
    assert tot["Cn:delta_a"]["top"] == 2 and tot["bias:airspeed"]["n"] == 0
    table = ic.roster_table(t)
    assert "| gliders | sgs | 0/0/0/0 of 1 | - | 2/1/2/1 of 2 | 0/1/1/0 of 1 | - | - | 1/2 | 2/4 | 1/4 |" in table
    assert "| all | 4 | 2 (50 %) | 2 (50 %) | 3 (75 %) | 1 (25 %) | 1/2 |" in ic.totals_table(t)


def test_a_later_file_overrides_an_earlier_case_and_pairs_count_apart(tmp_path):
    first = _write(tmp_path / "a.jsonl", [_case(top=False, est=False, gain=False, named=[]), _clean()])
    again = _write(tmp_path / "b.jsonl", [_case()])
    pair = {"aircraft": "sgs", "seed": 1, "effects": [["Cm:alpha^2", -4.0], ["Cn:delta_a", -0.03]],
            "score": {"ok": False, "effects": [{"found": True}, {"found": False}]}}
    t = ic.tally(ic.load([first, again, _write(tmp_path / "p.jsonl", [pair])]))
    assert t["cells"][("sgs", "Cn:delta_a")]["top"] == 1 and t["cells"][("sgs", "Cn:delta_a")]["n"] == 1
    assert t["clean"]["sgs"] == [1, 1] and t["pairs"] == [0, 1]
    t = ic.tally(ic.load([again, first]))                       # the other order: the miss wins
    assert t["cells"][("sgs", "Cn:delta_a")]["top"] == 0


def test_binomial_band_and_the_reading(tmp_path):
    d, band = ic.binomial_band(30, 50, 90, 150)
    assert d == pytest.approx(0.0) and band == pytest.approx(200 * (0.6 * 0.4 * (1 / 50 + 1 / 150)) ** 0.5)
    with pytest.raises(ValueError, match="both samples need cases"):
        ic.binomial_band(1, 0, 1, 2)
    new = ic.tally(ic.load([_write(tmp_path / "n.jsonl", [_case(seed=s) for s in range(1, 11)])]))
    old = ic.tally(ic.load([_write(tmp_path / "o.jsonl", [_case(seed=s, top=s > 8) for s in range(1, 11)])]))
    assert "| `Cn:delta_a` | 10 (100 %) | 2 (20 %) | +80 |" in ic.against_table(new, old)
    assert "higher" in ic.against_table(new, old) and "within draw scatter" in ic.against_table(new, new)


def test_cli_prints_the_tables_and_names_a_bad_line(tmp_path, capsys):
    good = _write(tmp_path / "r.jsonl", [_case(), _clean(named=["CY:beta"])])
    assert ic.main([good, "--against", good]) == 0
    out = capsys.readouterr().out
    assert "| gliders | sgs |" in out and "Clean flights that named a cause: sgs s11: CY:beta." in out
    assert "within draw scatter" in out
    bad = tmp_path / "bad.jsonl"
    bad.write_text(json.dumps(_case()) + "\n{\"aircraft\": \"sgs\"}\n")
    assert ic.main([str(bad)]) == 2
    assert f"{bad}:2: not an eval_jsbsim_diagnose record" in capsys.readouterr().err


def test_flips_pair_cases_flown_alike_and_read_gzip(tmp_path):
    import gzip

    flown = {"plan": "sweep", "sensor_draw": "per_aircraft", "turbulence_draw": "per_aircraft"}
    base = [dict(_case(seed=1), **flown), dict(_case(seed=2, top=False, est=False, gain=False, named=[]), **flown),
            dict(_clean(seed=11, named=["CX:beta"]), **flown), dict(_clean(seed=12), **flown),
            dict(_case(seed=3), plan="standard")]
    new = [dict(_case(seed=1, gain=False), **flown), dict(_case(seed=2), **flown),
           dict(_clean(seed=11), **flown), dict(_clean(seed=12, named=["scale:CY"]), **flown),
           dict(_case(seed=3), **flown)]                      # seed 3 flown with another plan: not paired
    gz = tmp_path / "base.jsonl.gz"
    with gzip.open(gz, "wt") as f:
        f.write("".join(json.dumps(r) + "\n" for r in base))
    f = ic.flips(ic.load([_write(tmp_path / "new.jsonl", new)]), ic.load([str(gz)]))
    assert f["paired"] == 4 and f["unpaired"] == 1
    c = f["counts"]
    assert c["top"] == {"wins": ["sgs s2 Cn:delta_a=-0.06"], "losses": []}
    assert c["gain"] == {"wins": ["sgs s2 Cn:delta_a=-0.06"], "losses": ["sgs s1 Cn:delta_a=-0.06"]}
    assert c["all"]["losses"] == ["sgs s1 Cn:delta_a=-0.06"] and c["all"]["wins"] == ["sgs s2 Cn:delta_a=-0.06"]
    assert c["clean"] == {"wins": ["sgs s11 clean"], "losses": ["sgs s12 clean"]}
    table = ic.flips_table(f)
    assert "Paired case by case: 4 cases (1 unpaired)." in table and "| top | 1 | 0 | +1 |" in table
    assert "- clean loss: sgs s12 clean" in table


def test_a_bad_gzip_file_is_named(tmp_path, capsys):
    bad = tmp_path / "r.jsonl.gz"
    bad.write_text("not gzip\n")
    assert ic.main([str(bad)]) == 2
    assert "issue9_counts:" in capsys.readouterr().err
