"""Fuzz: randomly damaged copies of the sample logs through ``replay`` and ``diagnose``.

Damage: truncation inside a record, bit flips, dropped packets, duplicated packets, and files spliced
from two logs at arbitrary bytes (one or two kinds per copy). Every run must end with exit 0 or 2,
no traceback and no internal error; every exit 0 must come with a report that states the damage,
whenever the damage is of a kind the tool can see (a flip inside the payload of a packet the tool
does not decode, or in the low bytes of a log stamp, is invisible to it, and is allowed to pass
silently; the fuzz computes which bytes are visible).

The commands run in-process (``gcs_sysid.cli.main``: the CLI's own code path, minus interpreter start
and signal handling, which ``tests/test_cli_robust.py`` covers with real subprocesses), without the
worker process, on short logs: the first 24 s of the sample flight and the first 52 s of the VTOL log.

``python -m pytest -m slow tests/test_fuzz_damage.py`` runs 200 copies (``GCS_SYSID_FUZZ_CASES``
changes the number); the default run takes a few seeded copies.
"""

import json
import os
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.cli import main
from gcs_sysid.telemetry.mavlink_streams import wanted_fields
from gcs_sysid.telemetry.tlog_scan import msgid_of

DATA = Path(__file__).resolve().parents[1] / "data"
BASES = {
    "sim": (DATA / "flights" / "sim-trainer-sysid.tlog", 0.10, DATA / "airframes" / "sim-trainer.toml"),
    "vtol": (DATA / "logs" / "ardupilot-quadplane-sitl-vtol.tlog", 0.25,
             DATA / "airframes" / "arduplane-sitl-vtol.toml"),
}
MODEL = DATA / "models" / "sim-trainer.toml"
#: Words of the damage notes (gcs_sysid.telemetry: Flight.damage) as the report shows them.
DAMAGE_WORDS = ("corrupt packet", "truncated", "missing from the MAVLink sequence", "out of sequence",
                "dropped duplicated", "time gaps", "reboot", "damaged log time stamp")
WANTED_IDS = {msgid_of(n) for n in wanted_fields()}


def _records(data: bytes) -> list[tuple[int, int, int, int]]:
    """(offset, end, msgid, src) of every record of an intact tlog."""
    out, pos = [], 0
    while pos + 16 <= len(data):
        if data[pos + 8] == 0xFE:
            end, mid, src = pos + 16 + data[pos + 9], data[pos + 13], (data[pos + 11] << 8) | data[pos + 12]
        else:
            end = pos + 20 + data[pos + 9] + (13 if data[pos + 10] & 1 else 0)
            mid = data[pos + 15] | (data[pos + 16] << 8) | (data[pos + 17] << 16)
            src = (data[pos + 13] << 8) | data[pos + 14]
        if end > len(data):
            break
        out.append((pos, end, mid, src))
        pos = end
    return out


class Base:
    """An intact short log (cut at a record boundary) and what the fuzz needs to know of its bytes."""

    def __init__(self, name: str):
        path, fraction, self.airframe = BASES[name]
        full = path.read_bytes()
        recs = _records(full[: int(fraction * len(full)) + 300])
        recs = [r for r in recs if r[1] <= int(fraction * len(full))]
        self.data = full[: recs[-1][1]]
        self.recs = recs
        self.starts = {r[0] for r in recs} | {len(self.data)}
        visible = np.zeros(len(self.data), bool)   # bytes whose damage the tool can see
        per_src: dict[int, list[int]] = {}
        for i, (a, e, mid, src) in enumerate(recs):
            visible[a:a + 5] = True                 # the stamp's high bytes (jumps beyond 16 s)
            seq_at = a + 10 if self.data[a + 8] == 0xFE else a + 12
            visible[[a + 8, a + 9, seq_at]] = True  # magic, length, sequence number
            if mid in WANTED_IDS:
                visible[a + 8:e] = True             # decoded packets: the CRC covers them
            per_src.setdefault(src, []).append(i)
        self.visible = visible
        # records whose loss shows as a gap in their sender's sequence numbers
        self.droppable = [i for idx in per_src.values() if len(idx) >= 3 for i in idx[1:-1]]


