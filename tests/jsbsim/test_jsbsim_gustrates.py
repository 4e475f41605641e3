"""Gust rates on a JSBSim flight: the rates from the estimator's reconstructed gusts against the
same equations fed with JSBSim's exact wind (one estimation of the shared fast flight, ~3 s)."""

import numpy as np
from benchmarks.jsbsim_harness import load_truth
from gcs_sysid.aero import compute_coefficients
from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation import estimate_states
from gcs_sysid.estimation.ekf import dcm
from gcs_sysid.estimation.gustrates import gust_rates
from gcs_sysid.telemetry import read_log


def test_estimated_gust_rates_follow_the_exact_gusts(fast_flight):
    af = load_airframe(fast_flight.airframe)
    st = estimate_states(read_log(fast_flight.tlog), af)
    tr = load_truth(fast_flight.truth)
    t, v = st.t, st.valid
    dt = float(t[1] - t[0])
    ip = lambda k: np.interp(t, tr.t, tr.fields[k])   # noqa: E731
    est = gust_rates(dt, dcm(st.data["phi"], st.data["theta"], st.data["psi"]),
                     np.stack([st.data[k] for k in ("wn", "we", "wd")], 1), st.data["V"], af.b, "path").rates
    exact = gust_rates(dt, dcm(ip("phi"), ip("theta"), ip("psi")), np.stack([ip(k) for k in ("wn", "we", "wd")], 1),
                       ip("V"), af.b, "path").rates
    # 90 s c172x light flights: 0.92 (q_g, from the aided vertical gust) and 0.68 (r_g, lateral)
    assert np.corrcoef(est[v, 1], exact[v, 1])[0, 1] > 0.8
    assert np.corrcoef(est[v, 2], exact[v, 2])[0, 1] > 0.4
    assert 0.7 < est[v, 1].std() / exact[v, 1].std() < 1.4
    tab, air = compute_coefficients(st, af), compute_coefficients(st, af, gust_rates="path")
    np.testing.assert_allclose(air.Y, tab.Y)
    np.testing.assert_allclose(air.X[:, 2], tab.X[:, 2])        # p_hat: p_g not observable
    assert np.nanstd(air.X[v, 3] - tab.X[v, 3]) > 0.0
