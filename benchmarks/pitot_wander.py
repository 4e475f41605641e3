"""What sets a small pitot bias's gain: the logged wind's wander on the untouched rows (issue 9; analysis only).

The diagnosis scores a pitot bias's gain in the sensor's own units on the untouched rows
(:func:`gcs_sysid.diagnose.wind_triangle.triangle_gain`): the residual ``r = V_pitot - |v_gps - w_ap|`` against the
autopilot's wind *as logged*, before (the reference flight's level) and after (plus the named change). On a
JSBSim flight of the harness (:mod:`benchmarks.jsbsim_harness.sensors`) the logged wind is the true wind low-passed
with a 10-s time constant plus a Gauss-Markov wander (0.3 m/s, 20 s per component), so along the air velocity

    ``r = b + h . (w_ap - LP10(w_true)) + h . (LP10(w_true) - w_true) + noise``
          bias   wander (this script's "wander")  gusts the estimate cannot follow

This script decomposes ``r`` of every flight of a diagnose eval's directory against the truth file: the wander's
mean over the flight and over the untouched rows (the two held-out blocks the gain is scored on,
:func:`gcs_sysid.diagnose.physical.split_held_out`), beside the diagnosis's own wind triangle
(:func:`gcs_sysid.diagnose.wind_triangle.wind_triangle`). It also fits the residual by generalised least squares
with the wander as a first-order Gauss-Markov process of the air-velocity direction (covariance
``sigma_w^2 exp(-|t_i - t_j| / tau) h_i . h_j`` plus white noise on 1-s bin means, sigma_w = 0.3 m/s, the
diagnosis's ``WIND_SYSTEMATIC_MPS``), with ``tau`` by restricted maximum likelihood (REML; Harville, JASA 72,
1977) on the flight itself and with ``tau`` = 20 s (the harness's value) for comparison: the "Gauss-Markov wind
error in the triangle fit" of the twelfth session's closing note. ``--monte-carlo`` draws the triangle gain of a
bias on the untouched rows under that noise model.

Usage::

    python -m benchmarks.pitot_wander --aircraft f4n --dir /tmp/NAME/f4n-diag     # flights of eval_jsbsim_diagnose
    python -m benchmarks.pitot_wander --monte-carlo

Nothing here changes a diagnosis; results are in ``docs/benchmarks.md``, *Thirteenth session, i9-wind*.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gcs_sysid.diagnose.wind_triangle import RHO0, WIND_SYSTEMATIC_MPS

SIGMA_W = WIND_SYSTEMATIC_MPS          # m/s, the wander's SD the diagnosis assumes (0.3)
TAUS = (2.5, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0, 320.0)
SIGMA_E = (0.03, 0.05, 0.08, 0.12, 0.18, 0.25, 0.35, 0.5)


def pitot_residual(meas) -> dict | None:
    """The triangle residual on the pitot's samples of one flight (as :func:`wind_triangle._samples` selects them).

    Returns ``{"t" (N,) s, "r" (N,) m/s, "h" (N, 2), "t_grid" (T,), "valid" (T,)}`` or None (no pitot or wind).
    """
    from gcs_sysid.diagnose import wind_triangle as wt

    table, states = meas.table, meas.states
    t_grid = np.asarray(table.t, float)
    valid = np.asarray(table.valid, bool) & np.all(np.isfinite(table.X), axis=1) & np.all(np.isfinite(table.Y), axis=1)
    st = {k: np.interp(t_grid, states.t, np.asarray(states.data[k], float)) for k in ("vn", "ve", "vd", "rho")}
    p = wt._pitot(meas.flight)
    w = None if p is None else wt.autopilot_wind(meas.flight, p[0])
    if p is None or w is None:
        return None
    tp, eas = p
    use = np.interp(tp, t_grid, valid.astype(float), left=0.0, right=0.0) > 0.999
    tas = eas * np.sqrt(RHO0 / np.interp(tp, t_grid, st["rho"]))
    vg = np.stack([np.interp(tp, t_grid, st[k]) for k in ("vn", "ve", "vd")], axis=1)
    use &= np.isfinite(tas) & np.isfinite(vg).all(axis=1) & np.isfinite(w).all(axis=1)
    use &= tas > max(wt.MIN_TAS_MPS, 0.5 * float(np.percentile(tas[use], 90)))
    a = vg.copy()
    a[:, :2] -= w
    V = np.linalg.norm(a, axis=1)
    return {"t": tp[use], "r": (tas - V)[use], "h": (a[:, :2] / V[:, None])[use], "w_ap": w[use],
            "t_grid": t_grid, "valid": valid, "states": st}


def truth_wander(res: dict, truth: dict) -> np.ndarray:
    """``h . (w_ap - LP10(w_true))`` (N,) m/s: the logged wind's wander along the air velocity (harness model)."""
    from benchmarks.jsbsim_harness.sensors import _lowpass

    t = np.asarray(truth["t"], float)
    dt = float(t[1] - t[0])
    lp = np.stack([np.interp(res["t"], t, _lowpass(np.asarray(truth[k], float), dt, 10.0)) for k in ("wn", "we")], 1)
    return np.sum(res["h"] * (res["w_ap"] - lp), axis=1)


