"""Command-line interface: ``gcs-sysid replay | simulate | fit | diagnose | predict | campaign | listen``.

Errors a user can cause (bad file, missing field, data that cannot support an
estimate) print one line ``gcs-sysid: error: ...`` on stderr and exit with code 2,
without a traceback. ``--debug`` shows the traceback of any error.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import SysidError

__all__ = ["main", "build_parser"]

EXIT_USER_ERROR = 2
EXIT_INTERNAL_ERROR = 1


def _window_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--from", dest="t_from", type=float, default=None, metavar="S",
                   help="start of the window, vehicle time since boot in s")
    p.add_argument("--to", dest="t_to", type=float, default=None, metavar="S",
                   help="end of the window, vehicle time since boot in s")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (documented in docs/cli.md)."""
    ap = argparse.ArgumentParser(
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
    _window_args(f)

    d = sub.add_parser("diagnose", help="compare the simulation model with measured data, name the cause")
    d.add_argument("log")
    d.add_argument("--airframe", required=True)
    d.add_argument("--model", required=True, help="the simulation's aerodynamic model TOML file")
    d.add_argument("--out", required=True, help="output directory")
    d.add_argument("--search", action="store_true", help="also search a wide term library (docs/diagnose.md)")
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

    from .live.cli import add_listen_parser

    add_listen_parser(sub)
    return ap


def _cmd_replay(a: argparse.Namespace) -> int:
    from .pipeline import ReplayOptions, run_replay

    opts = ReplayOptions(rate_hz=a.rate, holdout=a.holdout, t_from=a.t_from, t_to=a.t_to,
                         model_in=a.model_in, n_inducing=a.inducing, progress=not a.quiet)
    result = run_replay(a.log, a.airframe, a.out, opts)
    out = Path(a.out)
    print(f"report: {out / 'report.html'}")
    for name, m in result.metrics.items():
        ok, why = result.identifiable.get(name, (True, ""))
        if ok and m.get("n_heldout", 0) > 0:
            print(f"  {name:3s} held-out error {m['error_pct_heldout']:6.1f} %")
        else:
            print(f"  {name:3s} not identified: {why}")
    if result.suggestions:
        print(f"next maneuver: {result.suggestions[0].reason}")
    return 0


def _cmd_simulate(a: argparse.Namespace) -> int:
    from .sim import run_simulate

    res = run_simulate(a.airframe, a.model, a.maneuvers, a.out, seed=a.seed, truth_path=a.truth)
    print(f"wrote {a.out} ({res.t[-1] - res.t[0]:.0f} s of flight)")
    if a.live:
        from .live.stream import stream_tlog

        print(f"streamed {stream_tlog(a.out, a.live, a.speed)} packets to {a.live}")
    return 0


def _cmd_fit(a: argparse.Namespace) -> int:
    from .diagnose import run_fit

    run_fit(a.log, a.airframe, a.out, t_from=a.t_from, t_to=a.t_to)
    print(f"wrote {a.out}")
    return 0


def _cmd_diagnose(a: argparse.Namespace) -> int:
    from .diagnose import run_diagnose

    diag = run_diagnose(a.log, a.airframe, a.model, a.out, t_from=a.t_from, t_to=a.t_to, search=a.search)
    findings = diag.get("findings", []) if isinstance(diag, dict) else getattr(diag, "findings", [])
    print(f"wrote {Path(a.out) / 'diagnosis.json'}: {len(findings)} finding(s)")
    return 0


def _cmd_listen(a: argparse.Namespace) -> int:
    from .live.cli import cmd_listen

    return cmd_listen(a)


def _cmd_campaign(a: argparse.Namespace) -> int:
    from .campaign import run_campaign_cli

    return run_campaign_cli(a.airframe, a.model, a.flights, a.seeds, a.out, a.refit)


def _cmd_predict(a: argparse.Namespace) -> int:
    from .predict import run_predict

    pred = run_predict(a.model_dir, a.inputs, a.out)
    print(f"wrote {a.out} ({len(pred.X)} conditions, {', '.join(pred.outputs)})")
    return 0


COMMANDS = {"replay": _cmd_replay, "simulate": _cmd_simulate, "fit": _cmd_fit, "diagnose": _cmd_diagnose,
            "listen": _cmd_listen, "campaign": _cmd_campaign, "predict": _cmd_predict}


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the exit code (0 ok, 2 user error, 1 internal error)."""
    ap = build_parser()
    a = ap.parse_args(argv)
    if a.command not in ("replay", "listen"):   # replay and listen set these up themselves (so that
        # importing JAX overlaps the decoding)
        from .jaxconfig import enable_compilation_cache, enable_x64, limit_blas_threads

        enable_x64()
        limit_blas_threads(1)        # small matrices: BLAS threading costs more than it gains (docs/gp.md)
        enable_compilation_cache()   # later runs load compiled JAX programs instead of recompiling
    try:
        return COMMANDS[a.command](a)
    except SysidError as e:
        if a.debug:
            raise
        print(f"gcs-sysid: error: {e}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("gcs-sysid: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # a bug: say so in one line, keep the traceback behind --debug
        if a.debug:
            raise
        print(f"gcs-sysid: internal error: {e.__class__.__name__}: {e} (run with --debug for the traceback)",
              file=sys.stderr)
        return EXIT_INTERNAL_ERROR


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
