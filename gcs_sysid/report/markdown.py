"""summary.md: the report's text and tables in Markdown (no images)."""

from __future__ import annotations

from pathlib import Path

from ..result import ReplayResult
from . import tables
from .cards import cards_markdown, context_of, group_rows

__all__ = ["render_markdown"]


def _esc(v: str) -> str:
    return str(v).replace("|", "\\|").replace("\n", " ")


def _table(rows: list[dict[str, str]], empty: str = "none") -> str:
    if not rows:
        return f"_{empty}_\n"
    keys = list(rows[0])
    out = ["| " + " | ".join(keys) + " |", "|" + "|".join("---" for _ in keys) + "|"]
    out += ["| " + " | ".join(_esc(r[k]) for k in keys) + " |" for r in rows]
    return "\n".join(out) + "\n"


def render_markdown(r: ReplayResult, path: Path) -> Path:
    """Write summary.md for ``r`` to ``path``."""
    L = [f"# gcs-sysid replay: {Path(r.log_path).name}", "", "## Fly next", ""] + cards_markdown(r, level=2)
    L += ["## Summary", ""]
    L += [f"- **{k}**: {_esc(v)}" for k, v in tables.facts(r)]
    L += ["", "## What is missing / notes", ""]
    bad = [f"{c}: {why}" for c, (ok, why) in r.identifiable.items() if not ok]
    items = [f"- **not identifiable** - {b}" for b in bad] + [f"- **missing**: {m}" for m in r.missing]
    items += [f"- {n}" for n in r.notes]
    L += items or ["Nothing missing: all six coefficients identified."]
    L += ["", "## Data", "", _table(tables.stream_rows(r), "no streams decoded")]
    L += ["## Held-out error", "",
          f"Error = 100 RMS(model - measured) / RMS(measured) on the held-out segment; thesis floor "
          f"{tables.THESIS_FLOOR_PCT['forces']} % (forces), {tables.THESIS_FLOOR_PCT['moments']} % (moments).", "",
          _table(tables.error_rows(r))]
    L += ["## GP model", ""]
    L += [f"- {k}: {_esc(v)}" for k, v in tables.gp_rows(r)] or ["_no model fitted_"]
    ls = tables.lengthscale_rows(r)
    if ls:
        L += ["", _table(ls)]
    L += ["", "## Envelope confidence", "", _table(tables.score_rows(r), "no confidence map")]
    groups = group_rows(context_of(r))
    L += ["## Flagged regions, grouped by fix", "",
          _table(groups) if groups else _table(tables.region_rows(r), "no regions flagged")]
    L += ["## Maneuver suggestions", "", _table(tables.suggestion_rows(r), "no suggestions")]
    L += [f"{s.rank}. {_esc(s.reason)}" for s in r.suggestions]
    path.write_text("\n".join(L) + "\n", encoding="utf-8")
    return path