def _bins(t, r, h, width: float = 1.0):
    """1-s bin means of the residual and the (renormalised) air-velocity direction."""
    k = np.floor((t - t[0]) / width).astype(int)
    _, inv, cnt = np.unique(k, return_inverse=True, return_counts=True)
    ok = cnt >= 0.5 * np.median(cnt)
    tb = np.bincount(inv, t)[ok] / cnt[ok]
    rb = np.bincount(inv, r)[ok] / cnt[ok]
    hb = np.stack([np.bincount(inv, h[:, j])[ok] / cnt[ok] for j in range(2)], 1)
    return tb, rb, hb / np.linalg.norm(hb, axis=1)[:, None]


def gm_gls(tb, rb, hb, tau: float, sigma_e: float, sigma_w: float = SIGMA_W) -> tuple[float, float, float]:
    """GLS bias with a Gauss-Markov wander: ``(b, std_error, restricted log-likelihood)`` (m/s, m/s, -)."""
    C = sigma_w ** 2 * np.exp(-np.abs(tb[:, None] - tb[None, :]) / tau) * (hb @ hb.T)
    C[np.diag_indices_from(C)] += sigma_e ** 2
    L = np.linalg.cholesky(C)
    one = np.linalg.solve(L, np.ones(len(rb)))
    y = np.linalg.solve(L, rb)
    info = float(one @ one)
    b = float(one @ y) / info
    e = y - one * b
    return b, 1.0 / np.sqrt(info), float(-0.5 * e @ e - np.sum(np.log(np.diag(L))) - 0.5 * np.log(info))


def gm_fit(res: dict, tau: float | None = None) -> dict:
    """The GM-GLS bias with ``tau`` by REML on this flight (None) or fixed; sigma_e profiled on a grid."""
    F = _bins(res["t"], res["r"], res["h"])
    best = None
    for ta in (TAUS if tau is None else (tau,)):
        for se in SIGMA_E:
            b, s, ll = gm_gls(*F, ta, se)
            if best is None or ll > best["ll"]:
                best = {"tau_s": ta, "sigma_e": se, "bias_mps": b, "std_error": s, "ll": ll}
    return best


def _cases(d: Path, ac: str):
    """(label, tlog, truth) of the reference, pitot-bias and clean flights of an eval directory (sweep plan)."""
    for tl in sorted(d.glob(f"{ac}-*-sweep.tlog")):
        lab = tl.name[len(ac) + 1: -len("-sweep.tlog")]
        if lab == "ref" or "bias_airspeed" in lab or "clean" in lab:
            yield lab, tl, d / f"{tl.name[: -len('.tlog')]}-truth.npz"


def decompose(ac: str, d: Path) -> list[dict]:
    """One row per flight (reference first) of an eval directory: see the module docstring."""
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from gcs_sysid.diagnose.context import held_out_blocks
    from gcs_sysid.diagnose.physical import split_held_out
    from gcs_sysid.diagnose.run import load_measurements
    from gcs_sysid.diagnose.wind_triangle import wind_triangle

    airframe = aircraft(ac).airframe_path
    rows = []
    for lab, tl, tr in sorted(_cases(d, ac), key=lambda c: c[0] != "ref"):
        meas = load_measurements(tl, airframe)
        res = pitot_residual(meas)
        if res is None:
            continue
        truth = np.load(tr)
        w = truth_wander(res, truth)
        _, test = held_out_blocks(res["t_grid"], res["valid"])
        _, unt = split_held_out(res["t_grid"], test)
        u = np.interp(res["t"], res["t_grid"], unt.astype(float)) > 0.999
        tri = wind_triangle(res["t_grid"], res["states"], res["valid"], meas.flight)
        rows.append({"case": lab, "triangle_mps": tri["bias_mps"], "triangle_se": tri["std_error"],
                     "triangle_wind_correction": tri["wind_correction_mps"],
                     "heading_span_deg": tri["heading_span_deg"],
                     "level": float(np.mean(res["r"])), "wander": float(np.mean(w)),
                     "level_untouched": float(np.mean(res["r"][u])), "wander_untouched": float(np.mean(w[u])),
                     "n_untouched": int(u.sum()), "gm_reml": gm_fit(res), "gm_tau20": gm_fit(res, 20.0)})
        print(json.dumps(rows[-1]), flush=True)
    return rows


