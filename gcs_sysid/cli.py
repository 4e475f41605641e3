"""Command-line interface: ``gcs-sysid replay | simulate | fit | diagnose | predict | campaign | listen``.

Errors a user can cause (bad file, missing field, bad option, data that cannot support an
estimate) print one line ``gcs-sysid: error: ...`` on stderr and exit with code 2, without a
traceback; options and paths are checked before any work (:mod:`gcs_sysid.options`,
:mod:`gcs_sysid.outdir`). Ctrl-C and SIGTERM end any command at once with 130 / 143 and one line
(:mod:`gcs_sysid.stopping`). ``--debug`` shows the traceback of any error. Exit codes are listed
in ``docs/cli.md``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from .errors import SysidError

__all__ = ["main", "build_parser"]

EXIT_USER_ERROR = 2
EXIT_INTERNAL_ERROR = 1


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``gcs-sysid: error: ...``, exit 2) instead of usage + error."""

    def error(self, message: str):
        where = self.prog.split(" ", 1)[1] + ": " if " " in self.prog else ""
        print(f"gcs-sysid: error: {where}{message} (see gcs-sysid {where[:-2]} --help)".replace("  ", " "),
              file=sys.stderr)
        sys.exit(EXIT_USER_ERROR)


def _say(line: str) -> None:
    print(line, flush=True)


