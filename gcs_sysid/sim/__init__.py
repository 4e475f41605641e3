"""The project's 6-DOF fixed-wing simulation (JAX), its aero model file and tlog writer.

Entry points: :func:`simulate` (fly a plan, get truth and sensors), :func:`propagate`
(deterministic response to given controls), :func:`write_tlog` (ArduPilot-like telemetry
log), :func:`run_simulate` (files in, tlog out: the ``gcs-sysid simulate`` command), the
model file API (:func:`load_model`, :func:`save_model`, :class:`AeroModel`) and plans
(:func:`load_plan`, :class:`Effects`). Formats: ``docs/sim.md``, ``docs/model-file.md``.
"""

from .effects import CONTROL_NAMES, Effects, effects_from_dict
from .model_file import VOCABULARY, AeroModel, canonical_term, load_model, model_from_dict, parse_term, save_model
from .plan import Maneuver, Plan, Setpoint, load_plan, plan_from_dict
from .run import run_simulate
from .flight import TRUTH_KEYS, SimResult, control_limits, propagate, simulate, state_from_measurements
from .tlog import write_tlog
from .trim import Trim, trim

__all__ = [
    "CONTROL_NAMES", "Effects", "effects_from_dict", "VOCABULARY", "AeroModel", "canonical_term", "load_model",
    "model_from_dict", "parse_term", "save_model", "Maneuver", "Plan", "Setpoint", "load_plan", "plan_from_dict",
    "run_simulate", "TRUTH_KEYS", "SimResult", "control_limits", "propagate", "simulate",
    "state_from_measurements", "write_tlog", "Trim", "trim",
]
