"""``gcs-sysid listen CONNECTION --airframe A --out DIR`` (argument parsing; the work is in :mod:`.session`)."""

from __future__ import annotations

import argparse

__all__ = ["add_listen_parser", "cmd_listen"]


def add_listen_parser(sub) -> argparse.ArgumentParser:
    """Add the ``listen`` subcommand to the CLI's subparsers (documented in docs/live.md)."""
    p = sub.add_parser("listen", help="listen to a live MAVLink link (SITL, telemetry radio, router), learn while "
                                      "the aircraft flies, and speak back as a MAVLink component")
    p.add_argument("connection", help="pymavlink connection: udpin:0.0.0.0:14550, udpout:HOST:PORT, tcp:HOST:5760, "
                                      "tcpin:0.0.0.0:5760, /dev/ttyUSB0 (with --baud) or /dev/ttyUSB0,57600")
    p.add_argument("--airframe", required=True, help="airframe TOML file (docs/airframe.md)")
    p.add_argument("--out", required=True, help="output directory: raw.tlog, session.json, report.md, model/")
    p.add_argument("--baud", type=int, default=57600, help="serial baud rate (default 57600)")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="stop after S seconds (default: Ctrl-C)")
    p.add_argument("--window", type=float, default=30.0, metavar="S",
                   help="seconds of data smoothed per learning step (default 30)")
    p.add_argument("--step", type=float, default=10.0, metavar="S", help="seconds between learning steps (default 10)")
    p.add_argument("--lag", type=float, default=3.0, metavar="S",
                   help="newest seconds left for the next step, the smoother's future context (default 3)")
    p.add_argument("--min-rows", type=int, default=500, help="samples before the GP is first fitted (default 500)")
    p.add_argument("--inducing", type=int, default=None, help="inducing points of the global GP")
    p.add_argument("--gp-noise", default=None, choices=("learned", "independent", "diagonal", "full", "full-nstart"),
                   help="the GP's output noise: 'learned' (the default, as the replay's) learns the outputs' noise "
                        "correlation with the hyperparameters and keeps only its diagonal in the predictions; "
                        "'independent' one variance per output (the default until the twenty-sixth session); "
                        "docs/live.md, 'The GP's noise'")
    p.add_argument("--air-roll", default="on", choices=("on", "off"),
                   help="the air-rate pair in the learner: 'on' moves Cl's training target to the air-relative roll "
                        "rate with the replay's roll fit (made once on the first fit's rows, with its Dryden and "
                        "instruments' checks; refused: the gyro's rate for the whole session); default on (since the "
                        "sixty-sixth session; 'off': Cl learned at the gyro's rate); "
                        "docs/live.md, 'The air-rate pair'")
    p.add_argument("--lift-line", default="off", choices=("on", "off"),
                   help="carry a lift line across the learner's windows: each window's alpha level is set on the line "
                        "of the windows so far instead of its own 30 s of mean vertical wind, and at the end every "
                        "row is moved onto the line of all windows and learned again; default off; docs/live.md, "
                        "'The lift line carried across windows'")
    p.add_argument("--air-pitch", default="on", choices=("on", "off"),
                   help="each window's q_hat at the air-relative estimate, the gyro's less the pitch gust rate from "
                        "the reconstructed wind times its share in Cm fitted on the session's windows together (free "
                        "sign; applied only when the pooled fit shows it); default on (since the sixty-ninth "
                        "session; 'off': the gyro's q_hat); docs/live.md, 'The air-relative pitch rate in the "
                        "windows'")
    p.add_argument("--air-pitch-relearn", default="off", choices=("on", "off"),
                   help="with --air-pitch on: at the session's end move every learned row's q_hat to the share of "
                        "all windows (each window was learned at the share of its time) and learn the GP again; "
                        "default off; docs/live.md, 'The air-relative pitch rate in the windows'")
    p.add_argument("--alpha-profile", default="off", choices=("on", "off"),
                   help="the windows' alpha aiding takes the elevator's slope by the gust model's likelihood instead "
                        "of least squares (in closed loop least squares loads it with the gust's normal force, and "
                        "the model reads Cm_delta_e short); default off; docs/live.md, 'The lift line carried across "
                        "windows'")
    p.add_argument("--rate-errors", default=None, choices=("on", "off"),
                   help="the gyro rates' errors (the rolling gust's share of p_hat, the yaw gust rate's map of "
                        "r_hat) in the saved model's band at exact conditions, pooled over the windows with the "
                        "estimator's other stated regressor errors; default on, as the replay; docs/live.md, "
                        "'The band at exact conditions'")
    p.add_argument("--silence", type=float, default=30.0, metavar="S",
                   help="report the link as silent after S seconds without a packet (default 30)")
    p.add_argument("--no-learn", action="store_true", help="only log, monitor and request rates")
    p.add_argument("--no-request", action="store_true", help="do not ask the vehicle for message rates")
    p.add_argument("--no-component", action="store_true",
                   help="do not send HEARTBEAT/STATUSTEXT/NAMED_VALUE_FLOAT nor serve parameters")
    p.add_argument("--sysid", type=int, default=None, help="component's system id (default: the vehicle's)")
    p.add_argument("--compid", type=int, default=191, help="component id (default 191, onboard computer)")
    p.add_argument("--no-mavsdk", action="store_true",
                   help="serve parameters with pymavlink's PARAM protocol instead of MAVSDK's server")
    p.add_argument("--can", default=None, metavar="INTERFACE:CHANNEL",
                   help="also log and decode a DroneCAN bus (python-can: socketcan:can0, slcan:/dev/ttyACM0, "
                        "virtual:NAME) into DIR/can.log; needs the 'can' extra")
    p.add_argument("--quiet", action="store_true", help="no live console")
    return p


def cmd_listen(a: argparse.Namespace) -> int:
    """Run ``listen`` from parsed arguments; prints where the report went. Returns 0."""
    from ..errors import InputError
    from .learner import LearnOptions
    from .session import ListenOptions, run_listen

    for name, v in (("--sysid", a.sysid), ("--compid", a.compid)):
        if v is not None and not 1 <= v <= 255:
            raise InputError(f"{name} {v}: must lie in 1..255")
    learn = None if a.no_learn else LearnOptions(window_s=a.window, step_s=a.step, lag_s=a.lag,
                                                 min_rows=a.min_rows, n_inducing=a.inducing,
                                                 gp_noise=a.gp_noise, air_roll=a.air_roll == "on",
                                                 lift_line=a.lift_line == "on", air_pitch=a.air_pitch == "on",
                                                 air_pitch_relearn=a.air_pitch_relearn == "on",
                                                 alpha_profile=("delta_e",) if a.alpha_profile == "on" else None,
                                                 rate_errors=None if a.rate_errors is None else a.rate_errors == "on")
    opts = ListenOptions(connection=a.connection, baud=a.baud, learn=learn, request=not a.no_request,
                         component=not a.no_component, system_id=a.sysid, component_id=a.compid,
                         duration_s=a.duration, silence_s=a.silence, console=not a.quiet,
                         use_mavsdk=not a.no_mavsdk, can=a.can)
    snap = run_listen(a.airframe, a.out, opts)
    print(f"raw log: {snap['raw_log']} ({snap['raw_records']} packets); report: {a.out}/report.md")
    if snap.get("samples_learned") is not None:
        print(f"learned {snap['samples_learned']} samples; model: {snap.get('model', 'none')}")
    for c in snap.get("costs", []):
        print(f"  {c}")
    return 0