def _window_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--from", dest="t_from", type=float, default=None, metavar="S",
                   help="start of the window, vehicle time since boot in s")
    p.add_argument("--to", dest="t_to", type=float, default=None, metavar="S",
                   help="end of the window, vehicle time since boot in s")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (documented in docs/cli.md)."""
    ap = _Parser(
        prog="gcs-sysid",
        description="UAV system identification from MAVLink telemetry: aerodynamic coefficients, "
                    "a Gaussian-process model with uncertainty, and maneuver suggestions.",
    )
    ap.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = ap.add_subparsers(dest="command", required=True)

    r = sub.add_parser("replay", help="replay a flight log end to end and write the report")
    r.add_argument("log", help="MAVLink telemetry log (.tlog) or ArduPilot DataFlash log (.bin)")
    r.add_argument("--airframe", required=True, help="airframe TOML file (docs/airframe.md)")
    r.add_argument("--out", required=True, help="output directory for the report and model state")
    _window_args(r)
    r.add_argument("--rate", type=float, default=50.0, help="estimation grid rate in Hz (default 50)")
    r.add_argument("--holdout", type=float, default=0.2,
                   help="fraction of the flight (last time segment) held out for testing (default 0.2)")
    r.add_argument("--model", dest="model_in", default=None,
                   help="model state saved by an earlier replay (DIR/model): continue learning from it")
    r.add_argument("--inducing", type=int, default=None, help="number of inducing points of the global GP")
    r.add_argument("--target", default=None, metavar="C[,C...]",
                   help="coefficients the maneuver suggestions target, e.g. Cl,Cn (default: all, moment "
                        "coefficients first)")
    r.add_argument("--can-log", default=None, metavar="FILE",
                   help="recorded CAN log (.log/.asc/.blf/.csv): DroneCAN actuator positions and airspeed "
                        "(docs/live.md)")
    r.add_argument("--can-offset", type=float, default=None, metavar="S",
                   help="seconds added to the CAN log's times (default 0 with a .tlog; required with a .bin)")
    r.add_argument("--gust-rates", default=None, choices=("path", "path-yaw", "mean-wind", "inertial"),
                   help="p_hat q_hat r_hat relative to the air: minus the gust rates estimated from the "
                        "reconstructed gusts in this frame; 'inertial' the gyro's rates (the default; "
                        "docs/estimation.md, 'Gust rates')")
    r.add_argument("--beta-gls", default=None, choices=("on", "off"),
                   help="the aided sideslip's side-force model by generalised least squares under the gust model "
                        "('on', opt-in) or least squares ('off', the default, as fit and diagnose load their flights; "
                        "docs/estimation.md, 'The side-force model by generalised least squares')")
    r.add_argument("--air-yaw", default=None, choices=("on", "off"),
                   help="Cn learned at the air-relative yaw rate (its training target less the yaw gust rate's "
                        "moment, the held-out Cn asked at r_hat less the yaw gust rate; the inputs stay the gyro's): "
                        "'on' opt-in, 'off' the default (docs/estimation.md, 'The yaw gust rate in the moments' "
                        "targets')")
    r.add_argument("--air-pitch", default=None, choices=("on", "off"),
                   help="q_hat at the air-relative estimate, the gyro's less the pitch gust rate from the "
                        "reconstructed wind with its share in Cm fitted on the training rows (free sign; applied only "
                        "when the fit shows it), for every output and row: 'on' the default (off with --gust-rates "
                        "path or mean-wind), 'off' the gyro's q_hat (docs/estimation.md, 'The air-relative pitch "
                        "rate')")
    r.add_argument("--rate-errors", default=None, choices=("on", "off"),
                   help="state the gyro rates' errors as stand-ins for the air-relative rates in the model's band at "
                        "exact conditions (predict's sigma): p_hat's scale error from the rolling gust, r_hat's "
                        "linear error from the yaw gust rate ('on', the default) or leave the rates exact there "
                        "('off'; docs/gp.md, 'The rates' errors')")
    r.add_argument("--coefficient-band", default=None, choices=("white", "stated"),
                   help="the coefficient's band at the flight's own regressors (coefficients.csv's <C>_sigma): "
                        "'stated' (the default) for CZ, Cm and Cn the blocked validation's residual variance, for CZ "
                        "and Cm plus the measured coefficient's error variance the estimator states (CX, CY, Cl: "
                        "white); 'white' the measurement's band less its white part for all six (docs/gp.md, 'The "
                        "coefficient's band from the stated measurement error')")
    r.add_argument("--gp-noise", default=None, choices=("learned", "independent", "diagonal", "full", "full-nstart"),
                   help="the GP's output noise: 'learned' (the default) learns the outputs' noise correlation with "
                        "the hyperparameters and keeps only its diagonal in the predictions; 'independent' (the "
                        "default until the twenty-fifth session; 'diagonal' is its older name) one noise variance per "
                        "output; 'full' the learned correlation in the predictions too (docs/gp.md, "
                        "'The default noise')")
    r.add_argument("--stated-lift-level", action="store_true",
                   help="set the aided alpha's flight mean on the airframe's stated lift line ([aero] CL0 with "
                        "CL_alpha; docs/estimation.md, 'A stated lift line sets alpha's level'; default off)")
    r.add_argument("--air-roll", default=None, choices=("on", "off"),
                   help="Cl learned and asked at the air-relative roll rate (the rolling gust's moment taken out "
                        "of Cl's training target, the held-out Cl asked at the gyro's p_hat less the predicted "
                        "gust; refused, with a note, where the roll fit finds no gust): 'on' the default, 'off' "
                        "Cl at the gyro's rate as every other coefficient (docs/estimation.md, 'The pair is the "
                        "default')")
    r.add_argument("--quiet", action="store_true", help="no progress display")

    s = sub.add_parser("simulate", help="simulate a flight with the project's 6-DOF model and write a tlog")
    s.add_argument("--airframe", required=True, help="airframe TOML file")
    s.add_argument("--model", required=True, help="aerodynamic model TOML file (docs/model-file.md)")
    s.add_argument("--maneuvers", required=True, help="flight plan TOML file (docs/sim.md)")
    s.add_argument("--out", required=True, help="output .tlog path")
    s.add_argument("--seed", type=int, default=None, help="random seed (overrides the plan's)")
    s.add_argument("--truth", default=None, help="also write the true states and coefficients to this .npz")
    s.add_argument("--live", default=None, metavar="CONNECTION",
                   help="then stream the flight onto this link as a stand-in vehicle (docs/live.md)")
    s.add_argument("--speed", type=float, default=1.0, help="with --live: 1 real time, 0 as fast as possible")

    f = sub.add_parser("fit", help="equation-error least squares + stepwise regression -> model file")
    f.add_argument("log")
    f.add_argument("--airframe", required=True)
    f.add_argument("--out", required=True, help="output model TOML file")
    f.add_argument("--gust-rates", default=None, choices=("path", "path-yaw", "mean-wind"),
                   help="p_hat q_hat r_hat relative to the air (as replay's --gust-rates; default: the gyro's "
                        "rates, as diagnose reads its flights)")
    f.add_argument("--stated-lift-level", action="store_true",
                   help="alpha's flight mean on the airframe's stated lift line (as replay's --stated-lift-level)")
    f.add_argument("--air-roll", default=None, choices=("on", "off"),
                   help="Cl fitted on the replay's air-rate target (the measured Cl less the window's smoothed "
                        "rolling-gust moment, so the model's Cl terms read the air-relative roll rate; refused, "
                        "with a note in the model's header and <out>.fit.json, where the roll fit finds no gust): "
                        "'on', or 'off' (the measured Cl at the gyro's rate); not given: as diagnose reads its "
                        "reference flight (Cl's air-rate target, docs/diagnose.md, 'The air-relative roll rate'; "
                        "docs/estimation.md, 'Where the pair applies')")
    f.add_argument("--air-pitch", default="off", choices=("on", "off"),
                   help="q_hat at the air-relative estimate, the gyro's less the pitch gust rate from the "
                        "reconstructed wind times its share in Cm fitted on the window (as replay's default; applied "
                        "only where the fit shows it, with a note in the model's header and <out>.fit.json): 'on', "
                        "or 'off' (the default: the gyro's q_hat, as diagnose reads its flights); "
                        "docs/estimation.md, 'The air-relative pitch rate'")
    f.add_argument("--beta-profile", default="off", choices=("on", "off"),
                   help="the aided sideslip's CY_beta by the gust model's likelihood, held in the later passes (opt-in "
                        "everywhere since the thirty-third session): 'off' the default (least squares, as the "
                        "diagnosis loads its flights), "
                        "'on' (docs/estimation.md, 'The side-force slope by the gust model's likelihood')")
    _window_args(f)

    d = sub.add_parser("diagnose", help="compare the simulation model with measured data, name the cause")
    d.add_argument("log")
    d.add_argument("--airframe", required=True)
    d.add_argument("--model", required=True, help="the simulation's aerodynamic model TOML file")
    d.add_argument("--out", required=True, help="output directory")
    d.add_argument("--search", action="store_true", help="also search a wide term library (docs/diagnose.md)")
    d.add_argument("--reference", action="append", metavar="LOG", help="a reference flight (repeatable; default: "
                   "the flight(s) the model was fitted on, from <model>.fit.json): differential diagnosis")
    d.add_argument("--no-reference", action="store_true", help="no differential diagnosis")
    d.add_argument("--alpha-level", choices=("reference", "pooled"), default=None,
                   help="put this flight's alpha in the reference flight's frame, or in the mean frame of every "
                        "--reference flight (pooled lift curve, docs/diagnose.md 'The alpha level'; default off)")
    _window_args(d)

    pr = sub.add_parser("predict", help="evaluate a saved model at given flight conditions (CSV in, CSV out)")
    pr.add_argument("model_dir", help="replay output directory holding model.npz/model.json (or the model prefix)")
    pr.add_argument("--inputs", required=True, help="CSV with columns " + " ".join(
        ("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a", "delta_r", "delta_t", "V")) + " (SI)")
    pr.add_argument("--out", required=True, help="output CSV: inputs plus <C>_mean, <C>_sigma, <C>_sigma_obs")

    c = sub.add_parser("campaign", help="closed-loop campaign in the simulation: suggested vs standard flights")
    c.add_argument("--airframe", required=True, help="airframe TOML with a [limits] table")
    c.add_argument("--model", required=True, help="truth aerodynamic model TOML (docs/model-file.md)")
    c.add_argument("--flights", type=int, default=4, help="flights per arm, the first standard (default 4)")
    c.add_argument("--seeds", default="1", help="comma-separated seeds, one campaign each (default 1)")
    c.add_argument("--out", required=True, help="output directory (campaign.json, campaign.md, campaign.png)")
    c.add_argument("--refit", action="store_true", help="re-learn the GP after each flight instead of updating it")
    c.add_argument("--gp-noise", default=None, choices=("learned", "independent", "diagonal", "full", "full-nstart"),
                   help="the GP's output noise (default independent: one variance per output; 'learned' is the "
                        "replay's default; docs/gp.md, 'Noise')")

    from .live.cli import add_listen_parser

    add_listen_parser(sub)
    return ap


def _replay_options(a: argparse.Namespace):
    from .pipeline import ReplayOptions

    return ReplayOptions(rate_hz=a.rate, holdout=a.holdout, t_from=a.t_from, t_to=a.t_to,
                         model_in=a.model_in, n_inducing=a.inducing, progress=not a.quiet, notify=_say,
                         targets=None if a.target is None else tuple(c.strip() for c in a.target.split(",")),
                         can_log=a.can_log, can_offset=a.can_offset, gust_rates=a.gust_rates,
                         beta_gls=None if a.beta_gls is None else a.beta_gls == "on",
                         air_yaw=None if a.air_yaw is None else a.air_yaw == "on",
                         rate_errors=None if a.rate_errors is None else a.rate_errors == "on",
                         air_pitch=None if a.air_pitch is None else a.air_pitch == "on",
                         coefficient_band=a.coefficient_band,
                         gp_noise=a.gp_noise, **_air_roll_options(getattr(a, "air_roll", None)))


def _air_roll_options(flag: str | None) -> dict:
    """``--air-roll on|off`` as :class:`gcs_sysid.pipeline.ReplayOptions` fields (``air_roll_train`` and
    ``heldout_air_roll``, the pair :mod:`gcs_sysid.aero.gustfilter` makes the default); None: the defaults."""
    if flag is None:
        return {}
    return {"air_roll_train": flag == "on", "heldout_air_roll": "predicted:Cl" if flag == "on" else "off"}


def _stated_lift_level(a: argparse.Namespace) -> None:
    """``--stated-lift-level``: switch on :data:`gcs_sysid.estimation.airangles.STATED_LIFT_LEVEL` for this run (the
    aiding runs in this process; an airframe without ``[aero] CL0`` is unchanged)."""
    if getattr(a, "stated_lift_level", False):
        from .estimation import airangles

        airangles.STATED_LIFT_LEVEL = True


def _check_replay(a: argparse.Namespace) -> None:
    from .pipeline import check_replay

    check_replay(a.log, a.airframe, a.out, _replay_options(a))


def _cmd_replay(a: argparse.Namespace) -> int:
    from .pipeline import MIN_TRAIN_ROWS, run_replay

    _stated_lift_level(a)
    result = run_replay(a.log, a.airframe, a.out, _replay_options(a))
    out = Path(a.out)
    print(f"report: {out / 'report.html'}")
    fitted = bool(result.gp_summary)
    for name, m in result.metrics.items():
        ok, why = result.identifiable.get(name, (True, ""))
        if not ok:
            print(f"  {name:3s} not identified: {why}")
        elif m.get("n_heldout", 0) > 0:
            print(f"  {name:3s} held-out error {m['error_pct_heldout']:6.1f} %")
        elif not fitted:
            print(f"  {name:3s} no model fitted: {m.get('n_train', 0)} valid training samples "
                  f"(need {MIN_TRAIN_ROWS})")
        elif a.holdout == 0:
            print(f"  {name:3s} no held-out error: --holdout 0")
        else:
            print(f"  {name:3s} no held-out error: no valid samples in the held-out segment")
    if result.suggestions:
        print(f"next maneuver: {result.suggestions[0].reason}")
    return 0


def _check_window(a: argparse.Namespace) -> None:
    from .options import check_log, check_window

    check_window(a.t_from, a.t_to)
    check_log(a.log)


def _check_simulate(a: argparse.Namespace) -> None:
    from .options import check_input_file
    from .outdir import check_out_file

    check_input_file(a.airframe, "--airframe", "an airframe TOML file (docs/airframe.md)")
    check_input_file(a.model, "--model", "an aerodynamic model TOML file (docs/model-file.md)")
    check_input_file(a.maneuvers, "--maneuvers", "a flight plan TOML file (docs/sim.md)")
    check_out_file(a.out, "--out")
    if a.truth is not None:
        check_out_file(a.truth, "--truth")


def _cmd_simulate(a: argparse.Namespace) -> int:
    from .sim import run_simulate

    res = run_simulate(a.airframe, a.model, a.maneuvers, a.out, seed=a.seed, truth_path=a.truth)
    print(f"wrote {a.out} ({res.t[-1] - res.t[0]:.0f} s of flight)")
    if a.live:
        from .live.stream import stream_tlog

        print(f"streamed {stream_tlog(a.out, a.live, a.speed)} packets to {a.live}")
    return 0


def _check_fit(a: argparse.Namespace) -> None:
    from .airframe import load_airframe
    from .outdir import check_out_file

    _check_window(a)
    from .diagnose.run import check_fit_air_pitch

    check_fit_air_pitch(a.air_pitch == "on", a.gust_rates)
    load_airframe(a.airframe)
    out = Path(a.out)
    check_out_file(out, "--out")
    check_out_file(out.with_suffix(".fit.json"), "--out")


def _cmd_fit(a: argparse.Namespace) -> int:
    from .diagnose import run_fit

    _stated_lift_level(a)
    run_fit(a.log, a.airframe, a.out, t_from=a.t_from, t_to=a.t_to, notify=_say, gust_rates=a.gust_rates,
            air_roll_train=None if a.air_roll is None else a.air_roll == "on", profile_beta=a.beta_profile == "on",
            air_pitch=a.air_pitch == "on")
    print(f"wrote {a.out}")
    return 0


def _check_diagnose(a: argparse.Namespace) -> None:
    from .airframe import load_airframe
    from .diagnose.run import DIAGNOSE_OUTPUTS
    from .outdir import check_out_dir
    from .sim.model_file import load_model

    _check_window(a)
    load_airframe(a.airframe)
    load_model(a.model)
    from .errors import InputError

    for r in a.reference or []:
        if not Path(r).is_file():
            raise InputError(f"--reference {r}: no such log file")
    check_out_dir(a.out, "--out", DIAGNOSE_OUTPUTS)


def _cmd_diagnose(a: argparse.Namespace) -> int:
    from .diagnose import run_diagnose

    diag = run_diagnose(a.log, a.airframe, a.model, a.out, t_from=a.t_from, t_to=a.t_to, search=a.search,
                        notify=_say, references=[] if a.no_reference else a.reference,
                        alpha_level=a.alpha_level)
    findings = diag.get("findings", []) if isinstance(diag, dict) else getattr(diag, "findings", [])
    print(f"wrote {Path(a.out) / 'diagnosis.json'}: {len(findings)} finding(s)")
    from .diagnose.report import pitot_console_lines

    for line in pitot_console_lines(diag.get("data", {}) if isinstance(diag, dict) else getattr(diag, "data", {}),
                                    findings):
        print(line)
    return 0


def _cmd_listen(a: argparse.Namespace) -> int:
    from .live.cli import cmd_listen

    return cmd_listen(a)


def _cmd_campaign(a: argparse.Namespace) -> int:
    from .campaign import run_campaign_cli
    from .outdir import StagedDir

    with StagedDir(a.out, "campaign", ("campaign.json", "campaign.md", "campaign.png")) as stage:
        rc = run_campaign_cli(a.airframe, a.model, a.flights, a.seeds, a.out, a.refit, write_to=stage.path,
                              gp_noise=a.gp_noise)
    return rc


def _cmd_predict(a: argparse.Namespace) -> int:
    from .outdir import StagedFiles
    from .predict import run_predict

    with StagedFiles(a.out) as stage:   # the CSV appears complete or not at all
        pred = run_predict(a.model_dir, a.inputs, stage.path(a.out))
    print(f"wrote {a.out} ({len(pred.X)} conditions, {', '.join(pred.outputs)})")
    return 0


def _check_listen(a: argparse.Namespace) -> None:
    from .options import check_input_file

    check_input_file(a.airframe, "--airframe", "an airframe TOML file (docs/airframe.md)")
    out = Path(a.out)
    if out.exists() and not out.is_dir():
        from .errors import InputError

        raise InputError(f"--out {out}: is an existing file; expected a folder for raw.tlog and the session's "
                         "outputs (an existing raw.tlog there is appended to, never overwritten)")


def _check_campaign(a: argparse.Namespace) -> None:
    from .options import check_input_file
    from .outdir import check_out_dir

    check_input_file(a.airframe, "--airframe", "an airframe TOML file with a [limits] table (docs/airframe.md)")
    check_input_file(a.model, "--model", "a truth aerodynamic model TOML file (docs/model-file.md)")
    check_out_dir(a.out, "--out", owned=("campaign.json", "campaign.md", "campaign.png"))


def _check_predict(a: argparse.Namespace) -> None:
    from .options import check_input_file
    from .outdir import check_out_file

    check_input_file(a.inputs, "--inputs", "a CSV of flight conditions (docs/cli.md, predict)")
    check_out_file(a.out, "--out")


COMMANDS = {"replay": _cmd_replay, "simulate": _cmd_simulate, "fit": _cmd_fit, "diagnose": _cmd_diagnose,
            "listen": _cmd_listen, "campaign": _cmd_campaign, "predict": _cmd_predict}
#: Checks of every option and path, run before any work (a command without one checks inside its job).
CHECKS = {"replay": _check_replay, "simulate": _check_simulate, "fit": _check_fit, "diagnose": _check_diagnose,
          "listen": _check_listen, "campaign": _check_campaign, "predict": _check_predict}


def _sigterm_as_interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def main(argv: list[str] | None = None, handle_signals: bool = True) -> int:
    """Run the CLI; returns the exit code (0 ok, 1 internal error, 2 user error; a signal ends the
    process itself with 130 for SIGINT, 143 for SIGTERM).

    Args:
        argv: the arguments (None: ``sys.argv[1:]``).
        handle_signals: install :mod:`gcs_sysid.stopping` (SIGINT/SIGTERM end the process at once);
            False for callers that keep their own handlers (tests running commands in-process).
    """
    from . import stopping

    try:
        return _main(argv, handle_signals)
    except stopping.Stopped:   # a signal: the watcher thread cleans up and ends the process
        stopping.park()
        raise   # not reached


def _main(argv: list[str] | None, handle_signals: bool) -> int:
    import threading

    from . import stopping

    ap = build_parser()
    a = ap.parse_args(argv)
    if handle_signals and threading.current_thread() is threading.main_thread():
        if a.command == "listen":
            # a live session ends on Ctrl-C by writing its report (gcs_sysid.live.session): SIGTERM does the same
            import signal

            signal.signal(signal.SIGTERM, _sigterm_as_interrupt)
        else:
            stopping.install()
    try:
        with warnings.catch_warnings():
            # numerical warnings (overflow, invalid value in a reduction ...) never reach the console: the
            # stages turn real numerical problems into notes with their cause
            warnings.simplefilter("ignore")
            if a.command in CHECKS:
                CHECKS[a.command](a)
            if a.command not in ("replay", "listen"):   # these set it up themselves, once its worker is decoding
                # (so that importing JAX overlaps the decoding)
                from .jaxconfig import enable_compilation_cache, enable_x64, limit_blas_threads

                enable_x64()
                limit_blas_threads(1)        # small matrices: BLAS threading costs more than it gains
                enable_compilation_cache()   # later runs load compiled JAX programs instead of recompiling
            return COMMANDS[a.command](a)
    except SysidError as e:
        if a.debug:
            raise
        print(f"gcs-sysid: error: {e}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:   # only without stopping.install (listen, or not the main thread)
        print("gcs-sysid: interrupted", file=sys.stderr)
        return 130
    except OSError as e:   # a file the user named cannot be written or read (disk full, permissions)
        if a.debug:
            raise
        where = f"{e.filename}: " if e.filename else ""
        print(f"gcs-sysid: error: {where}{e.strerror or e}", file=sys.stderr)
        return EXIT_USER_ERROR
    except Exception as e:  # a bug: say so in one line, keep the traceback behind --debug
        if a.debug:
            raise
        print(f"gcs-sysid: internal error: {e.__class__.__name__}: {e} (run with --debug for the traceback)",
              file=sys.stderr)
        return EXIT_INTERNAL_ERROR


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
