"""Closed-loop test campaign in the project's simulation: fly, identify, suggest, fly the suggestions, repeat.

``gcs-sysid campaign --airframe A --model TRUE --flights N --out DIR`` runs, per seed:

1. a validation flight (orthogonal multisines on all surfaces at three airspeeds across the limits,
   no turbulence): its true regressors and the truth model's coefficients are the held-out test set;
2. flight 1: standard doublets on each axis at cruise; identify (:func:`gcs_sysid.gp.fit_gp`);
3. two arms from that model, flights 2..N each:
   *suggested*: map the confidence, :func:`gcs_sysid.maneuvers.suggest_maneuvers`, fly the top
   suggestions (as many as fit the flight) with :func:`gcs_sysid.sim.simulate`;
   *standard*: a standard doublet set with the same input-time and amplitude budget;
   after each flight the model is updated incrementally (``model.update``, then
   ``refresh_hyperparameters()``; sigma is read before the refresh, at the hyperparameters the
   flight was designed with);
4. per flight and arm: held-out error of each coefficient against the truth
   (``100 RMS(model - truth) / RMS(truth)``) and the mean latent predictive sigma in the regions
   flagged after flight 1; whether every suggestion respected the limits (designed peaks and the
   peaks the simulation actually flew).

Identification shortcut (said in the output): the coefficients are the simulation's true ones plus
white noise of the size the estimation chain leaves (``COEF_NOISE``), at 10 Hz; the regressors are
the true ones (turbulence included). The EKF/RTS chain itself is checked by the replay round trip
tests, and running it here would multiply the campaign's time by ten.
"""

from .config import COEF_NOISE, CampaignConfig
from .render import campaign_figure, campaign_markdown
from .run import run_campaign, run_campaign_cli

__all__ = ["CampaignConfig", "run_campaign", "run_campaign_cli", "COEF_NOISE", "campaign_figure", "campaign_markdown"]
