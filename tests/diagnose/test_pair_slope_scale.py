"""Alpha's scale uncertainty of a flight against its reference from the two aidings' lift slopes
(``sparse.THRESHOLDS["coverage_scale_pair"] = "slopes"``, :func:`gcs_sysid.diagnose.uncertainty.pair_slope_scale`).

The aided alpha's excursions are the normal force's over the aiding's ``CZ_alpha``, so two flights aided with
``c_f`` and ``c_ref`` differ in alpha scale by ``c_ref / c_f - 1``; the stated ``AxisFit.scale_sigma`` (the aided and
the kinematic angle's disagreement) is, on a gusty flight, the gust's share of the angle (JSBSim c172p light: 0.42 and
0.88 on the reference and the seed-2 flight, whose slopes -4.945 and -4.996 differ by 1 %). Synthetic fits, < 0.1 s.
"""

import numpy as np
import pytest

from gcs_sysid.diagnose.sparse import THRESHOLDS
from gcs_sysid.diagnose.uncertainty import air_data_uncertainty, pair_slope_scale
from gcs_sysid.estimation.airangles import AxisFit

COLS = ("1", "alpha", "(alpha - alpha0)^2", "q_hat", "delta_e")


def _fit(cza: float, se: float, scale_sigma: float) -> AxisFit:
    f = AxisFit("alpha", True, "", COLS, np.array([-0.2, cza, 1.0, -0.5, -0.15]),
                np.array([np.nan, se, 0.1, 0.1, np.nan]), scale_sigma=scale_sigma, bias_sigma=0.01)
    return f


def test_the_pair_scale_is_the_slopes_ratio_not_the_gust_share():
    ref, flt = _fit(-4.945, 0.007, 0.42), _fit(-4.996, 0.012, 0.88)
    beta = AxisFit("beta", True, "", ("1", "beta"), np.array([0.0, -0.3]), np.array([np.nan, 0.01]), scale_sigma=0.2)
    want = np.sqrt((4.945 / 4.996 - 1) ** 2 + (0.012 / 4.996) ** 2 + (0.007 / 4.945) ** 2)
    assert pair_slope_scale(flt, ref) == pytest.approx(want, rel=1e-9)
    assert 0.005 < want < 0.02
    fits, rfits = {"alpha": flt, "beta": beta}, {"alpha": ref, "beta": beta}
    quad = air_data_uncertainty(fits, rfits)
    assert quad["alpha"]["scale"] > 0.9          # the function's default: both flights' own statements in quadrature
    new = air_data_uncertainty(fits, rfits, pair_scale="slopes")
    assert new["alpha"]["scale_null"] == pytest.approx(want, rel=1e-9)     # read under no change only
    assert new["alpha"]["scale"] == quad["alpha"]["scale"]    # a named change's type B keeps the quadrature
    assert "scale_null" not in quad["alpha"]
    assert new["beta"] == quad["beta"]           # beta is unchanged
    assert new["alpha"]["offset_rad"] == quad["alpha"]["offset_rad"]
    # the sign of the slopes' difference does not matter; an unaided axis falls back to the quadrature
    assert pair_slope_scale(ref, flt) == pytest.approx(np.sqrt((4.996 / 4.945 - 1) ** 2 + (0.012 / 4.996) ** 2
                                                               + (0.007 / 4.945) ** 2), rel=1e-9)
    off = AxisFit("alpha", False, "not identified")
    assert pair_slope_scale(off, ref) is None
    assert "scale_null" not in air_data_uncertainty({"alpha": off}, rfits, pair_scale="slopes")["alpha"]
    with pytest.raises(ValueError):
        air_data_uncertainty(fits, rfits, pair_scale="sum")
    # the diagnosis's default since the forty-first session (the function's own default stays the quadrature)
    assert THRESHOLDS["coverage_scale_pair"] == "slopes"
