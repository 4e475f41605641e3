"""The states' ``alpha_dot`` (force equations, gcs_sysid.estimation.alpharate) against the rate JSBSim's
aerodynamics reads (``aero/alphadot-rad_sec``: air-relative velocity, ground-velocity derivative),
rebuilt from the truth file, on the fast c172x flight. The derivative of the reconstructed alpha is
scored too: it carries the gusts' derivative and is the worse estimate of that rate.

Thresholds FROZEN 2026-11-22 (branch i8-j3cub) from the first measurement on the J3Cub's flights (light,
seeds 1-3: correlation 0.997-0.998, RMS error 7-7.5 % of the signal) with a margin; not measured on
the c172x before they were set.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import load_truth
from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation import estimate_states
from gcs_sysid.telemetry import read_log

MIN_CORRELATION = 0.98
MAX_ERROR_FRACTION = 0.2


def _truth_alpha_rate(truth, t):
    F = truth.fields
    ip = lambda x: np.interp(t, truth.t, x, left=np.nan, right=np.nan)   # noqa: E731
    V, al, be = ip(F["V"]), ip(F["alpha"]), ip(F["beta"])
    ua, wa = V * np.cos(al) * np.cos(be), V * np.sin(al) * np.cos(be)
    udot, wdot = ip(np.gradient(F["u"], truth.t)), ip(np.gradient(F["w"], truth.t))
    return (ua * wdot - wa * udot) / (ua**2 + wa**2)


@pytest.mark.slow
def test_alpha_rate_against_jsbsim(fast_flight):
    af = load_airframe(fast_flight.airframe)
    st = estimate_states(read_log(fast_flight.tlog), af)
    truth = load_truth(fast_flight.truth)
    ref = _truth_alpha_rate(truth, st.t)
    est = st.data["alpha_dot"]
    m = st.valid & np.isfinite(ref) & np.isfinite(est)
    assert m.mean() > 0.8
    rms = lambda x: float(np.sqrt(np.mean(x**2)))   # noqa: E731
    corr = float(np.corrcoef(est[m], ref[m])[0, 1])
    frac = rms(est[m] - ref[m]) / rms(ref[m])
    print(f"alpha_dot: correlation {corr:.4f}, RMS error {100 * frac:.1f} % of the signal")
    assert corr > MIN_CORRELATION and frac < MAX_ERROR_FRACTION, (corr, frac)
    # differentiating the reconstructed alpha instead: its error is several times larger
    diff = np.gradient(st.data["alpha"], st.t)
    print(f"d(alpha)/dt: RMS error {100 * rms(diff[m] - ref[m]) / rms(ref[m]):.1f} %")
    assert rms(diff[m] - ref[m]) > 2.0 * rms(est[m] - ref[m])


def test_the_truths_alpha_dot_is_jsbsims_and_the_rebuild_matches_it(fast_flight):
    """Since the sixty-ninth session the truth keeps JSBSim's own ``aero/alphadot-rad_sec`` (what the XMLs'
    ``Cm_alphadot`` terms read); ``eval_jsbsim.true_alpha_dot``, which issue 8's scores at exact conditions use, rebuilds
    it from the ground velocity's derivative. Measured on the navion and b737 light s1 flights: correlation 0.998 and
    0.999, RMS difference 6.5 and 4.4 % of the signal; on the fast flight 0.999 and 4.7 %. Asked here: above 0.99 and
    below 15 % (thresholds set from those measurements)."""
    from benchmarks.eval_jsbsim import true_alpha_dot

    truth = load_truth(fast_flight.truth)
    assert "alpha_dot" in truth.fields
    own, rebuilt = truth.fields["alpha_dot"], true_alpha_dot(truth)
    ok = np.isfinite(own) & np.isfinite(rebuilt)
    assert ok.mean() > 0.99 and np.std(own[ok]) > 0
    assert np.corrcoef(own[ok], rebuilt[ok])[0, 1] > 0.99
    assert np.sqrt(np.mean((own[ok] - rebuilt[ok]) ** 2)) < 0.15 * np.std(own[ok])