def damage(rng: np.random.Generator, base: Base, other: Base) -> tuple[bytes, list[str], bool]:
    """A damaged copy of ``base``: (bytes, kinds, whether the tool can see the damage)."""
    data, kinds, visible = bytearray(base.data), [], False
    picked = rng.choice(["truncate", "flip", "drop", "duplicate", "splice"], size=int(rng.integers(1, 3)),
                        replace=False)
    for kind in sorted(picked, key=lambda k: k == "truncate"):   # a truncation last: it keeps the rest
        kinds.append(str(kind))
        if kind == "flip":
            pos = rng.choice(len(data), size=int(rng.integers(1, 40)), replace=False)
            for p in pos:
                data[p] ^= 1 << int(rng.integers(0, 8))
            if len(data) == len(base.data):   # offsets still those of the base
                visible |= bool(base.visible[pos].any())
            else:
                visible = True
        elif kind in ("drop", "duplicate"):
            if len(data) != len(base.data):
                continue
            picks = sorted(rng.choice(base.droppable, size=int(rng.integers(1, 6)), replace=False), reverse=True)
            for i in picks:
                a, e = base.recs[i][:2]
                data[a:e] = b"" if kind == "drop" else data[a:e] * 2
            visible = True
        elif kind == "splice":
            a = int(rng.integers(len(data) // 4, 3 * len(data) // 4))
            b = int(rng.integers(0, len(other.data) // 2))
            data = data[:a] + bytearray(other.data[b:])
            visible = True
        elif kind == "truncate":
            if len(data) == len(base.data):
                cut = int(rng.integers(len(data) // 3, len(data) - 1))
                while cut in base.starts:
                    cut += 1   # inside a record: a cut on a boundary leaves an intact (shorter) log
            else:   # offsets moved: cut inside the last record (every record is longer than 15 bytes)
                cut = len(data) - int(rng.integers(1, 16))
            data = data[:cut]
            visible = True
    return bytes(data), kinds, visible


_bases: dict[str, Base] = {}


def _base(name: str) -> Base:
    if name not in _bases:
        _bases[name] = Base(name)
    return _bases[name]


def run_case(seed: int, tmp: Path, capsys) -> dict:
    """Damage a copy (seeded), run replay and diagnose on it, check the outcome; returns what happened."""
    rng = np.random.default_rng(seed)
    name = "sim" if seed % 2 == 0 else "vtol"
    base, other = _base(name), _base("vtol" if name == "sim" else "sim")
    data, kinds, visible = damage(rng, base, other if rng.random() < 0.5 else base)
    log = tmp / f"case{seed}.tlog"
    log.write_bytes(data)
    outcome = {"seed": seed, "base": name, "kinds": kinds, "visible": visible}
    commands = {
        "replay": ["replay", log, "--airframe", base.airframe, "--out", tmp / f"r{seed}", "--quiet",
                   "--inducing", "16", "--rate", "25"],
        "diagnose": ["diagnose", log, "--airframe", base.airframe, "--model", MODEL, "--out", tmp / f"d{seed}"],
    }
    for cmd, argv in commands.items():
        capsys.readouterr()
        try:
            rc = main([str(a) for a in argv], handle_signals=False)
        except SystemExit as e:   # argparse only; never for a damaged log
            rc = e.code
        out, err = capsys.readouterr()
        outcome[cmd] = rc
        where = f"seed {seed} ({name}, {'+'.join(kinds)}) {cmd}"
        assert rc in (0, 2), f"{where}: exit {rc}: {err.strip()}"
        assert "Traceback" not in err and "internal error" not in err, f"{where}: {err}"
        if rc == 2:
            assert len([ln for ln in err.splitlines() if ln.strip()]) == 1, f"{where}: {err}"
            continue
        if cmd == "replay":
            text = (tmp / f"r{seed}" / "summary.md").read_text()
            stated = any(w in text for w in DAMAGE_WORDS)
        else:
            doc = json.loads((tmp / f"d{seed}" / "diagnosis.json").read_text())
            stated = bool(doc["data"].get("log_damage"))
        if visible:
            assert stated, f"{where}: exit 0 but the report does not state the damage"
            assert "damaged log:" in out, f"{where}: the console does not state the damage"
    return outcome


@pytest.fixture()
def in_process(monkeypatch):
    monkeypatch.setenv("GCS_SYSID_PARALLEL", "0")


@pytest.mark.parametrize("seed", [1, 3, 5])
def test_damaged_copies(seed, tmp_path, capsys, in_process):
    run_case(seed, tmp_path, capsys)


@pytest.mark.slow
def test_fuzz_200_damaged_copies(tmp_path, capsys, in_process):
    n = int(os.environ.get("GCS_SYSID_FUZZ_CASES", "200"))
    results = []
    for seed in range(1000, 1000 + n):
        results.append(run_case(seed, tmp_path, capsys))
        with capsys.disabled():   # progress, one line per copy (seen with -s or in the terminal)
            r = results[-1]
            print(f"\nfuzz case {seed}: {r['base']} {'+'.join(r['kinds'])}: replay {r['replay']}, "
                  f"diagnose {r['diagnose']}", end="", flush=True)
        for p in tmp_path.iterdir():   # keep the disk use small
            if p.is_file():
                p.unlink()
    with capsys.disabled():
        codes = {c: {k: sum(r[c] == k for r in results) for k in (0, 2)} for c in ("replay", "diagnose")}
        print(f"\nfuzz: {n} damaged copies; exit codes {codes}; "
              f"{sum(r['visible'] for r in results)} with damage the tool can see")
