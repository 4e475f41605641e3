"""The sideslip aiding's ``CY_beta`` estimator per path: least squares everywhere by default (the gust model's
likelihood with the slope held, ``airangles.BETA_PROFILE`` and ``BETA_PROFILE_HOLD``, was the replay's default in the
thirty-second session only); the diagnosis and ``gcs-sysid fit`` load their flights with least squares
(``gcs_sysid.diagnose.run.BETA_PROFILE``), and ``fit --beta-profile on`` asks for the profile (docs/estimation.md, "The
side-force slope by the gust model's likelihood")."""

from pathlib import Path

import pytest

from gcs_sysid.cli import build_parser, main

DATA = Path(__file__).resolve().parents[1] / "data"
LOG = DATA / "flights" / "sim-trainer-sysid.tlog"
AIRFRAME = DATA / "airframes" / "sim-trainer.toml"


def test_fit_beta_profile_flag_reaches_run_fit_and_is_off_by_default(monkeypatch):
    """No flag: ``profile_beta=False``; ``on``: True; another value is a user error (exit 2)."""
    import gcs_sysid.cli as cli
    import gcs_sysid.diagnose as dg

    seen = []
    monkeypatch.setattr(dg, "run_fit", lambda *x, **k: seen.append(k["profile_beta"]) or 1 / 0)
    base = ["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml"]
    for extra in ([], ["--beta-profile", "off"], ["--beta-profile", "on"]):
        a = build_parser().parse_args(base + extra)
        with pytest.raises(ZeroDivisionError):
            cli.COMMANDS[a.command](a)
    assert seen == [False, False, True]
    with pytest.raises(SystemExit) as e:
        main(base + ["--beta-profile", "maybe"], handle_signals=False)
    assert e.value.code == 2


def test_least_squares_is_every_paths_default_and_the_profile_is_asked_for(monkeypatch):
    """On the project's sample flight: the estimator's default (the replay's ``estimate_states``) and
    ``load_measurements`` (the diagnosis's and ``fit``'s loader) run no likelihood search of ``CY_beta`` (opt-in again
    since the thirty-third session); ``profile_beta=True`` runs it on either path."""
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.diagnose.run import load_measurements
    from gcs_sysid.estimation import airangles, estimate_states
    from gcs_sysid.telemetry import read_log

    assert not airangles.BETA_PROFILE and airangles.BETA_PROFILE_HOLD      # the hold acts only with the profile
    calls = []
    real = airangles._profile_angle_slope
    monkeypatch.setattr(airangles, "_profile_angle_slope", lambda *a, **k: calls.append(1) or real(*a, **k))
    replay = estimate_states(read_log(LOG), load_airframe(AIRFRAME))
    assert replay.angle_fits["beta"].used and calls == []
    load_measurements(LOG, AIRFRAME)
    assert calls == []                                   # least squares: no search
    load_measurements(LOG, AIRFRAME, profile_beta=True)
    assert len(calls) == 1
    estimate_states(read_log(LOG), load_airframe(AIRFRAME), profile_beta=True)
    assert len(calls) == 2
