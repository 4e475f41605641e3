"""Excitation maneuvers that would shrink the model's uncertainty where the confidence map flags it,
inside the aircraft's limits, for every axis.

- :mod:`.limits`: the airframe's ``[limits]`` (defaulted from the flown envelope) and the peak check.
- :mod:`.linear`: derivative estimates, short-period and lateral-directional models, modes.
- :mod:`.design`: one candidate: safe 1-g condition, doublet / 3-2-1-1 / orthogonal multisine,
  amplitude within the limits, expected peaks, the regressor trajectory.
- :mod:`.suggest`: quality gate, weighting (moments first), ranking by the model's expected
  variance reduction, grouping of flagged regions by fix.
- :mod:`.suggestion`: :class:`Suggestion` (data, JSON) and :class:`SuggestionList` (with context).
- :mod:`.flyplan`: a plan file (``docs/sim.md``) that ``gcs-sysid simulate`` flies.

Details and sources: ``docs/maneuvers.md``.
"""

from .design import ManeuverConfig
from .flyplan import plan_document, write_plan
from .limits import EffectiveLimits, check_peaks, effective_limits
from .linear import derivative_estimates, linear_models, modes
from .suggest import SURFACE_OF, quality_gate, suggest_maneuvers
from .suggestion import SURFACE_NAMES, Suggestion, SuggestionList

__all__ = ["ManeuverConfig", "Suggestion", "SuggestionList", "suggest_maneuvers", "derivative_estimates",
           "linear_models", "modes", "SURFACE_OF", "SURFACE_NAMES", "EffectiveLimits", "effective_limits",
           "check_peaks", "quality_gate", "plan_document", "write_plan"]
