"""The split of a change's error in ``benchmarks/effect_bias_split.py``, on synthetic flights with a known cause."""

import numpy as np

from benchmarks.effect_bias_split import one_term_change, split
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.sim.model_file import model_from_dict

CN, DA, BETA = COEFFICIENTS.index("Cn"), REGRESSORS.index("delta_a"), REGRESSORS.index("beta")
CN_BETA, CN_DA, CHANGE = 0.10, 0.004, -0.06


def _flight(change: float, seed: int, beta_read_low: float, n: int = 4000) -> dict[str, np.ndarray]:
    """Exact and pipeline arrays of a lateral flight. The aileron drives sideslip (more when ``change`` adds adverse
    yaw); the pipeline's sideslip reads the aileron-driven part ``beta_read_low`` too low (a lagged aiding's error),
    the rest exactly; its Cn is the exact one."""
    rng = np.random.default_rng(seed)
    Xt = np.zeros((n, len(REGRESSORS)))
    da = np.convolve(rng.normal(size=n), np.ones(25) / 25, "same")
    gust = np.convolve(rng.normal(size=n), np.ones(40) / 40, "same")
    driven = (0.2 - 5.0 * change) * da
    Xt[:, DA], Xt[:, BETA] = da, gust + driven
    Yt = np.zeros((n, len(COEFFICIENTS)))
    Yt[:, CN] = CN_BETA * Xt[:, BETA] + (CN_DA + change) * da + rng.normal(scale=1e-4, size=n)
    X = Xt.copy()
    X[:, BETA] = gust + (1.0 - beta_read_low) * driven
    return {"X": X, "Y": Yt.copy(), "Xt": Xt, "Yt": Yt}


def _model():
    return model_from_dict({"name": "test", "Cn": {"beta": CN_BETA, "delta_a": CN_DA}})


def test_the_one_term_change_is_the_difference_of_the_two_slopes():
    col = {"effect": np.arange(10.0), "reference": np.arange(10.0)}
    res = {"effect": 3.0 * col["effect"] + 1.0, "reference": 2.0 * col["reference"] - 4.0}
    assert abs(one_term_change(res, col) - 1.0) < 1e-12


def test_a_sideslip_that_reads_the_aileron_driven_part_low_is_named_as_the_cause():
    out = split(_flight(CHANGE, 1, 0.3), _flight(0.0, 2, 0.3), _model())
    for way in ("model at truth", "linear at truth", "linear, true beta"):
        assert abs(out[way] - CHANGE) < 0.05 * abs(CHANGE), (way, out)
    # the pipeline's sideslip misses 0.3 of the effect flight's extra aileron-driven sideslip (-5 CHANGE per unit of
    # delta_a), whose moment CN_BETA times it then reads as a smaller change
    expected = CHANGE + CN_BETA * 0.3 * (-5.0 * CHANGE)
    assert abs(out["linear, pipeline"] - expected) < 0.002, (expected, out)
    assert abs(out["linear, pipeline"] - CHANGE) > 0.1 * abs(CHANGE), out


def test_an_exact_sideslip_leaves_no_bias_to_name():
    out = split(_flight(CHANGE, 1, 0.0), _flight(0.0, 2, 0.0), _model())
    assert all(abs(v - CHANGE) < 0.05 * abs(CHANGE) for v in out.values()), out
