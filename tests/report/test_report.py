"""Report files: existence, CSV columns, self-contained HTML with every section, valid JSON, re-render."""

import csv
import html
import json
import re

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.errors import InputError
from gcs_sysid.report import CSV_COLUMNS, load_result, write_report
from gcs_sysid.report.html import SECTIONS


@pytest.fixture(scope="module")
def written(replay_result, tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    return replay_result, write_report(replay_result, out)


def test_files_exist(written):
    _, files = written
    for key in ("html", "markdown", "csv", "suggestions", "result_json", "result_npz"):
        assert files[key].is_file() and files[key].stat().st_size > 0, key
    assert files["html"].name == "report.html" and files["markdown"].name == "summary.md"


def test_csv_columns_and_values(written):
    r, files = written
    with open(files["csv"]) as f:
        rows = list(csv.reader(f))
    expected = ["time_s", *REGRESSORS, *COEFFICIENTS, *(c + "_pred" for c in COEFFICIENTS),
                *(c + "_sigma" for c in COEFFICIENTS), *(c + "_sigma_obs" for c in COEFFICIENTS), "held_out"]
    assert rows[0] == expected == list(CSV_COLUMNS)
    assert len(rows) == len(r.table.t) + 1
    data = np.array([[float(v) for v in row] for row in rows[1:]])
    np.testing.assert_allclose(data[:, 0], r.table.t, atol=1e-4)
    np.testing.assert_allclose(data[:, 1 + REGRESSORS.index("V")], r.table.x("V"), rtol=1e-6)
    np.testing.assert_allclose(data[:, expected.index("Cm_pred")], r.pred_mean[:, 4], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(data[:, expected.index("Cm_sigma")], r.pred_sigma[:, 4], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(data[:, expected.index("Cm_sigma_obs")], r.pred_sigma_obs[:, 4], rtol=1e-6,
                               atol=1e-12)
    assert set(np.unique(data[:, -1])) == {0.0, 1.0}
    assert data[:, -1].sum() == r.held_out.sum()


def test_html_self_contained_with_sections(written):
    r, files = written
    page = files["html"].read_text()
    assert "http://" not in page and "https://" not in page
    srcs = re.findall(r'src="([^"]*)"', page)
    assert srcs and all(s.startswith("data:image/png;base64,") for s in srcs)
    assert "<link" not in page and "<script" not in page
    for anchor, title in SECTIONS:
        assert f'id="{anchor}"' in page and title in page
    for c in COEFFICIENTS:
        assert f"<td>{c}</td>" in page
    assert "19.8" in page and "23.8" in page
    # one envelope figure per slice, suggestion waveform plot
    assert page.count('alt="') >= 5 + len(r.envelope.slices)
    assert html.escape(r.suggestions[0].reason) in page


def test_suggestions_json(written):
    r, files = written
    doc = json.loads(files["suggestions"].read_text())
    assert [s["rank"] for s in doc["suggestions"]] == list(range(1, len(r.suggestions) + 1))
    s0 = doc["suggestions"][0]
    for key in ("coefficients", "kind", "controls", "amplitude_rad", "amplitude_deg", "pulse_width_s", "duration_s",
                "flight_condition", "expected_reduction", "reason", "waveform", "region"):
        assert key in s0
    assert len(s0["waveform"]["t"]) == len(s0["waveform"][s0["controls"][0]])
    assert doc["regions"] and {"coefficient", "axes", "bounds", "center", "mean_rel_sigma", "n_points",
                               "reason"} <= set(doc["regions"][0])
    assert set(doc["scores"]) == set(COEFFICIENTS)


def test_markdown(written):
    _, files = written
    md = files["markdown"].read_text()
    for h in ("## Summary", "## What is missing / notes", "## Held-out error", "## Flagged regions",
              "## Maneuver suggestions"):
        assert h in md
    assert "| coefficient | held-out error (%)" in md


def test_save_load_rerender(partial_result, tmp_path):
    files = write_report(partial_result, tmp_path / "first")
    back = load_result(tmp_path / "first" / "result")
    np.testing.assert_array_equal(back.table.X, partial_result.table.X)
    np.testing.assert_array_equal(back.pred_sigma, partial_result.pred_sigma)
    np.testing.assert_array_equal(back.pred_sigma_obs, partial_result.pred_sigma_obs)
    np.testing.assert_array_equal(back.held_out, partial_result.held_out)
    assert back.states.data.keys() == partial_result.states.data.keys()
    assert [s.reason for s in back.suggestions] == [s.reason for s in partial_result.suggestions]
    assert back.envelope.scores == pytest.approx(partial_result.envelope.scores)
    assert back.summaries["servo"].gaps == partial_result.summaries["servo"].gaps
    again = write_report(back, tmp_path / "again", save=False)
    assert "result_json" not in again
    for key in ("markdown", "csv", "suggestions"):
        assert again[key].read_text() == files[key].read_text(), key
    with pytest.raises(InputError, match="not a saved result"):
        load_result(tmp_path)


def test_csv_written_by_a_job_is_the_same_file(written, tmp_path):
    """write_report(csv=job): the pipeline writes coefficients.csv from csv_data (write_csv_data), its
    measured fields formatted earlier by its worker (csv_measured_text); the report collects it and the file is the
    one write_csv writes, byte for byte, with or without the measured fields given."""
    from gcs_sysid.report.tables import csv_data, csv_measured_text, write_csv_data

    r, files = written
    tb = r.table
    data = csv_data(tb.t, tb.X, tb.Y, r.pred_mean, r.pred_sigma, r.pred_sigma_obs, r.held_out)
    calls = []

    class Job:                                # what gcs_sysid.parallel.Job gives: result() -> the path
        def result(self):
            calls.append(1)
            return write_csv_data(data, tmp_path / "coefficients.csv", csv_measured_text(tb.t, tb.X, tb.Y))

    again = write_report(r, tmp_path, save=False, csv=Job())
    assert calls == [1] and again["csv"] == tmp_path / "coefficients.csv"
    assert again["csv"].read_bytes() == files["csv"].read_bytes()
    assert write_csv_data(data, tmp_path / "whole.csv").read_bytes() == files["csv"].read_bytes()
    with pytest.raises(InputError, match="formatted rows"):
        write_csv_data(data, tmp_path / "bad.csv", csv_measured_text(tb.t, tb.X, tb.Y)[1:])


def test_partial_result_says_what_is_missing(partial_result, tmp_path):
    from gcs_sysid.report.html import render_html
    from gcs_sysid.report.markdown import render_markdown
    from gcs_sysid.report.tables import write_csv, write_suggestions_json

    files = {"html": render_html(partial_result, tmp_path / "report.html"),
             "markdown": render_markdown(partial_result, tmp_path / "summary.md"),
             "csv": write_csv(partial_result, tmp_path / "c.csv"),
             "suggestions": write_suggestions_json(partial_result, tmp_path / "s.json")}
    page = files["html"].read_text()
    notes = page[page.index('id="notes"'):page.index('id="data"')]
    assert "not identifiable" in notes and "IMU at 4 Hz" in notes and "wind: no WIND message" in notes
    assert "no model for Cm" not in notes
    md = files["markdown"].read_text()
    assert "not identified: IMU at 4 Hz" in md
    doc = json.loads(files["suggestions"].read_text())
    assert set(doc["not_identified"]) == {"Cl", "Cm", "Cn"}
    assert all(set(s["coefficients"]) <= {"CX", "CY", "CZ"} for s in doc["suggestions"])
    with open(files["csv"]) as f:
        rows = list(csv.reader(f))
    assert rows[1][rows[0].index("Cm_pred")] == "nan"


def test_figures_from_the_worker_make_the_same_page(replay_result, tmp_path):
    """The pipeline draws the figures in its worker process: same PNG bytes, same report.html."""
    from gcs_sysid.parallel import Helper
    from gcs_sysid.report import plots

    r = replay_result
    with Helper(enabled=True) as h:
        jobs = {
            "streams": h.submit("gcs_sysid.report.plots:streams_figure", r.summaries),
            "states": h.submit("gcs_sysid.report.plots:states_figure", r.states, r.held_out),
            "coefficients": h.submit("gcs_sysid.report.plots:coefficients_figure", r.table, r.pred_mean,
                                     r.pred_sigma_obs, r.held_out, r.identifiable),   # the measurements' band
            "envelope": h.submit("gcs_sysid.report.plots:envelope_figures", r.envelope, r.table.X[r.train]),
            "suggestions": h.submit("gcs_sysid.report.plots:suggestions_figure", r.suggestions),
        }
        assert jobs["states"].result() == plots.figure(r, "states")
        assert jobs["envelope"].result() == plots.figure(r, "envelope")
        a = write_report(r, tmp_path / "worker", save=False, figures=jobs)["html"].read_text()
    assert all(j.ran_in_worker for j in jobs.values())
    b = write_report(r, tmp_path / "here", save=False)["html"].read_text()
    assert a == b


def test_result_saved_before_the_two_bands_loads_its_sigma_as_the_measurement_band(partial_result, tmp_path):
    """A result saved before the eleventh session has one ``pred_sigma``, the band for a new measurement:
    it loads as ``pred_sigma_obs``, and the coefficient's band is unknown (NaN), not mislabelled."""
    import zipfile

    from gcs_sysid.report.store import save_result

    files = save_result(partial_result, tmp_path / "old")
    with zipfile.ZipFile(files["result_npz"]) as z:
        arrays = {n[:-4]: np.load(z.open(n)) for n in z.namelist() if n != "pred_sigma_obs.npy"}
    arrays["pred_sigma"] = partial_result.pred_sigma_obs
    np.savez(files["result_npz"], **arrays)
    back = load_result(tmp_path / "old")
    np.testing.assert_array_equal(back.pred_sigma_obs, partial_result.pred_sigma_obs)
    assert np.isnan(back.pred_sigma).all()
