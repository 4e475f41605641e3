"""Hold an aero model against measured data: equation-error fit, stepwise regression, diagnosis.

Entry points:

- :func:`fit_model` (``CoefficientTable`` -> ``AeroModel`` + :class:`FitReport`) and
  :func:`run_fit` (log -> model file): ``gcs-sysid fit``.
- :func:`diagnose` (table, airframe, model, states -> :class:`Diagnosis`) and
  :func:`run_diagnose` (log -> ``diagnosis.json``, ``model_extended.toml``, ``report.html``):
  ``gcs-sysid diagnose``.
- :func:`ols`, :func:`stepwise`: least squares with coloured-residual standard errors
  (Morelli and Klein, *Aircraft System Identification*, ch. 5).
- :func:`detect_faults` (flight, airframe -> ``stuck:<control>`` / ``thrust_loss`` findings read from
  the servo outputs against the autopilot's demand); :func:`strip_tlog` (a tlog without
  PARAM_VALUE / STATUSTEXT, for blind evaluation); :func:`search_residual` (wide-library search).

Documentation: ``docs/diagnose.md``.
"""

from .core import Diagnosis, diagnose
from .faults import FaultThresholds, detect_faults
from .fit import FitReport, fit_model
from .regression import OLSResult, StepwiseResult, ols, stepwise
from .run import run_diagnose, run_fit
from .search import search_residual
from .strip import strip_tlog

__all__ = ["Diagnosis", "diagnose", "FitReport", "fit_model", "OLSResult", "StepwiseResult", "ols", "stepwise",
           "run_diagnose", "run_fit", "FaultThresholds", "detect_faults", "search_residual", "strip_tlog"]
