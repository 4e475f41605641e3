"""The pitot scale a flight's turns would give, and how sure it is (groundwork for a gated scale; no change to the
estimator).

For each ``LOG@AIRFRAME``: the estimator's inputs (GPS velocity, attitude, pitot TAS, autopilot wind) are taken
from :func:`gcs_sysid.estimation.estimate_states`, and the wind fit is run once more with **one** wind for the whole
flight and a pitot scale ``k`` (:func:`gcs_sysid.estimation.airdata.estimate_wind`, ``window_s`` = the flight, up
to 3000 points). It prints the track's mean resultant length (the fit only solves for ``k`` below 0.5), ``k``, its
white-noise 1-sigma, the effective sample size of the magnitude residual against the airspeed (Bartlett's product
formula, :func:`gcs_sysid.estimation.angleerrors.effective_n`, lags up to 30 s), the coloured 1-sigma
``se_white * sqrt(n / N_eff)`` and ``t = (k - 1) / se``. The estimator itself keeps ``k = 1``
(``estimate.PITOT_SCALE_FROM_TURNS``). The measured table is in docs/benchmarks.md, "Thirty-fourth session, lead".

    python benchmarks/pitot_scale_gate.py FLIGHT.tlog@data/airframes/X.toml [...]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))


def main(argv=None) -> int:
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.estimation import airdata
    from gcs_sysid.estimation import estimate as estimate_mod
    from gcs_sysid.estimation.angleerrors import effective_n
    from gcs_sysid.telemetry import read_log

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("flights", nargs="+", metavar="LOG@AIRFRAME")
    a = p.parse_args(argv)
    wind_fit = airdata.estimate_wind
    row: dict = {}

    def one_wind(t, v_ned, tas, use, **kw):
        u = use & np.isfinite(tas) & np.isfinite(v_ned).all(axis=1)
        trk = np.arctan2(v_ned[u, 1], v_ned[u, 0])
        row["resultant"] = float(np.hypot(np.cos(trk).mean(), np.sin(trk).mean()))
        w1 = wind_fit(t, v_ned, tas, use, **dict(kw, window_s=1e9, min_turn=0.5, max_points=3000))
        if np.isfinite(w1.scale_sigma):
            d = v_ned[u].copy()
            d[:, :2] -= w1.wind[u, :2]
            r = np.linalg.norm(d, axis=1) - w1.scale * tas[u]
            n_eff = effective_n(r, tas[u], int(30.0 / float(np.median(np.diff(t)))))
            se = w1.scale_sigma * np.sqrt(min(3000, int(u.sum())) / n_eff)
            row.update(k=w1.scale, se_white=w1.scale_sigma, n=int(u.sum()), n_eff=n_eff, se=se)
        return wind_fit(t, v_ned, tas, use, **kw)

    estimate_mod.estimate_wind = one_wind
    try:
        print("| flight | resultant | k | 1-sigma white | N | N_eff | 1-sigma coloured | t |")
        print("|---|---|---|---|---|---|---|---|")
        for spec in a.flights:
            log, _, af = spec.partition("@")
            if not af:
                p.error(f"{spec}: expected LOG@AIRFRAME")
            row.clear()
            estimate_mod.estimate_states(read_log(log), load_airframe(af), aid_air_angles=False)
            name = Path(log).name
            if "resultant" not in row:
                print(f"| {name} | | no wind fit (no usable airspeed with GPS velocity) | | | | | |")
                continue
            if "k" not in row:
                print(f"| {name} | {row['resultant']:.2f} | not fitted (the track does not turn) | | | | | |")
                continue
            print(f"| {name} | {row['resultant']:.2f} | {row['k']:.4f} | {row['se_white']:.4f} | {row['n']} | "
                  f"{row['n_eff']:.0f} | {row['se']:.4f} | {(row['k'] - 1) / row['se']:+.1f} |", flush=True)
    finally:
        estimate_mod.estimate_wind = wind_fit
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
