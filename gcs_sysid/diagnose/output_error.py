"""Output error: the simulation driven by the measured controls from measured initial states.

Short windows (3 s by default: long enough for the short-period and roll modes,
short enough that the open-loop simulation stays near the measured trajectory)
start from the measured state (attitude, rates, body velocity over the ground,
altitude) and are driven by the measured controls; the simulated V, alpha, beta,
p, q, r, phi, theta, psi are compared with the measured ones. The "before" run
is the model under test with no wind (the simulation as the engineer runs it);
"after" adds every finding: extended model, actuator delays (controls shifted),
stuck surfaces (controls frozen), mass / inertia (airframe), CG offset, wind,
and sensor corrections applied to the measured states it is compared with.

An unmodelled steady wind shows here (not in the equation error when the log
carries the autopilot's alpha/beta estimates): the ``wind`` candidate takes the
estimator's mean wind and is accepted when it removes held-out output error.

References: Morelli and Klein, *Aircraft System Identification*, ch. 6 (output
error); Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., sec. 4.2.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .regression import effective_samples

__all__ = ["OE_KEYS", "window_starts", "simulate_windows", "output_error_gain", "wind_candidate"]

OE_KEYS = ("V", "alpha", "beta", "p", "q", "r", "phi", "theta", "psi")
_CTRL = ("delta_e", "delta_a", "delta_r", "delta_t")
_NEED = ("phi", "theta", "psi", "p", "q", "r", "u", "v", "w", "alt", "V", "alpha", "beta") + _CTRL


def window_starts(valid: np.ndarray, test: np.ndarray, n: int, step: int, max_windows: int = 48):
    """Start indices of windows of ``n`` rows lying wholly in valid rows; and whether each is held out.

    A window is held out when most of it lies in held-out rows. At most
    ``max_windows`` of each kind, evenly spread.
    """
    T = len(valid)
    cv = np.concatenate([[0], np.cumsum(valid)])
    ct = np.concatenate([[0], np.cumsum(test)])
    ks = np.arange(0, T - n, step)
    ok = (cv[ks + n] - cv[ks]) == n
    ks = ks[ok]
    held = (ct[ks + n] - ct[ks]) > n // 2
    out = []
    for h in (False, True):
        sel = ks[held == h]
        if len(sel) > max_windows:
            sel = sel[np.linspace(0, len(sel) - 1, max_windows).round().astype(int)]
        out += [(int(k), h) for k in sel]
    out.sort()
    return np.array([k for k, _ in out], int), np.array([h for _, h in out], bool)


def _controls(states, t, starts, n, delays=None, stuck=None):
    """(N, n, 4) measured controls, optionally delayed (s) or frozen after an onset (s) at a value."""
    U = []
    full = {}
    for c in _CTRL:
        u = np.asarray(states[c], float)
        if delays and c in delays:
            u = np.interp(t - delays[c], t, u)
        if stuck and c in stuck:
            onset, val = stuck[c]
            u = np.where(t >= onset, val, u)
        full[c] = u
    for k in starts:
        U.append(np.column_stack([full[c][k:k + n] for c in _CTRL]))
    return np.stack(U)


def simulate_windows(airframe, model, states, starts, n, wind=(0.0, 0.0, 0.0), delays=None, stuck=None,
                     cg_offset=None, pad_to: int | None = None) -> dict[str, np.ndarray]:
    """Run :func:`gcs_sysid.sim.propagate` over the windows at once.

    Args:
        airframe, model: what to simulate (``AeroModel``).
        states: FlightStates (or mapping with ``.t`` and keys :data:`_NEED`).
        starts: (N,) window start rows; n: rows per window.
        wind: steady wind NED, m/s. delays: control -> s. stuck: control -> (onset s, value).
        cg_offset: (3,) m or None. pad_to: pad the batch to this size (one compiled shape).

    Returns:
        key -> (N, n) simulated values for :data:`OE_KEYS`.
    """
    from ..sim import Effects, propagate, state_from_measurements

    t = np.asarray(states.t, float)
    d = {k: np.asarray(states[k], float) for k in _NEED}
    x0 = np.array([state_from_measurements(d["phi"][k], d["theta"][k], d["psi"][k], d["p"][k], d["q"][k],
                                           d["r"][k], d["alt"][k], u=d["u"][k], v=d["v"][k], w=d["w"][k])
                   for k in starts])
    U = _controls(d, t, starts, n, delays, stuck)
    N = len(starts)
    if pad_to and pad_to > N:
        x0 = np.concatenate([x0, np.repeat(x0[:1], pad_to - N, 0)])
        U = np.concatenate([U, np.repeat(U[:1], pad_to - N, 0)])
    eff = Effects(cg_offset=tuple(float(x) for x in cg_offset)) if cg_offset is not None else None
    out = propagate(airframe, model, x0, t[:n] - t[0], U, wind_ned=tuple(float(x) for x in wind), effects=eff)
    return {k: np.asarray(out[k])[:N] for k in OE_KEYS}


def _measured(states, starts, n, corr=None):
    corr = corr or {}
    out = {}
    for k in OE_KEYS:
        x = np.asarray(states[k], float)
        if k in corr:
            x = corr[k](x)
        out[k] = np.stack([x[s:s + n] for s in starts])
    return out


def _errors(sim, meas):
    e = {k: sim[k] - meas[k] for k in OE_KEYS}
    e["psi"] = np.angle(np.exp(1j * e["psi"]))
    return e


def _rms(e, mask):
    return {k: float(np.sqrt(np.mean(e[k][mask] ** 2))) if mask.any() else float("nan") for k in OE_KEYS}


def _setup(diag, states, window_s, step_s):
    t = np.asarray(states.t, float)
    rate = 1.0 / float(np.median(np.diff(t)))
    n = max(10, int(round(window_s * rate)))
    valid = np.ones(len(t), bool)
    for k in _NEED:
        valid &= np.isfinite(np.asarray(states[k], float))
    if len(diag.t) == len(t):
        valid &= diag.train | diag.test
        test = diag.test
    else:
        test = np.interp(t, diag.t, diag.test.astype(float)) > 0.5
    starts, held = window_starts(valid, test, n, max(1, int(round(step_s * rate))))
    return t, n, starts, held


def wind_candidate(diag, states, airframe, model, window_s: float = 3.0, step_s: float = 1.5):
    """The ``wind`` cause: does the estimator's mean wind, given to the simulation, remove output error?

    Returns:
        dict with ``estimate`` (wind speed m/s), ``std_error``, ``wind_ned``, per-state held-out
        gains and a held-out score (as the equation-error candidates), or None without windows.
    """
    if not all(k in states for k in ("wn", "we")):
        return None
    t, n, starts, held = _setup(diag, states, window_s, step_s)
    if held.sum() < 2 or (~held).sum() < 2:
        return None
    v = diag.train | diag.test if len(diag.t) == len(t) else np.ones(len(t), bool)
    wn, we = np.asarray(states["wn"], float)[v], np.asarray(states["we"], float)[v]
    w = np.array([np.mean(wn), np.mean(we), 0.0])
    spd = float(np.hypot(w[0], w[1]))
    se = float(np.hypot(np.std(wn) / np.sqrt(effective_samples(wn)), np.std(we) / np.sqrt(effective_samples(we))))
    pad = len(starts)
    meas = _measured(states, starts, n)
    e0 = _errors(simulate_windows(airframe, model, states, starts, n, pad_to=pad), meas)
    e1 = _errors(simulate_windows(airframe, model, states, starts, n, wind=w, pad_to=pad), meas)
    gains, score = {}, 0.0
    for k in ("V", "alpha", "beta"):
        b, a = np.sqrt(np.mean(e0[k][held] ** 2)), np.sqrt(np.mean(e1[k][held] ** 2))
        gains[k] = {"rms_before": float(b), "rms_after": float(a),
                    "percent": float(100 * (1 - a / b)) if b > 0 else 0.0}
        neff = effective_samples(e0[k][held].ravel()) if b > 0 else 1.0
        score += neff / 2 * np.log(b**2 / max(a**2, 1e-300)) if b > 0 else 0.0
    score -= np.log(max(held.sum() * n, 2))
    return {"estimate": spd, "std_error": se, "wind_ned": w.tolist(), "gains": gains, "score": float(score),
            "from_deg": float(np.degrees(np.arctan2(-w[1], -w[0])) % 360), "n_windows": int(len(starts))}


def _after_inputs(diag, airframe):
    """What the findings change: airframe, delays, stuck, cg, wind, corrections of the measured states."""
    af, delays, stuck, cg, wind, corr = airframe, {}, {}, None, np.zeros(3), {}
    for f in diag.findings:
        c, est = f["cause"], f["estimate"]
        if f["evidence"].get("domain") == "data compatibility":
            continue                      # a sensor error: the reconstruction the windows start from is not affected
        kind, _, what = c.partition(":")
        p = f["evidence"].get("parameters", {})
        if kind == "delay":
            delays[what] = est
        elif kind == "stuck":
            stuck[what] = (f["onset_s"], est)
        elif c == "mass":
            af = replace(af, mass=est)
        elif kind == "inertia":
            af = replace(af, **{what: est})
        elif c == "cg_offset":
            cg = np.array([p.get("dx", 0.0), p.get("dy", 0.0), p.get("dz", 0.0)])
        elif c == "wind":
            wind = np.asarray(f["evidence"].get("wind_ned", [p.get("wn", 0.0), p.get("we", 0.0), 0.0]), float)
        elif c == "bias:airspeed":
            corr["V"] = lambda x, b=est: x - b
        elif c == "scale:airspeed":
            corr["V"] = lambda x, s=est: x / s
        elif c == "bias:alpha":
            corr["alpha"] = lambda x, b=est: x - b
        elif c == "bias:beta":
            corr["beta"] = lambda x, b=est: x - b
    return af, delays, stuck, cg, wind, corr


def output_error_gain(diag, states, airframe, window_s: float = 3.0, step_s: float = 1.5) -> dict:
    """Output error before (model under test, no wind) and after (all findings), on held-out windows.

    Returns:
        dict: ``available``, ``window_s``, ``n_windows``, ``states_rms`` (state -> rms_before,
        rms_after, percent on held-out windows), ``windows_plot`` (a few windows for the report).
    """
    from ..sim.model_file import AeroModel

    t, n, starts, held = _setup(diag, states, window_s, step_s)
    if len(starts) == 0 or not held.any():
        return {"available": False, "reason": "no window of valid data long enough for output error"}
    pad = len(starts)
    m0 = AeroModel(diag.model, "model")
    m1 = AeroModel(diag.model_extended, "extended")
    meas0 = _measured(states, starts, n)
    s0 = simulate_windows(airframe, m0, states, starts, n, pad_to=pad)
    e0 = _errors(s0, meas0)
    out = {"available": True, "window_s": float(window_s), "n_windows": int(held.sum()), "states": list(OE_KEYS)}
    r0 = _rms(e0, held)
    if diag.findings:
        af, delays, stuck, cg, wind, corr = _after_inputs(diag, airframe)
        meas1 = _measured(states, starts, n, corr)
        s1 = simulate_windows(af, m1, states, starts, n, wind, delays, stuck, cg, pad_to=pad)
        e1 = _errors(s1, meas1)
        r1 = _rms(e1, held)
    else:
        s1, meas1, r1 = None, None, None
    out["states_rms"] = {k: {"rms_before": r0[k], **({"rms_after": r1[k], "percent":
                                                          float(100 * (1 - r1[k] / r0[k])) if r0[k] > 0 else 0.0}
                                                         if r1 else {})} for k in OE_KEYS}
    idx = np.nonzero(held)[0]
    pick = idx[np.linspace(0, len(idx) - 1, min(4, len(idx))).round().astype(int)]
    plots = []
    for i in pick:
        w = {"t": (t[starts[i]:starts[i] + n]).tolist(),
             "measured": {k: meas0[k][i].tolist() for k in OE_KEYS},
             "before": {k: s0[k][i].tolist() for k in OE_KEYS}}
        if s1 is not None:
            w["after"] = {k: s1[k][i].tolist() for k in OE_KEYS}
        plots.append(w)
    out["windows_plot"] = plots
    return out
