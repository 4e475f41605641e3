"""Settings of the closed-loop campaign (:func:`gcs_sysid.campaign.run_campaign`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["CampaignConfig", "COEF_NOISE"]

#: estimation error the replay leaves on the sample flight (held-out residuals of a well-fitted model).
COEF_NOISE = np.array([0.004, 0.003, 0.01, 0.0006, 0.0015, 0.0004])


@dataclass(frozen=True)
class CampaignConfig:
    """Settings of :func:`run_campaign`.

    Attributes:
        flights: flights per arm including the first (>= 2).
        seeds: one campaign per seed (turbulence, noise, GP subsets).
        flight_s: length of every flight, s (one compiled simulation).
        w20_mps: turbulence at 20 ft, m/s (MIL-HDBK-1797 light is 7.7; calm sysid air ~1.5).
        max_suggestions: suggestions flown per flight, at most.
        rate_hz: rate of the identification data.
        n_inducing: inducing points of the GP.
        gp_steps: Adam steps of the GP fit.
        local: the GP's local layer.
        targets: coefficients to target (None: all, moments first).
        refit: re-learn the GP (hyperparameters, inducing points) on all data after each flight
            instead of the incremental update (for comparison; the product updates incrementally).
        gp_noise: the GP's output noise, a name of :data:`gcs_sysid.pipeline.GP_NOISE_MODES` (``"independent"``: one
            variance per output, ``GPConfig()``'s; ``"learned"``: the replay's default, a ``P x P`` noise covariance
            learned with the hyperparameters, only its variances in the posterior; ``docs/gp.md``, "Noise"). The
            campaign's coefficient noise ``COEF_NOISE`` is drawn independently per coefficient, so ``learned`` has
            no cross-correlated noise to find here (``docs/campaign-results.md``).
    """

    flights: int = 4
    seeds: tuple[int, ...] = (1,)
    flight_s: float = 90.0
    w20_mps: float = 1.5
    max_suggestions: int = 4
    rate_hz: float = 10.0
    n_inducing: int = 48
    gp_steps: int = 80
    local: bool = True
    targets: tuple[str, ...] | None = None
    refit: bool = False
    gp_noise: str = "independent"

    def __post_init__(self):
        if self.flights < 2:
            raise InputError(f"--flights must be at least 2 (one standard, then suggested), got {self.flights}")
        if not self.seeds:
            raise InputError("at least one seed is needed")
        if not self.flight_s >= 82.0:
            raise InputError(f"flight length must be at least 82 s (the validation flight's), got {self.flight_s}")
        from ..pipeline import gp_noise_fields

        gp_noise_fields(self.gp_noise)      # InputError on an unknown name


