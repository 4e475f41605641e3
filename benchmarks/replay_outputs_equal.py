"""Whether two replay output folders hold the same outputs, byte for byte (a speed change must not move a number).

    python benchmarks/replay_outputs_equal.py OUT_A OUT_B

Compared: ``model.npz`` and ``result/result.npz`` array by array (``np.array_equal``, NaN equal to NaN, dtype and
shape too), ``result/result.json`` less its ``timings``, every embedded figure of ``report.html`` (the PNG data
URIs, in order), and every other file byte for byte. Each folder's own path (the summary's and the result's model
path) is replaced by ``OUT`` first, and ``.gcs-sysid-output`` (the writer's pid and time) is skipped; the log's and
the airframe's paths are written as given, so compare replays of the same paths. Prints ``ALL IDENTICAL`` and exits
0, or lists what differs and exits 1.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

_FIGURE = re.compile(rb"data:image/[a-z+]+;base64,[A-Za-z0-9+/=]+")


def _npz(a: Path, b: Path, rel: str, bad: list[str]) -> int:
    """Compare one .npz array by array; returns the number of arrays."""
    with np.load(a / rel, allow_pickle=False) as A, np.load(b / rel, allow_pickle=False) as B:
        if sorted(A.files) != sorted(B.files):
            bad.append(f"{rel}: different arrays")
            return 0
        for k in A.files:
            x, y = A[k], B[k]
            if x.dtype != y.dtype or x.shape != y.shape or not np.array_equal(x, y, equal_nan=x.dtype.kind in "fc"):
                bad.append(f"{rel}: {k} differs")
        return len(A.files)


def _without_timings(d):
    if isinstance(d, dict):
        return {k: _without_timings(v) for k, v in d.items() if k != "timings"}
    if isinstance(d, list):
        return [_without_timings(v) for v in d]
    return d


def compare(a: Path, b: Path) -> list[str]:
    """What differs between the output folders ``a`` and ``b`` (empty: the same outputs)."""
    bad: list[str] = []
    counts = {rel: _npz(a, b, rel, bad) for rel in ("model.npz", "result/result.npz") if (a / rel).exists()}
    files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    bad += ([f"{f}: only in {a}" for f in sorted(files_a - files_b)]
            + [f"{f}: only in {b}" for f in sorted(files_b - files_a)])
    for f in sorted(files_a & files_b):
        name = str(f)
        if name.endswith(".npz") or name == ".gcs-sysid-output":
            continue
        x = (a / f).read_bytes().replace(str(a.resolve()).encode(), b"OUT").replace(str(a).encode(), b"OUT")
        y = (b / f).read_bytes().replace(str(b.resolve()).encode(), b"OUT").replace(str(b).encode(), b"OUT")
        if name.endswith("result.json"):
            same = _without_timings(json.loads(x)) == _without_timings(json.loads(y))
        elif name.endswith("report.html"):      # the header lists the stages' timings: compare the figures
            fx, fy = _FIGURE.findall(x), _FIGURE.findall(y)
            same = fx == fy and len(fx) > 0
            print(f"report.html: {len(fx)} figures")
        else:
            same = x == y
        if not same:
            bad.append(f"{name} differs")
    print(", ".join(f"{rel} {n} arrays" for rel, n in counts.items()))
    return bad


def main() -> None:
    a, b = Path(sys.argv[1]), Path(sys.argv[2])
    bad = compare(a, b)
    print("ALL IDENTICAL" if not bad else "DIFFERENT:\n  " + "\n  ".join(bad))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
