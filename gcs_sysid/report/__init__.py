"""Renderers of a :class:`~gcs_sysid.result.ReplayResult`: HTML, Markdown, CSV, JSON.

Results are data, reports are renderers (as pyinstrument's ``Session`` and its renderers): the
result can be saved (:func:`save_result`) and re-rendered later (:func:`load_result`) without
recomputing. Contents and file formats: ``docs/report.md``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..result import ReplayResult
from .cards import render_testcards_html, render_testcards_md, write_flynext_plan
from .html import render_html
from .markdown import render_markdown
from .store import load_result, save_result
from .tables import CSV_COLUMNS, write_csv, write_suggestions_json

__all__ = ["write_report", "save_result", "load_result", "CSV_COLUMNS"]


def write_report(result: ReplayResult, out_dir: str | Path, save: bool = True,
                 figures: dict | None = None, csv: Any = None) -> dict[str, Path]:
    """Write the report files into ``out_dir`` (created).

    Args:
        result: the replay result.
        out_dir: output directory.
        save: also save the result itself (``out_dir/result/result.{json,npz}``) for re-rendering.
        figures: figures drawn elsewhere, or jobs drawing them (see :func:`~gcs_sysid.report.html.render_html`).
        csv: None, or a job writing ``out_dir/coefficients.csv`` (its ``result()`` gives the path:
            :func:`~gcs_sysid.report.tables.write_csv_data`, which the pipeline runs here, from the measured
            fields its worker formatted); collected before the HTML.

    Returns:
        name -> path for ``report.html``, ``summary.md``, ``coefficients.csv``, ``suggestions.json``,
        ``testcards.md``, ``testcards.html`` and, when there are suggestions, ``flynext_plan.toml``
        (keys ``html``, ``markdown``, ``csv``, ``suggestions``, ``testcards_md``, ``testcards_html``,
        ``plan``) and, with ``save``, ``result_json`` and ``result_npz``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files = {
        "csv": write_csv(result, out / "coefficients.csv") if csv is None else None,
        "suggestions": write_suggestions_json(result, out / "suggestions.json"),
        "markdown": render_markdown(result, out / "summary.md"),
        "testcards_md": render_testcards_md(result, out / "testcards.md"),
        "testcards_html": render_testcards_html(result, out / "testcards.html"),
    }
    plan = write_flynext_plan(result, out / "flynext_plan.toml")
    if plan is not None:
        files["plan"] = plan
    if save:
        files.update(save_result(result, out / "result"))
    if csv is not None:
        files["csv"] = Path(csv.result())
    files["html"] = render_html(result, out / "report.html", figures)   # last: figures may still be drawing
    return files
