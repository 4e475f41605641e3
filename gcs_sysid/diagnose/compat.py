"""Sensor causes by data compatibility: each sensor against the kinematic flight-path reconstruction.

The estimation layer calibrates some sensor errors away (gyro and accelerometer
biases by its filters, the pitot scale by its wind fit) and does not use others
(the autopilot's AOA_SSA), so a sensor error does not show in the aerodynamic
coefficients. A flight-test engineer finds it by checking data compatibility
(Morelli and Klein, *Aircraft System Identification*, 2nd ed., ch. 10;
Klein and Morelli 2006 ch. 10; Jategaonkar 2015 ch. 10): the sensor is compared
with what the kinematics say it should read, and a constant offset (or scale)
is estimated.

- ``bias:alpha``, ``bias:beta``: the logged AOA_SSA (the autopilot's air-data
  estimate, lagged) against ``first_order_lag(alpha_reconstructed, tau)``,
  ``tau`` scanned; the offset is the bias. The reconstruction misses the gusts;
  the zero-mean gust angle that the measured coefficients see
  (:mod:`gcs_sysid.diagnose.turbulence`) is added to it first.
- ``bias:airspeed``, ``scale:airspeed``: the pitot's true airspeed against
  ``|v_ground - w|`` with one steady wind ``w`` for the flight, fitted jointly
  with the bias (or scale) from the magnitude equation and the crab-angle
  condition (sideslip zero on average), which fixes the cross-track wind on each
  heading (Cho et al., IEEE TAES 47(1), 2011).
- ``bias:gyro_x`` (y, z): the raw gyro against the body rates from the Euler
  angle kinematics of the logged attitude (Stevens, Lewis and Johnson eq. 1.4-4),
  both averaged over 1 s.
- ``bias:accel_x`` (y, z): the raw accelerometer (moved to the CG) against the
  specific force from the GPS velocity derivative, ``C'(dv/dt - g)``, both
  averaged over 1 s.

Each cause is fitted on the training rows and scored on the held-out rows with
the same held-out likelihood ratio and BIC penalty as the equation-error causes;
``gain`` is the held-out RMS of the compatibility residual before and after. The
diagnosis passes the acceptance rows as ``test`` and the untouched rows as
``gain_rows`` (:func:`gcs_sysid.diagnose.physical.split_held_out`). Standard errors
are honest: the coloured-residual error and the reconstruction's systematic error
(``RESOLUTION``) in quadrature. :func:`judge` decides which are named causes and
which are calibration notes (the same offset in the reference flight).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import lfilter

from .regression import colored_covariance, effective_samples

__all__ = ["compatibility_candidates", "judge", "MIN_T_SENSOR"]

G0 = 9.80665


def _interp(t, ts, x):
    ok = np.isfinite(x)
    if ok.sum() < 2:
        return np.full(len(t), np.nan)
    y = np.interp(t, ts[ok], x[ok], left=np.nan, right=np.nan)
    return y


def _lag(x, dt, tau):
    if tau <= 0:
        return x
    a = np.exp(-dt / tau)
    y, _ = lfilter([1 - a], [1, -a], x, zi=[a * x[0]])
    return y


def _movavg(x, n):
    if n <= 1:
        return x
    k = np.ones(n) / n
    return np.convolve(x, k, mode="same")


def _score(res0_te, res1_te, k):
    """Held-out log-likelihood ratio with BIC penalty, and the gain dict."""
    sse0, sse1 = float(np.sum(res0_te**2)), float(np.sum(res1_te**2))
    neff = effective_samples(res1_te)
    s = neff / 2 * np.log(sse0 / max(sse1, 1e-300)) - k / 2 * np.log(max(neff, 2.0)) if sse0 > 0 else -np.inf
    n = max(len(res0_te), 1)
    b, a = np.sqrt(sse0 / n), np.sqrt(sse1 / n)
    return float(s), {"rms_before": float(b), "rms_after": float(a),
                      "percent": float(100 * (1 - a / b)) if b > 0 else 0.0}


#: Smallest offset each check can resolve, whatever its statistics say: below it the reconstruction's
#: own systematic error is as large (alpha/beta: a 0.2 m/s wind-estimate error at the flight's airspeed,
#: added in ``_aoa``; gyro: the attitude-kinematics rate after smoothing; accelerometer: the GPS
#: velocity derivative with ~0.05 m/s velocity noise over the averaging window).
RESOLUTION = {"rad/s": 0.002, "m/s^2": 0.05}
WIND_ERROR_MPS = 0.2


def _honest(se: float, systematic: float) -> float:
    """Standard error with the reconstruction's systematic error in quadrature (coloured part ``se``)."""
    return float(np.hypot(se, systematic))