def table(rows: list[dict]) -> str:
    """Markdown: changes since the reference (first row) and the wander, m/s."""
    ref = rows[0]
    out = ["| flight | triangle change (current) | level change vs logged wind | wander, flight | "
           "level change, untouched | wander, untouched | GM REML tau (s): change | GM tau 20 s: change |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        gr, g2 = r["gm_reml"], r["gm_tau20"]
        se_c = np.hypot(r["triangle_se"], ref["triangle_se"]) if r is not ref else r["triangle_se"]
        chg = r["triangle_mps"] - (ref["triangle_mps"] if r is not ref else 0.0)
        gch = gr["bias_mps"] - (ref["gm_reml"]["bias_mps"] if r is not ref else 0.0)
        gse = np.hypot(gr["std_error"], ref["gm_reml"]["std_error"]) if r is not ref else gr["std_error"]
        g2ch = g2["bias_mps"] - (ref["gm_tau20"]["bias_mps"] if r is not ref else 0.0)
        g2se = np.hypot(g2["std_error"], ref["gm_tau20"]["std_error"]) if r is not ref else g2["std_error"]
        lref = ref["level"] if r is not ref else 0.0
        out.append(f"| {r['case']} | {chg:+.2f} +- {se_c:.2f} | {r['level'] - lref:+.2f} | {r['wander']:+.2f} | "
                   f"{r['level_untouched'] - lref:+.2f} | {r['wander_untouched']:+.2f} | "
                   f"{gr['tau_s']:g}: {gch:+.2f} +- {gse:.2f} | {g2ch:+.2f} +- {g2se:.2f} |")
    return "\n".join(out)


def monte_carlo(n: int = 2000, sigma_w: float = SIGMA_W, tau_w: float = 20.0, seed: int = 0) -> str:
    """Triangle gain of a bias on the untouched rows under the harness's noise model (markdown table).

    ``r = b + w + g + n`` at 25 Hz over 120 s: ``w`` the wander (GM sigma_w, tau_w), ``g`` the gusts the estimate
    cannot follow (GM 0.15 m/s, 2 s), ``n`` white 0.23 m/s (the f4n's flights against the truth); the reference
    an independent draw with b = 0. Untouched rows: 32.5-39.5 s and 80.5-87.5 s (the held-out blocks of
    :func:`gcs_sysid.diagnose.context.held_out_blocks` split by :func:`split_held_out`). The estimate is either
    exact or the flight's mean level minus the reference's (what a single-heading triangle reads).
    """
    rng = np.random.default_rng(seed)
    dt = 0.04
    t = np.arange(0.0, 120.0, dt)

    def gm(sig, tau):
        a = np.exp(-dt / tau)
        x = np.empty((n, t.size))
        x[:, 0] = rng.normal(0, sig, n)
        e = rng.normal(0, sig * np.sqrt(1 - a * a), (n, t.size))
        for i in range(1, t.size):
            x[:, i] = a * x[:, i - 1] + e[:, i]
        return x

    def flight(b):
        return b + gm(sigma_w, tau_w) + gm(0.15, 2.0) + rng.normal(0, 0.23, (n, t.size))

    unt = ((t > 32.5) & (t < 39.5)) | ((t > 80.5) & (t < 87.5))
    lines = [f"sigma_w {sigma_w} m/s, tau {tau_w} s, {n} draws", "",
             "| bias (m/s) | estimate | wander on untouched rows, SD | gain median | P(gain >= 50 %) "
             "| P(gain >= 10 %) |",
             "|---|---|---|---|---|---|"]
    ref = flight(0.0)
    lref = ref.mean(1)
    for b in (1.0, 2.0):
        f = flight(b)
        for name, bh in (("exact", np.full(n, b)), ("level minus reference's", f.mean(1) - lref)):
            before = np.sqrt(np.mean((f[:, unt] - lref[:, None]) ** 2, 1))
            after = np.sqrt(np.mean((f[:, unt] - lref[:, None] - bh[:, None]) ** 2, 1))
            g = 100 * (1 - after / before)
            wsd = float(np.std(f[:, unt].mean(1) - b))
            lines.append(f"| {b:g} | {name} | {wsd:.2f} | {np.median(g):.0f} % | {np.mean(g >= 50):.2f} | "
                         f"{np.mean(g >= 10):.2f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--aircraft")
    p.add_argument("--dir", type=Path, help="an eval_jsbsim_diagnose --out directory (flights and truth files)")
    p.add_argument("--monte-carlo", action="store_true")
    p.add_argument("--mc-sigma", type=float, default=SIGMA_W, help="the wander's SD in the Monte Carlo, m/s")
    p.add_argument("--mc-tau", type=float, default=20.0, help="the wander's time constant in the Monte Carlo, s")
    p.add_argument("--json", type=Path, help="write the rows here")
    a = p.parse_args(argv)
    if a.monte_carlo:
        print(monte_carlo(sigma_w=a.mc_sigma, tau_w=a.mc_tau))
    if a.aircraft and a.dir:
        rows = decompose(a.aircraft, a.dir)
        if a.json:
            a.json.write_text("\n".join(json.dumps(r) for r in rows) + "\n")
        print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
