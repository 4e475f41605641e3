"""`gcs-sysid fit --air-roll on|off` (thirtieth session, i8-airfit): Cl fitted on the replay's air-rate target.

Opt-in (default off: `diagnose` fits its reference models through the same code). The JSBSim case, where the roll fit is
accepted and the fitted Cl moves towards the truth at the air-relative rate, is `tests/jsbsim/test_fit_air_roll.py`."""

import json
import tomllib
from pathlib import Path

import pytest

from gcs_sysid.cli import build_parser, main

DATA = Path(__file__).resolve().parents[1] / "data"
LOG = DATA / "flights" / "sim-trainer-sysid.tlog"
AIRFRAME = DATA / "airframes" / "sim-trainer.toml"


def test_fit_air_roll_flag_reaches_run_fit_and_follows_the_diagnosis_by_default(monkeypatch):
    """No flag: ``air_roll_train=None`` (the diagnosis's own mode); ``off``: False; ``on``: True; another value is a
    user error (exit 2)."""
    import gcs_sysid.cli as cli
    import gcs_sysid.diagnose as dg

    seen = []
    monkeypatch.setattr(dg, "run_fit", lambda *x, **k: seen.append(k["air_roll_train"]) or 1 / 0)
    base = ["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml"]
    for extra in ([], ["--air-roll", "off"], ["--air-roll", "on"]):
        a = build_parser().parse_args(base + extra)
        with pytest.raises(ZeroDivisionError):
            cli.COMMANDS[a.command](a)
    assert seen == [None, False, True]
    with pytest.raises(SystemExit) as e:
        main(base + ["--air-roll", "maybe"], handle_signals=False)
    assert e.value.code == 2


def test_fit_air_roll_is_refused_in_calm_air_with_the_reason_recorded(tmp_path, monkeypatch, capsys):
    """The project's sample flight (the simulation's turbulence moves the air, not the roll moment: no rolling gust):
    the pair's roll fit is refused by its instruments' check (twenty-ninth session, i8-guard), so ``--air-roll on``
    fits the measured Cl, the same model as ``off``; ``<out>.fit.json`` says ``target = "gyro"``, ``applied = false``
    and why, and so does the model file's header; without the flag (the diagnosis's ``"reference:Cl"``) the same
    refusal is recorded with the mode's name. The diagnosis's own air roll rate (``AIR_ROLL_RATE`` moving the
    fit's flight) and ``--air-roll on`` together are a user error (exit 2), before anything is written."""
    import gcs_sysid.diagnose.run as dr

    models, docs = {}, {}
    for key in ("off", "on"):
        out = tmp_path / f"{key}.toml"
        assert main(["fit", str(LOG), "--airframe", str(AIRFRAME), "--out", str(out), "--air-roll", key],
                    handle_signals=False) == 0
        models[key], docs[key] = out.read_text(), json.loads(out.with_suffix(".fit.json").read_text())
    assert docs["off"]["air_roll"]["target"] == "gyro" and not docs["off"]["air_roll"]["applied"]
    air = docs["on"]["air_roll"]
    assert air["target"] == "gyro" and not air["applied"] and air["Cl_p"] is None
    assert "air-rate training target" in air["note"] and "instrumented" in air["note"]
    assert air["note"] in docs["on"]["notes"]
    assert "# Cl's air-rate training target" in models["on"] and "air-rate" not in models["off"]
    on, off = tomllib.loads(models["on"]), tomllib.loads(models["off"])
    assert on.pop("name") == "on" and off.pop("name") == "off"
    assert on == off                                                          # the measured Cl: the same model
    # no flag: as the diagnosis loads its reference ("reference:Cl", the default): the same refusal, recorded as such
    out = tmp_path / "default.toml"
    assert main(["fit", str(LOG), "--airframe", str(AIRFRAME), "--out", str(out)], handle_signals=False) == 0
    air = json.loads(out.with_suffix(".fit.json").read_text())["air_roll"]
    assert air["target"] == "gyro" and not air["applied"] and air["Cl_p"] is None
    assert "'reference:Cl'" in air["note"] and "instrumented" in air["note"]
    default = tomllib.loads(out.read_text())
    assert default.pop("name") == "default" and default == off
    monkeypatch.setattr(dr, "AIR_ROLL_RATE", "fit")
    capsys.readouterr()
    out = tmp_path / "both.toml"
    assert main(["fit", str(LOG), "--airframe", str(AIRFRAME), "--out", str(out), "--air-roll", "on"],
                handle_signals=False) == 2
    assert "--air-roll on" in capsys.readouterr().err and not out.exists()
