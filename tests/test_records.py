"""benchmarks/records/: the committed baseline records add up to the totals their README states."""

import re
from pathlib import Path

import pytest

from benchmarks import issue8_counts as i8
from benchmarks import issue9_counts as i9

RECORDS = Path(__file__).resolve().parents[1] / "benchmarks" / "records"
README = (RECORDS / "README.md").read_text()


def test_every_record_file_is_described():
    shipped = {p.name for p in RECORDS.iterdir() if p.name != "README.md"}
    assert shipped, "benchmarks/records/ holds no records"
    assert shipped == set(re.findall(r"`([\w.-]+\.jsonl\.gz)`", README.split("**Provenance.**")[0]))


@pytest.mark.parametrize("name, label", [("issue9-roster.jsonl.gz", "issue 9"),
                                         ("issue9-seed3.jsonl.gz", "issue 9 seed 3")])
def test_issue9_totals_match_the_readme(name, label):
    t = i9.tally(i9.load([RECORDS / name]))
    tot = i9.effect_totals(t)
    got = {k: sum(v[k] for v in tot.values()) for k in ("n",) + i9.COUNTS}
    clean = [sum(v[i] for v in t["clean"].values()) for i in (0, 1)]
    m = re.search(re.escape(label) + r": top (\d+) of (\d+), estimate (\d+), gain (\d+), all three (\d+); clean "
                  r"flights with nothing named (\d+) of (\d+)", README)
    top, n, est, gain, all3, cn, cd = map(int, m.groups())
    assert (got["top"], got["n"], got["est"], got["gain"], got["all"]) == (top, n, est, gain, all3)
    assert clean == [cn, cd]


@pytest.mark.parametrize("seed", [0, 1])
def test_issue8_totals_match_the_readme(seed):
    runs = i8.load_runs([str(RECORDS / f"issue8-light-g{seed}.jsonl.gz")])
    assert set(runs) == {seed}
    total = i8.tally(runs[seed])["total"]
    line = re.search(rf"issue 8, GP seed {seed}: (.*)\.?\n", README).group(1)
    stated = {k: (int(a), int(b)) for k, a, b in re.findall(r"([\w<]+) (\d+)/(\d+)", line)}
    assert set(stated) == {"meas", "gp", "true_air", "gp<ls", "gp<fair"}
    assert {k: tuple(total[k]) for k in stated} == stated
    # the correlation line as written needs both pair fields on every line (since the sixty-ninth session)
    assert all("corr_pairs" in r and "truth_resid_corr" in r for r in runs[seed].values())
    stated_false = re.search(r"corr_false \(.*?\) (\d+)/75 and (\d+)/75", README.replace("\n  ", " "))
    assert tuple(total["corr_false"]) == (int(stated_false.group(1 + seed)), 75)
    # the held-out band per coefficient (a default count since the seventieth session) from the lines' cov_gp_each
    assert all(len(r["cov_gp_each"]) == 6 for r in runs[seed].values())
    stated_c = re.search(r"cov_gp_c \(.*?\) (\d+)/450 and (\d+)/450", README.replace("\n  ", " "))
    assert tuple(total["cov_gp_c"]) == (int(stated_c.group(1 + seed)), 450)