def _offset(cause, state, y, ref, train, test, unit, extra=None, resolution=None, opts=None):
    """Constant offset of ``y - ref`` (arrays on the grid): fitted on train, scored held out.

    The standard error is honest: the coloured-residual error of the mean (``effective_samples``) and
    the reconstruction's systematic error (``resolution``, default ``RESOLUTION[unit]``) in quadrature.
    ``opts``: ``{"gain_rows": (T,) mask}`` adds the gain on those untouched rows
    (``evidence.gain_untouched``); ``{"floors": False}`` keeps offsets below the resolution (for the
    differential comparison with a reference flight).

    Returns None (no candidate) when the data are too few or (with floors) the offset is below the
    resolution, the size the reconstruction itself cannot vouch for.
    """
    opts = opts or {}
    d = y - ref
    tr, te = train & np.isfinite(d), test & np.isfinite(d)
    if tr.sum() < 20 or te.sum() < 10:
        return None
    b = float(np.mean(d[tr]))
    floor = RESOLUTION.get(unit, 0.0) if resolution is None else resolution
    if abs(b) < floor and opts.get("floors", True):
        return None
    se_c = float(np.std(d[tr]) / np.sqrt(effective_samples(d[tr])))
    se = _honest(se_c, floor)
    score, gain = _score(d[te], d[te] - b, 1)
    ev = {"domain": "data compatibility", "parameters": {cause: b}, "unit": unit,
          "t_statistic": b / se if se > 0 else None, "std_error_coloured": se_c, "systematic_error": floor}
    g = opts.get("gain_rows")
    if g is not None and (g & np.isfinite(d)).sum() >= 10:
        ev["gain_untouched"] = _score(d[g & np.isfinite(d)], d[g & np.isfinite(d)] - b, 1)[1]
    ev.update(extra or {})
    return {"cause": cause, "coefficient": state, "estimate": b, "std_error": se, "score": score,
            "gain": gain, "evidence": ev}


def _aoa(flight, states, train, test, corrections=None, opts=None):
    out = []
    if not flight.has("aoa_ssa"):
        return out
    s = flight["aoa_ssa"]
    t = np.asarray(states.t, float)
    dt = float(np.median(np.diff(t)))
    for name, state in (("alpha", "alpha"), ("beta", "beta")):
        if name not in s.fields or state not in states:
            continue
        x = np.asarray(states[state], float)
        if not np.isfinite(x).any():
            continue
        x = np.where(np.isfinite(x), x, np.nanmean(x))
        gust = (corrections or {}).get(name)
        if gust is not None:
            x = x + np.nan_to_num(gust)
        y = _interp(t, s.t, np.asarray(s[name], float))
        best = None
        for tau in np.arange(0.0, 0.41, 0.05):                # the estimate's lag, scanned
            ref = _lag(x, dt, tau)
            d = y - ref
            m = train & np.isfinite(d)
            if m.sum() < 20:
                break
            v = float(np.var(d[m]))
            if best is None or v < best[0]:
                best = (v, tau, ref)
        if best is None:
            continue
        V = np.asarray(states["V"], float) if "V" in states else np.array([20.0])
        res = WIND_ERROR_MPS / max(float(np.nanmedian(V)), 5.0)   # rad: a wind error seen as an angle
        f = _offset(f"bias:{name}", name, y, best[2], train, test, "rad", resolution=res, opts=opts, extra=
                    {"sensor": f"AOA_SSA {name} (autopilot estimate) vs {name} reconstructed from GPS velocity, "
                               "attitude and wind" + (" plus the gust angle seen by the coefficients"
                                                      if gust is not None else ""), "lag_s": float(best[1])})
        if f:
            out.append(f)
    return out


