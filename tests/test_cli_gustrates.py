"""`--gust-rates` on replay and fit: parsed into the options, a wrong frame is a user error; `--air-roll` on replay."""

import pytest

from gcs_sysid.cli import _replay_options, build_parser, main


def test_replay_gust_rates_reaches_the_options():
    a = build_parser().parse_args(["replay", "x.tlog", "--airframe", "a.toml", "--out", "o", "--gust-rates", "path"])
    assert _replay_options(a).gust_rates == "path"
    a = build_parser().parse_args(["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"])
    assert _replay_options(a).gust_rates is None
    a = build_parser().parse_args(["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml", "--gust-rates",
                                   "mean-wind"])
    assert a.gust_rates == "mean-wind"


def test_replay_gust_rate_and_sideslip_flags_reach_the_stages(monkeypatch):
    """No flag: the gyro's rates (REPLAY_GUST_RATES "inertial" -> None for the coefficients) and the aiding's module
    default for the sideslip (airangles.BETA_GLS, off); `--gust-rates path-yaw --beta-gls on` reach the stages as
    given, `--beta-gls off` wins over the module switch; an unknown frame in the options is an InputError."""
    import gcs_sysid.estimation.airangles as aa
    import gcs_sysid.pipeline as pl

    base = ["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"]
    o = _replay_options(build_parser().parse_args(base))
    assert (o.gust_rates, pl.replay_gust_rates(o), pl.replay_beta_gls(o)) == (None, None, False)
    monkeypatch.setattr(aa, "BETA_GLS", True)
    assert pl.replay_beta_gls(o) is True
    o = _replay_options(build_parser().parse_args(base + ["--gust-rates", "path-yaw", "--beta-gls", "off"]))
    assert (pl.replay_gust_rates(o), pl.replay_beta_gls(o)) == ("path-yaw", False)
    o = _replay_options(build_parser().parse_args(base + ["--gust-rates", "inertial", "--beta-gls", "on"]))
    assert (o.gust_rates, pl.replay_gust_rates(o), pl.replay_beta_gls(o)) == ("inertial", None, True)
    with pytest.raises(pl.InputError, match="gust_rates: expected one of path, path-yaw, mean-wind, inertial"):
        pl.check_replay("x.tlog", "a.toml", None, pl.ReplayOptions(gust_rates="body"))
    o = _replay_options(build_parser().parse_args(base + ["--air-yaw", "on"]))
    assert o.air_yaw is True and _replay_options(build_parser().parse_args(base)).air_yaw is None
    with pytest.raises(pl.InputError, match="air_yaw: not with a gust_rates frame"):
        pl.check_replay("x.tlog", "a.toml", None, pl.ReplayOptions(air_yaw=True, gust_rates="path-yaw"))
    o = _replay_options(build_parser().parse_args(base + ["--air-pitch", "on"]))
    assert o.air_pitch is True and _replay_options(build_parser().parse_args(base)).air_pitch is None
    with pytest.raises(pl.InputError, match="air_pitch: not with the gust_rates frame 'path'"):
        pl.check_replay("x.tlog", "a.toml", None, pl.ReplayOptions(air_pitch=True, gust_rates="path"))
    # the default (on) gives way to a frame that already moves q_hat; an explicit choice stands
    assert pl.replay_air_pitch(pl.ReplayOptions()) is True
    assert pl.replay_air_pitch(pl.ReplayOptions(gust_rates="mean-wind")) is False
    assert pl.replay_air_pitch(pl.ReplayOptions(gust_rates="path-yaw")) is True
    assert pl.replay_air_pitch(pl.ReplayOptions(air_pitch=False)) is False


def test_unknown_gust_rate_frame_is_a_user_error(capsys):
    with pytest.raises(SystemExit) as e:
        main(["replay", "x.tlog", "--airframe", "a.toml", "--out", "o", "--gust-rates", "body"], handle_signals=False)
    assert e.value.code == 2
    assert "--gust-rates" in capsys.readouterr().err


