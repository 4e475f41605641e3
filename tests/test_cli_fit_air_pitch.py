"""`gcs-sysid fit --air-pitch on|off` (sixty-ninth session): the stepwise fit at the air-relative ``q_hat``, as the
replay's default learns, so that issue 8's least-squares line is fitted on the same data as the GP. Off by default
(`diagnose` fits its reference models through the same code and reads its flights at the gyro's rate)."""

import json
import tomllib
from pathlib import Path

import pytest

from gcs_sysid.cli import build_parser, main

DATA = Path(__file__).resolve().parents[1] / "data"
LOG = DATA / "flights" / "sim-trainer-sysid.tlog"
AIRFRAME = DATA / "airframes" / "sim-trainer.toml"


def test_fit_air_pitch_flag_reaches_run_fit_off_by_default(monkeypatch):
    import gcs_sysid.cli as cli
    import gcs_sysid.diagnose as dg

    seen = []
    monkeypatch.setattr(dg, "run_fit", lambda *x, **k: seen.append(k["air_pitch"]) or 1 / 0)
    base = ["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml"]
    for extra in ([], ["--air-pitch", "off"], ["--air-pitch", "on"]):
        a = build_parser().parse_args(base + extra)
        with pytest.raises(ZeroDivisionError):
            cli.COMMANDS[a.command](a)
    assert seen == [False, False, True]


def test_fit_air_pitch_on_the_sample_flight_is_recorded_and_refused_with_a_moving_frame(tmp_path, capsys):
    """The project's sample flight: the share's fit over the whole window applies (the sixty-eighth session saw the
    replay's apply too: the column also reads the aided alpha's fast error, kappa about +0.1); the model's header and
    ``<out>.fit.json`` say so; ``off`` records that it was off. ``--gust-rates path`` with ``--air-pitch on`` is a user
    error (exit 2), before anything is written."""
    docs, models = {}, {}
    for key in ("off", "on"):
        out = tmp_path / f"{key}.toml"
        assert main(["fit", str(LOG), "--airframe", str(AIRFRAME), "--out", str(out), "--air-pitch", key],
                    handle_signals=False) == 0
        docs[key], models[key] = json.loads(out.with_suffix(".fit.json").read_text()), out.read_text()
    assert docs["off"]["air_pitch"] == {"applied": False, "kappa": None, "t": None, "note": "off (--air-pitch off)"}
    on = docs["on"]["air_pitch"]
    assert on["applied"] and 0.0 < on["kappa"] < 0.5 and on["t"] > 10, on
    assert on["note"] in docs["on"]["notes"] and "# q_hat is the air-relative estimate" in models["on"]
    assert "air-relative" not in models["off"]
    a, b = tomllib.loads(models["on"]), tomllib.loads(models["off"])
    assert a["Cm"] != b["Cm"]                                  # the moved q_hat moves the pitching moment's terms
    out = tmp_path / "path.toml"
    capsys.readouterr()
    assert main(["fit", str(LOG), "--airframe", str(AIRFRAME), "--out", str(out), "--air-pitch", "on",
                 "--gust-rates", "path"], handle_signals=False) == 2
    assert "--air-pitch on: not with --gust-rates path" in capsys.readouterr().err and not out.exists()
