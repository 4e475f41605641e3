"""The side-force model's slopes and the aided sideslip against the band edge (nineteenth session, i8-betaband;
issue 8: the learned ``CY_r_hat`` of -0.5..-1.9 where JSBSim has 0..+1).

The hypothesis tested: the lateral analogue of alpha's heave band (``docs/estimation.md``, "The slopes' band and the
heave mode"). Below the directional (weathercock) corner the aircraft yaws into a side gust, so the kinematic
sideslip's gust error would be correlated with ``r_hat`` there and not above; fitting the side-force model's slopes
above the corner would then take the gust's side force off ``r_hat``. For every ``*.tlog`` with its ``*-truth.npz``
in the given eval_jsbsim work directories the replay's estimator is run once with the inputs of
:func:`gcs_sysid.estimation.airangles.aided_air_angles` captured, and

* ``edges``: the aiding is rerun with the side-force slopes fitted above each edge (``beta_band_hz``; ``wc`` is the
  flight's directional corner below): the fitted ``CY_beta``, ``CY_r_hat``, the aided sideslip's error SD against
  JSBSim's ``aero/beta-rad`` (deg) and its scale (least-squares slope of the aided on the true sideslip, centred);
* ``gust``: the kinematic sideslip's error ``g = beta_true - beta_kin`` regressed, band by band, on the model's
  columns (``beta_kin, p_hat, r_hat, delta_a, delta_r``; :func:`gust_regression`). By the omitted-variable formula
  least squares of ``CY`` on those columns gives ``CY_r_hat + CY_beta x (g on r_hat)`` (Greene, *Econometric
  Analysis*, 7th ed., 2012, sec. 4.3.2), so the coefficient on ``r_hat`` times JSBSim's ``CY_beta`` predicts the
  fitted ``CY_r_hat``'s bias in each band;
* ``wc``: the directional corner from the log alone, ``sqrt(qbar S b Cn_beta / I_zz) / (2 pi)`` (the weathercock
  frequency, Etkin, *Dynamics of Atmospheric Flight*, 1972, sec. 9.4), ``Cn_beta`` fitted above 0.3 Hz on the
  kinematic sideslip from Euler's moment equations (:func:`directional_hz`); JSBSim's own ``Cn_beta`` gives the
  same corner to within 0.01-0.14 Hz on the five aircraft measured (rascal 0.60-0.65 against 0.74).

The truth is read here to attribute errors; the pipeline never reads it.

Usage::

    python benchmarks/beta_band.py DIR [DIR ...] [--aircraft rascal] [--turbulence light] [--json F]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfiltfilt

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import gcs_sysid.estimation.airangles as aa  # noqa: E402
from benchmarks.alpha_budget import captured_aiding, flown_logs, work_parser  # noqa: E402
from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.jsbsim_harness.truth import load_truth  # noqa: E402

COLUMNS = ("beta", "p_hat", "r_hat", "delta_a", "delta_r")     #: the side-force model's columns (airangles)
EDGES = ("0.3", "0.4", "0.5", "0.8", "1.2", "wc")               #: slope band edges tried, Hz ("wc": the corner)
BANDS = ((0.3, None), (0.3, 0.6), (0.6, 1.2), (1.2, 2.4))      #: bands of the gust regression, Hz (None: open)


def band(x: np.ndarray, dt: float, lo: float, hi: float | None) -> np.ndarray:
    """``x`` (T,) or (T, k) band-passed between ``lo`` and ``hi`` Hz (None: high-pass only): zero-phase fourth-order
    Butterworth along axis 0, the mean removed first."""
    y = sosfiltfilt(butter(4, lo, "highpass", fs=1 / dt, output="sos"), x - x.mean(axis=0), axis=0)
    return y if hi is None else sosfiltfilt(butter(4, hi, "lowpass", fs=1 / dt, output="sos"), y, axis=0)


def gust_regression(dt: float, g: np.ndarray, X: np.ndarray, lo: float, hi: float | None) -> np.ndarray:
    """Least-squares coefficients of ``g`` (T,) on the columns of ``X`` (T, k), both band-passed (:func:`band`).

    A constant column (SD below 1e-9) gets NaN and is left out. Rows must be one contiguous, finite record.

    Raises:
        ValueError: ``g`` and ``X`` differ in length or hold a non-finite value.
    """
    g, X = np.asarray(g, float), np.asarray(X, float)
    if X.ndim != 2 or len(g) != len(X):
        raise ValueError(f"g {g.shape} and X {X.shape}: need (T,) and (T, k)")
    if not (np.isfinite(g).all() and np.isfinite(X).all()):
        raise ValueError("g and X must be finite (one contiguous record)")
    keep = X.std(axis=0) > 1e-9
    out = np.full(X.shape[1], np.nan)
    if keep.any():
        out[keep] = np.linalg.lstsq(band(X[:, keep], dt, lo, hi), band(g, dt, lo, hi), rcond=None)[0]
    return out


def directional_hz(dt: float, beta: np.ndarray, X_other: np.ndarray, Cn: np.ndarray, qbar: float, S: float,
                   b: float, Izz: float, edge_hz: float = 0.3) -> tuple[float, float]:
    """The weathercock (directional) corner from the log: ``sqrt(qbar S b Cn_beta / I_zz) / (2 pi)``, Hz.

    Args:
        dt: grid step, s. beta: (T,) sideslip, rad. X_other: (T, k) the other columns of the yawing-moment model
            (``p_hat, r_hat, delta_a, delta_r``). Cn: (T,) yawing-moment coefficient (Euler's equations).
        qbar: dynamic pressure, Pa (the flight's median). S: wing area, m^2. b: span, m. Izz: kg m^2.
        edge_hz: ``Cn_beta`` is fitted above this edge (:func:`gust_regression`).

    Returns:
        ``(f, Cn_beta)``: the corner, Hz (0 for a negative ``Cn_beta``: directionally unstable), and the slope, 1/rad.

    Source: Etkin, *Dynamics of Atmospheric Flight*, 1972, sec. 9.4 (the directional stiffness ``N_beta``).
    """
    cn_beta = float(gust_regression(dt, Cn, np.column_stack([beta, X_other]), edge_hz, None)[0])
    nb = qbar * S * b * cn_beta / Izz
    return float(np.sqrt(max(nb, 0.0)) / (2 * np.pi)), cn_beta


def flight(tlog: Path, aircraft: str, edges: tuple[str, ...] = EDGES) -> dict:
    """Both measurements of the module docstring for one flight (angles in deg, slopes per rad).

    Raises:
        ValueError: the estimator did not reach the aiding (no aided angles to measure).
    """
    st, a, kw = captured_aiding(tlog, aircraft)
    if a is None:
        raise ValueError(f"{tlog.stem}: the estimator did not reach the aiding")
    dt, bkin, V, qbar, rates, ctrl, S, b, use = a[0], a[2], a[3], a[4], a[6], a[7], a[9], a[10], a[12]
    tr = load_truth(tlog.with_name(tlog.stem + "-truth.npz"))
    bt = np.interp(st.t, tr.t, tr.X[:, 1], left=np.nan, right=np.nan)
    z = np.zeros_like(V)
    X = np.column_stack([bkin, rates[:, 0] * b / (2 * V), rates[:, 2] * b / (2 * V), ctrl.get("delta_a", z),
                         ctrl.get("delta_r", z)])
    m = use & np.all(np.isfinite(X), 1) & np.isfinite(bt)
    out: dict = {"flight": tlog.stem, "true_sd": float(np.degrees(bt[m].std())),
                 "kin_err_sd": float(np.degrees((bkin - bt)[m].std()))}
    I, rd = kw.get("inertia"), kw.get("rate_dot")
    if I is not None and rd is not None:
        Mb = rd @ I.T + np.cross(rates, rates @ I.T)
        with np.errstate(invalid="ignore", divide="ignore"):
            Cn = Mb[:, 2] / (qbar * S * b)
        mc = m & np.isfinite(Cn)
        out["wc_hz"], out["Cn_beta"] = directional_hz(dt, bkin[mc], X[mc, 1:], Cn[mc], float(np.median(qbar[mc])),
                                                      S, b, float(I[2, 2]))
    out["gust"] = {f"{lo}-{hi or ''}": dict(zip(COLUMNS, map(float, gust_regression(dt, (bt - bkin)[m], X[m], lo, hi))))
                   for lo, hi in BANDS}
    x = bt[m] - bt[m].mean()
    out["edges"] = {}
    for e in edges:
        f = out.get("wc_hz", np.nan) if e == "wc" else float(e)
        if not np.isfinite(f):
            continue
        r = aa.aided_air_angles(*a, **dict(kw, beta_band_hz=f))
        fb = r.axes[1]
        d = {"edge_hz": max(f, aa.HIGHPASS_HZ), "used": bool(fb.used)}
        if fb.used:
            d.update({c: float(v) for c, v in zip(fb.columns, fb.coef)})
        err = (r.beta - bt)[m]
        d["err_sd"] = float(np.degrees(err.std()))
        d["scale"] = float(np.dot(r.beta[m] - r.beta[m].mean(), x) / np.dot(x, x))
        out["edges"][e] = d
    return out


def show(r: dict) -> tuple[str, str]:
    """One flight as two markdown rows: the edges' ``CY_beta / CY_r_hat / error SD / scale`` (:data:`EDGES`), and
    the gust regression's ``g on beta_kin / g on r_hat`` per band (:data:`BANDS`)."""
    def cell(d):
        if not d.get("used"):
            return "not aided"
        return f"{d.get('beta', np.nan):.2f} / {d.get('r_hat', np.nan):.2f} / {d['err_sd']:.2f} / {d['scale']:.2f}"
    head = f"| {r['flight']} | {r['true_sd']:.2f} | {r['kin_err_sd']:.2f} | {r.get('wc_hz', np.nan):.2f} | "
    e = head + " | ".join(cell(r["edges"].get(k, {})) for k in EDGES) + " |"
    g = f"| {r['flight']} | " + " | ".join(f"{v['beta']:+.2f} / {v['r_hat']:+.2f}" for v in r["gust"].values()) + " |"
    return e, g


def main(argv: list[str] | None = None) -> int:
    a = work_parser(__doc__.split("\n")[0], json_out=True).parse_args(argv)
    print("| flight | true SD | kin err SD | wc Hz | " + " | ".join(f"edge {k}" for k in EDGES) + " |")
    print("|---" * (4 + len(EDGES)) + "|")
    gust = []
    for tlog, ac, _ in flown_logs(a.work, a.aircraft, a.turbulence):
        r = flight(tlog, ac)
        e, g = show(r)
        print(e, flush=True)
        gust.append(g)
        append_jsonl(a.json, [r])
    print("\n| flight | " + " | ".join(f"{lo}-{hi or ''} Hz: g on beta_kin / r_hat" for lo, hi in BANDS) + " |")
    print("|---" * (1 + len(BANDS)) + "|")
    print("\n".join(gust))
    return 0


if __name__ == "__main__":
    sys.exit(main())
