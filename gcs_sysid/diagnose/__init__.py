"""Hold an aero model against measured data: equation-error fit, stepwise regression, diagnosis.

Entry points:

- :func:`fit_model` (``CoefficientTable`` -> ``AeroModel`` + :class:`FitReport`) and
  :func:`run_fit` (log -> model file): ``gcs-sysid fit``.
- :func:`diagnose` (table, airframe, model, states -> :class:`Diagnosis`) and
  :func:`run_diagnose` (log -> ``diagnosis.json``, ``model_extended.toml``, ``report.html``):
  ``gcs-sysid diagnose``.
- :func:`ols`, :func:`stepwise`: least squares with coloured-residual standard errors
  (Morelli and Klein, *Aircraft System Identification*, ch. 5).

Documentation: ``docs/diagnose.md``.
"""

from .core import Diagnosis, diagnose
from .fit import FitReport, fit_model
from .regression import OLSResult, StepwiseResult, ols, stepwise
from .run import run_diagnose, run_fit

__all__ = ["Diagnosis", "diagnose", "FitReport", "fit_model", "OLSResult", "StepwiseResult", "ols", "stepwise",
           "run_diagnose", "run_fit"]
