"""``gcs-sysid simulate``: airframe, model and plan files in, telemetry log out."""

from __future__ import annotations

from pathlib import Path

from ..airframe import load_airframe
from ..signals import check_amplitudes
from ..outdir import StagedFiles
from .model_file import load_model
from .plan import load_plan
from .flight import SimResult, simulate
from .tlog import write_tlog

__all__ = ["run_simulate"]


def run_simulate(airframe_path: str | Path, model_path: str | Path, plan_path: str | Path, out_path: str | Path,
                 seed: int | None = None, truth_path: str | Path | None = None) -> SimResult:
    """Simulate the plan and write the tlog (and, optionally, the truth ``.npz``).

    Args:
        airframe_path: airframe TOML (``docs/airframe.md``).
        model_path: aero model TOML (``docs/model-file.md``).
        plan_path: maneuver plan TOML (``docs/sim.md``).
        out_path: the .tlog to write.
        seed: overrides the plan's seed.
        truth_path: where to save the truth (``SimResult.save_truth``), or None.

    Returns:
        the :class:`SimResult`.

    Raises:
        InputError: a file is missing or malformed (one line naming the file and field), or a
            maneuver asks a surface for more than its travel.
        DataError: the aircraft cannot be trimmed at a setpoint of the plan.

    The files are written under temporary names beside their places and renamed into place at the
    end (:class:`gcs_sysid.outdir.StagedFiles`): a failed or interrupted run leaves earlier files as
    they were. ``--out`` and ``--truth`` are checked before the simulation starts.
    """
    stages = [StagedFiles(out_path, option="--out")]
    try:
        if truth_path is not None:
            if not str(truth_path).endswith(".npz"):   # numpy adds it; so does the final name
                truth_path = f"{truth_path}.npz"
            stages.append(StagedFiles(truth_path, option="--truth"))
        airframe = load_airframe(airframe_path)
        model = load_model(model_path)
        plan = load_plan(plan_path)
        check_amplitudes(plan.maneuvers, airframe.authority, plan.source or str(plan_path), airframe.name)
        result = simulate(airframe, model, plan, seed=seed)
        write_tlog(result, stages[0].path(out_path), airframe)
        if truth_path is not None:
            result.save_truth(stages[1].path(truth_path))
        for st in stages:
            st.commit()
    except BaseException:
        for st in stages:
            st.abort()
        raise
    return result