def test_stated_lift_level_flag_switches_the_aiding(monkeypatch):
    """`--stated-lift-level` on replay and fit switches on airangles.STATED_LIFT_LEVEL for the run (off without it)."""
    import gcs_sysid.cli as cli
    import gcs_sysid.diagnose as dg
    import gcs_sysid.estimation.airangles as aa
    import gcs_sysid.pipeline as pl

    seen = []
    monkeypatch.setattr(pl, "run_replay", lambda *x, **k: seen.append(aa.STATED_LIFT_LEVEL) or 1 / 0)
    monkeypatch.setattr(dg, "run_fit", lambda *x, **k: seen.append(aa.STATED_LIFT_LEVEL) or 1 / 0)
    for argv in (["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"],
                 ["replay", "x.tlog", "--airframe", "a.toml", "--out", "o", "--stated-lift-level"],
                 ["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml", "--stated-lift-level"]):
        monkeypatch.setattr(aa, "STATED_LIFT_LEVEL", False)
        a = build_parser().parse_args(argv)
        with pytest.raises(ZeroDivisionError):
            cli.COMMANDS[a.command](a)
    assert seen == [False, True, True]


def test_replay_air_roll_flag_sets_both_halves_of_the_pair(capsys):
    """`--air-roll off` turns off Cl's air-rate target and its held-out rate together, `on` asks for both, no flag
    leaves the replay's defaults (None); another value is a user error (exit 2)."""
    base = ["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"]
    o = _replay_options(build_parser().parse_args(base + ["--air-roll", "off"]))
    assert (o.air_roll_train, o.heldout_air_roll) == (False, "off")
    o = _replay_options(build_parser().parse_args(base + ["--air-roll", "on"]))
    assert (o.air_roll_train, o.heldout_air_roll) == (True, "predicted:Cl")
    o = _replay_options(build_parser().parse_args(base))
    assert (o.air_roll_train, o.heldout_air_roll) == (None, None)
    with pytest.raises(SystemExit) as e:
        main(base + ["--air-roll", "maybe"], handle_signals=False)
    assert e.value.code == 2 and "--air-roll" in capsys.readouterr().err


def test_run_replay_hands_its_sideslip_estimator_and_rate_frame_to_the_stages(monkeypatch, tmp_path):
    """On the project's sample flight, `run_replay` decodes the log and calls the estimation with
    `gls_beta=replay_beta_gls(options)` and the coefficients with `gust_rates=replay_gust_rates(options)`
    (each captured, then the run stopped): the defaults give (False, None), the options as asked."""
    from pathlib import Path

    import gcs_sysid.estimation as est
    import gcs_sysid.pipeline as pl

    data = Path(__file__).resolve().parents[1] / "data"
    log, af = data / "flights" / "sim-trainer-sysid.tlog", data / "airframes" / "sim-trainer.toml"
    seen = []
    real = est.estimate_states

    def states(*a, **k):
        seen.append(k["gls_beta"])
        return real(*a, **{**k, "gls_beta": False})      # least squares either way: the call is what is checked

    monkeypatch.setattr(est, "estimate_states", states)
    monkeypatch.setattr(pl, "compute_coefficients", lambda s, f, gust_rates: seen.append(gust_rates) or 1 / 0)
    for opts in (pl.ReplayOptions(progress=False, write=False, parallel=False, t_to=40.0),
                 pl.ReplayOptions(progress=False, write=False, parallel=False, t_to=40.0, beta_gls=True,
                                  gust_rates="path-yaw")):
        with pytest.raises(ZeroDivisionError):
            pl.run_replay(log, af, tmp_path / "o", opts)
    assert seen == [False, None, True, "path-yaw"]


@pytest.mark.parametrize("flag, expected", [([], True), (["--air-pitch", "off"], False), (["--air-pitch", "on"], True)])
def test_listen_air_pitch_is_on_by_default(monkeypatch, flag, expected):
    """`listen`'s windows learn at the air-relative q_hat unless told otherwise (sixty-ninth session, rule 69), as
    `LearnOptions`' own default."""
    import gcs_sysid.live.session as session
    from gcs_sysid.live.cli import cmd_listen
    from gcs_sysid.live.learner import LearnOptions

    seen = {}

    def fake_run_listen(airframe, out, opts):
        seen["learn"] = opts.learn
        return {"raw_log": "raw.tlog", "raw_records": 0}

    monkeypatch.setattr(session, "run_listen", fake_run_listen)
    a = build_parser().parse_args(["listen", "udpin:127.0.0.1:14550", "--airframe", "a.toml", "--out", "o"] + flag)
    assert cmd_listen(a) == 0
    assert seen["learn"].air_pitch is expected
    assert LearnOptions().air_pitch is True
