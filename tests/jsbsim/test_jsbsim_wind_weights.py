"""The wind fit weights its airspeed residuals with their own scatter, not with the pitot's noise.

The JSBSim Navion glides issue 9's sweep (120 s, light turbulence, the roster's reference flight: seed 100,
per-aircraft draws). Its dives reach 33 m/s down at 96 m/s airspeed, where JSBSim's vertical gusts (up to 6.5 m/s)
put 1-3 m/s between the pitot and ``|v_gps - w|`` for any horizontal wind. Weighted as 0.5-m/s pitot noise those
residuals outweighed the sideslip residuals, and the fit bought them down with a crosswind 9-23 m/s off from 20 to 60
s (4.6 m/s off on average; thirty-sixth session's lead). Weighted with their own RMS (``estimate.WIND_RESIDUAL_SCALE``,
thirty-eighth session; the default since the fortieth, when the rule written before fresh flights passed,
docs/benchmarks.md) the wind is within a metre per second of JSBSim's on average.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig
from gcs_sysid.estimation import estimate as estimate_mod
from gcs_sysid.estimation import estimate_states

from truth_fits import flown_flight


@pytest.fixture(scope="module")
def navion(tmp_path_factory):
    cfg = FlightConfig("navion", duration_s=120.0, seed=100, plan="sweep", sensor_draw="per_aircraft",
                       turbulence_draw="per_aircraft")
    return flown_flight(cfg, tmp_path_factory.mktemp("navion"))


def _mean_wind_error(states, truth) -> float:
    """|mean horizontal wind error| (m/s) against JSBSim's wind over the flight."""
    t = np.asarray(states.t)
    e = [np.nanmean(np.asarray(states.data[k]) - np.interp(t, truth["t"], truth[k])) for k in ("wn", "we")]
    return float(np.hypot(*e))


def _model_class_scatter(truth, window_s: float = estimate_mod.WIND_WINDOW_S, sigma_tas: float = 0.5) -> float:
    """RMS (m/s) of ``|v_ground - w| - V`` with ``w`` JSBSim's horizontal wind as the fit models it (its window means,
    linear between the window centres) and JSBSim's airspeed, with the pitot's noise in quadrature."""
    t = truth["t"]
    edges = np.arange(t[0], t[-1] + window_s, window_s)
    rows = [(t >= a) & (t < b) for a, b in zip(edges[:-1], edges[1:])]
    centres = [t[m].mean() for m in rows if m.any()]
    w = np.stack([np.interp(t, centres, [truth[k][m].mean() for m in rows if m.any()]) for k in ("wn", "we")]
                 + [0.0 * t], axis=1)
    vg = np.stack([truth["vn"], truth["ve"], truth["vd"]], axis=1)
    r = np.linalg.norm(vg - w, axis=1) - truth["V"]
    return float(np.sqrt(np.mean(r ** 2) + sigma_tas ** 2))


def test_the_navion_dive_keeps_its_wind_with_residual_weights(navion):
    """The default weighting (the residuals' own RMS) keeps the wind through the dive."""
    flight, af, truth = navion
    st = estimate_states(flight, af)
    assert _mean_wind_error(st, truth) < 1.0                     # measured 0.07 m/s
    note = next(n for n in st.notes if "airspeed residuals weighted with their own RMS" in n)
    sigma = float(note.split("own RMS, ")[1].split(" m/s")[0])
    # the weight is the scatter the fit's model class leaves at JSBSim's own wind: JSBSim's horizontal wind averaged
    # over the fit's 30-s windows and interpolated between their centres, against the pitot's 0.5 m/s noise
    # (2.375 m/s on this flight; the fit's 2.42 is 2 % above it)
    assert sigma == pytest.approx(_model_class_scatter(truth), rel=0.15)


def test_pitot_noise_weights_lose_the_wind_in_the_dive(navion, monkeypatch):
    """The weighting before the fortieth session (the pitot's noise), on the same flight: the crosswind several m/s
    off. This is what the default guards against."""
    flight, af, truth = navion
    monkeypatch.setattr(estimate_mod, "WIND_RESIDUAL_SCALE", False)
    st = estimate_states(flight, af)
    assert _mean_wind_error(st, truth) > 3.0                     # measured 4.6 m/s
    assert not any("own RMS" in n for n in st.notes)