def _airspeed(flight, states, train, test, opts=None):
    if not all(k in states for k in ("vn", "ve", "vd", "phi", "theta", "psi", "rho")):
        return []
    stream = "airspeed" if flight.has("airspeed") and "eas" in flight["airspeed"].fields else "vfr_hud"
    key = "eas" if stream == "airspeed" else "airspeed"
    if not flight.has(stream) or key not in flight[stream].fields:
        return []
    t = np.asarray(states.t, float)
    eas = _interp(t, flight[stream].t, np.asarray(flight[stream][key], float))
    rho = np.asarray(states["rho"], float)
    tas = eas * np.sqrt(1.225 / rho)
    v = np.column_stack([np.asarray(states[k], float) for k in ("vn", "ve", "vd")])
    from .causes import _dcm_nb

    C = _dcm_nb(np.asarray(states["phi"]), np.asarray(states["theta"]), np.asarray(states["psi"]))   # NED -> body
    ok = np.isfinite(tas) & np.isfinite(v).all(1) & (tas > 5.0)
    tr, te = train & ok, test & ok
    if tr.sum() < 50 or te.sum() < 20:
        return []
    step = max(1, int(tr.sum() // 1500))
    idx = np.nonzero(tr)[0][::step]
    sig_v, sig_beta = 0.3, 0.05

    def resid(p, kind, rows):
        w = np.array([p[0], p[1], 0.0])
        va = np.einsum("tij,tj->ti", C[rows], v[rows] - w)
        V = np.linalg.norm(va, axis=1)
        meas = tas[rows]
        pred = V + p[2] if kind == "bias" else V * p[2]
        return np.concatenate([(meas - pred) / sig_v, va[:, 1] / (sig_beta * np.maximum(V, 1.0))]), meas - pred

    out = []
    fits = {}
    for kind in ("none", "bias", "scale"):
        p0 = np.array([0.0, 0.0, 0.0 if kind != "scale" else 1.0])
        if kind == "none":
            sol = least_squares(lambda p: resid(np.r_[p, 0.0], "bias", idx)[0], p0[:2])
            p = np.r_[sol.x, 0.0]
            J = None
        else:
            sol = least_squares(lambda p: resid(p, kind, idx)[0], p0)
            p, J = sol.x, sol.jac
        fits[kind] = (p, J, sol.fun)
    r0 = resid(fits["none"][0], "bias", np.nonzero(te)[0])[1]
    for kind, cause in (("bias", "bias:airspeed"), ("scale", "scale:airspeed")):
        p, J, fun = fits[kind]
        vif = _vif(J, 2)
        if not vif < MAX_VIF:      # the pitot error cannot be told from the wind on these headings
            continue
        r1 = resid(p, kind, np.nonzero(te)[0])[1]
        score, gain = _score(r0, r1, 1)
        cov = colored_covariance(J, fun)
        se_c = float(np.sqrt(max(cov[2, 2], 0.0)))
        sys_err = WIND_ERROR_MPS if kind == "bias" else WIND_ERROR_MPS / max(float(np.median(tas[tr])), 5.0)
        se = _honest(se_c, sys_err)
        extra = {"std_error_coloured": se_c, "systematic_error": sys_err, "vif_against_wind": vif}
        g = (opts or {}).get("gain_rows")
        if g is not None and (g & ok).sum() >= 20:
            gi = np.nonzero(g & ok)[0]
            extra["gain_untouched"] = _score(resid(fits["none"][0], "bias", gi)[1], resid(p, kind, gi)[1], 1)[1]
        out.append({"cause": cause, "coefficient": "V", "estimate": float(p[2]), "std_error": se, "score": score,
                    "gain": gain, "evidence": {**extra, "domain": "data compatibility",
                                               "unit": "m/s" if kind == "bias" else "",
                                               "parameters": {"wn": float(p[0]), "we": float(p[1]), kind: float(p[2])},
                                               "sensor": "pitot true airspeed vs |v_gps - w| with one steady wind "
                                                         "(sideslip zero on average)",
                                               "t_statistic": (p[2] - (0.0 if kind == "bias" else 1.0)) / se
                                               if se > 0 else None}})
    return out


#: Largest variance-inflation factor of the pitot parameter against the wind (Morelli and Klein sec. 5.4,
#: collinearity: VIF >= 10 means the parameter is mostly a combination of the others). With few
#: heading changes a pitot bias and a headwind are the same thing to this check; the coefficients then
#: judge it (:mod:`gcs_sysid.diagnose.pitot`).
MAX_VIF = 10.0


def _vif(J: np.ndarray, k: int) -> float:
    """Variance-inflation factor of parameter ``k`` of a least-squares Jacobian ``J`` (N, K)."""
    A = J.T @ J
    try:
        return float(np.linalg.inv(A)[k, k] * A[k, k])
    except np.linalg.LinAlgError:
        return float("inf")


def _euler_rates(phi, theta, psi, dt):
    psi = np.unwrap(psi)
    d = [np.gradient(x, dt) for x in (phi, theta, psi)]
    p = d[0] - d[2] * np.sin(theta)
    q = d[1] * np.cos(phi) + d[2] * np.sin(phi) * np.cos(theta)
    r = -d[1] * np.sin(phi) + d[2] * np.cos(phi) * np.cos(theta)
    return np.column_stack([p, q, r])


def _gyro_accel(flight, states, airframe, train, test, avg_s=1.0, opts=None):
    out = []
    if not flight.has("imu"):
        return out
    t = np.asarray(states.t, float)
    dt = float(np.median(np.diff(t)))
    n = max(1, int(round(avg_s / dt)))
    imu = flight["imu"]
    if flight.has("attitude") and all(k in flight["attitude"].fields for k in ("roll", "pitch", "yaw")):
        a = flight["attitude"]
        ang = [_interp(t, a.t, np.unwrap(np.asarray(a[k], float)) if k == "yaw" else np.asarray(a[k], float))
               for k in ("roll", "pitch", "yaw")]
        if all(np.isfinite(x).sum() > 10 for x in ang):
            ang = [np.where(np.isfinite(x), x, np.nanmean(x)) for x in ang]
            kin = _euler_rates(*ang, dt)
            for i, (k, ax) in enumerate(zip("pqr", "xyz")):
                if k not in imu.fields:
                    continue
                g = _movavg(_interp(t, imu.t, np.asarray(imu[k], float)), n)
                f = _offset(f"bias:gyro_{ax}", k, g, _movavg(kin[:, i], n), train, test, "rad/s", opts=opts,
                            extra={"sensor": f"IMU gyro {k} vs the rate from the attitude kinematics (1 s averages)"})
                if f:
                    out.append(f)
    if all(k in states for k in ("vn", "ve", "vd", "phi", "theta", "psi")) and \
            all(k in imu.fields for k in ("ax", "ay", "az")):
        from .causes import _dcm_nb

        C = _dcm_nb(np.asarray(states["phi"]), np.asarray(states["theta"]), np.asarray(states["psi"]))
        v = np.column_stack([np.asarray(states[k], float) for k in ("vn", "ve", "vd")])
        acc = np.column_stack([np.gradient(v[:, i], dt) for i in range(3)]) - np.array([0.0, 0.0, G0])
        f_gps = np.einsum("tij,tj->ti", C, acc)
        f_imu = np.column_stack([_interp(t, imu.t, np.asarray(imu[k], float)) for k in ("ax", "ay", "az")])
        arm = np.asarray(getattr(airframe, "imu_lever_arm", (0.0, 0.0, 0.0)), float)
        if np.any(arm != 0) and all(k in states for k in ("p", "q", "r", "p_dot", "q_dot", "r_dot")):
            W = np.column_stack([np.asarray(states[k], float) for k in ("p", "q", "r")])
            Wd = np.column_stack([np.asarray(states[k], float) for k in ("p_dot", "q_dot", "r_dot")])
            f_imu = f_imu - np.cross(Wd, arm) - np.cross(W, np.cross(W, arm))
        for i, ax in enumerate("xyz"):
            f = _offset(f"bias:accel_{ax}", f"a{ax}", _movavg(f_imu[:, i], n), _movavg(f_gps[:, i], n), train, test,
                        "m/s^2", opts=opts,
                        extra={"sensor": f"IMU specific force {ax} vs C'(dv_gps/dt - g) (1 s averages)"})
            if f:
                out.append(f)
    return out


def compatibility_candidates(flight, states, airframe, train, test, corrections=None, gain_rows=None,
                             floors: bool = True) -> list[dict]:
    """Fit and score the sensor causes by data compatibility.

    Args:
        flight: the decoded :class:`~gcs_sysid.telemetry.types.Flight` (raw sensor streams).
        states: its :class:`~gcs_sysid.estimation.states.FlightStates` (the reconstruction).
        airframe: for the IMU lever arm.
        train, test: (T,) masks on the states grid.
        corrections: optional ``{"alpha": (T,), "beta": (T,)}`` zero-mean gust angles (rad) the
            reconstruction misses, as the coefficients see them
            (:meth:`gcs_sysid.diagnose.turbulence.GustProjector.angles`), added to the reconstruction.
        gain_rows: (T,) untouched rows (neither fitted nor scored on): each candidate's
            ``evidence.gain_untouched`` is measured there once.
        floors: False keeps offsets below the reconstruction's resolution (to compare with a reference).

    Returns:
        candidate dicts ``cause coefficient estimate std_error score gain evidence`` (``coefficient`` is
        the sensor's quantity: ``alpha``, ``beta``, ``V``, ``p`` ... ``ax`` ...).
    """
    opts = {"gain_rows": gain_rows, "floors": floors}
    out = []
    try:
        out += _aoa(flight, states, train, test, corrections, opts)
    except (ValueError, np.linalg.LinAlgError):
        pass
    try:
        out += _airspeed(flight, states, train, test, opts)
    except (ValueError, np.linalg.LinAlgError):
        pass
    try:
        out += _gyro_accel(flight, states, airframe, train, test, opts=opts)
    except (ValueError, np.linalg.LinAlgError):
        pass
    return [c for c in out if np.isfinite(c["score"]) and np.isfinite(c["estimate"])]


#: |t| a sensor offset needs with its honest standard error (coloured scatter and the reconstruction's
#: systematic error in quadrature); frozen 2026-11-22 00:15 UTC with :mod:`gcs_sysid.diagnose.physical`.
MIN_T_SENSOR = 3.0


def judge(cands: list[dict], references: list[tuple[str, list[dict]]], min_score: float,
          min_gain_pct: float) -> list[str]:
    """Mark each compatibility candidate ``accepted`` (a named cause) or not, in place.

    A sensor cause is named when all hold:

    - significant: ``|t| >= MIN_T_SENSOR`` with the honest standard error;
    - accepted on the acceptance rows: held-out score ``>= min_score`` and gain ``>= min_gain_pct``;
    - the gain on the untouched rows (``evidence.gain_untouched``, when measured) ``>= min_gain_pct``;
    - differential: against every reference flight where the same check could be made, the change
      ``c - c_ref`` is at least 3 standard errors (``sqrt(se^2 + se_ref^2)``). A bias the reference
      has too is a **calibration note** (``evidence.differential.verdict = "calibration"``): the
      sensor needs calibrating, but nothing changed;
    - and it is the best-scoring accepted cause of its sensor (pitot: bias or scale).

    Args:
        cands: from :func:`compatibility_candidates` on the flight (updated in place: ``accepted``,
            ``evidence.differential``, ``evidence.rivals``, ``evidence.separable``).
        references: ``(label, candidates)`` per reference flight, from :func:`compatibility_candidates`
            with ``floors=False`` on all its rows.
        min_score, min_gain_pct: the diagnosis' acceptance thresholds.

    Returns:
        the calibration notes (one line each).
    """
    cands.sort(key=lambda c: c["score"], reverse=True)
    notes, seen = [], set()
    for c in cands:
        ev = c["evidence"]
        sensor = "airspeed" if c["cause"].endswith(":airspeed") else c["cause"]
        tstat = ev.get("t_statistic")
        checks = {"significant": tstat is not None and abs(tstat) >= MIN_T_SENSOR,
                  "accepted_on_acceptance_rows": c["score"] >= min_score and c["gain"]["percent"] >= min_gain_pct,
                  "gain_untouched": ev.get("gain_untouched", {"percent": 100.0})["percent"] >= min_gain_pct}
        comps = []
        for label, rc in references:
            hit = next((r for r in rc if r["cause"] == c["cause"]), None)
            if hit is None:
                continue
            dlt = c["estimate"] - hit["estimate"]
            sig = float(np.hypot(c["std_error"], hit["std_error"]))
            comps.append({"label": label, "estimate": float(hit["estimate"]), "std_error": float(hit["std_error"]),
                          "change": float(dlt), "same": bool(abs(dlt) < 3.0 * sig)})
        if comps and all(x["same"] for x in comps):
            ev["differential"] = {"verdict": "calibration", "references": comps,
                                  "why": "the reference flight(s) had the same offset: present when the model was "
                                         "fitted, a calibration to correct, not a change"}
            checks["changed_since_reference"] = False
        elif comps:
            ev["differential"] = {"verdict": "changed", "references": comps}
        else:
            ev["differential"] = {"verdict": "not compared" if references else "no reference flight"}
        ev["checks"] = {k: bool(v) for k, v in checks.items()}
        c["accepted"] = bool(sensor not in seen and all(checks.values()))
        if ev["differential"]["verdict"] == "calibration" and checks["significant"] and sensor not in seen:
            ev["calibration_note"] = (f"{c['cause']} = {c['estimate']:.3g} +- {c['std_error']:.2g} "
                                      f"{ev.get('unit', '')}, "
                                      "the same in the reference flight(s): a calibration note, not a cause")
            notes.append(ev["calibration_note"])
        rivals = [r for r in cands if r is not c and r["cause"].split(":")[-1] == c["cause"].split(":")[-1]]
        ev.update({"score": c["score"], "separable": not any(r["score"] > 0.9 * c["score"] for r in rivals),
                   "rivals": [{"cause": r["cause"], "score": r["score"], "gain_percent": r["gain"]["percent"]}
                              for r in rivals]})
        if c["accepted"]:
            seen.add(sensor)
    return notes
