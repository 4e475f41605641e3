"""Pieces the benchmark scripts share word for word: the ``--aircraft`` help of the harness's names and the
``--json`` records (one JSON line per result, appended; read back, plain or gzip-compressed, by :func:`read_lines`).

Moved here from ``eval_jsbsim.py``, ``eval_gp_jsbsim.py``, ``eval_gp_joint.py``, ``eval_live_jsbsim.py``,
``eval_accel_sigma.py``, ``alpha_stages.py``, ``rate_floor.py`` and ``beta_band.py`` (twenty-eighth session, a
refactoring: every script's output, records and ``--help`` are unchanged).
"""

from __future__ import annotations

import gzip
import json
from collections.abc import Iterable
from pathlib import Path

__all__ = ["AIRCRAFT_HELP", "append_jsonl", "read_lines"]

#: ``--aircraft`` help of the scripts that fly the harness's aircraft by name (``aircraft_argument``).
AIRCRAFT_HELP = ("harness names (c172x sgs pa28 j3cub c182 t37 t6 b747 f16 f4n rascal sgs126 asw20 iar80 "
                 "c684 ultrastick b737 c172p eternity us25e ka350 s23 dr1 navion fokker50) or JSBSim model names "
                 "(J3Cub, "
                 "T37, "
                 "t6texan2, B747, "
                 "f16_direct, "
                 "F4N_fcs, Rascal110_glide, asw20_glide, IAR80_glide, C684_glide, UltraStick120_glide, 737, "
                 "Eternity_glide, UltraStick25e_glide, KingAir350_glide, ShortS23_glide, Dr1_glide, "
                 "Navion_glide, Fokker50_glide); no aircraft is untouched now (docs/jsbsim.md); default %(default)s")


def append_jsonl(path: str | None, rows: Iterable[dict]) -> None:
    """Append each of ``rows`` to the file ``path`` as one JSON line (``json.dumps``, then a newline); nothing
    where ``path`` is None or empty (no ``--json`` given).

    Args:
        path: the ``--json`` file, created if missing.
        rows: JSON-serialisable records (dicts of numbers, strings, lists, dicts).

    Raises:
        OSError: the file cannot be opened for appending. TypeError: a record is not JSON-serialisable (the
            lines before it are written).
    """
    if not path:
        return
    with open(path, "a") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")


def read_lines(path: str | Path) -> list[str]:
    """The lines of a text file of records, gzip-decompressed where the name ends in ``.gz`` (the committed record
    sets, ``benchmarks/records/``).

    Args:
        path: a ``.jsonl`` file, or a ``.jsonl.gz`` one.

    Returns:
        its lines, without their line ends.

    Raises:
        OSError: the file cannot be read, or a ``.gz`` file is not gzip data (``gzip.BadGzipFile``).
        UnicodeDecodeError: the content is not UTF-8 text.
    """
    p = Path(path)
    if p.name.endswith(".gz"):
        with gzip.open(p, "rt", encoding="utf-8") as f:
            return f.read().splitlines()
    return p.read_text(encoding="utf-8").splitlines()
