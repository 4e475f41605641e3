"""The reconstructed alpha's error by stage and by kind on eval_jsbsim's flights (attribution only; eighteenth
session, i8-alpha; issue 8 item 2).

For every ``*.tlog`` with its ``*-truth.npz`` in the given directories the replay's estimator is run once with the
inputs of the specific-force aiding (:func:`gcs_sysid.estimation.airangles.aided_air_angles`) and the windowed wind
(:func:`gcs_sysid.estimation.airdata.estimate_wind`) captured. Each stage's alpha is compared with JSBSim's
``aero/alpha-rad`` (gusts included) on the aided rows, and its error ``e = a - a_true`` (rad) split into

* ``off``: the mean of ``e``;
* ``scl``: ``b - 1``, ``b`` the least-squares slope of the estimate on the truth (both centred), and ``rms(scl)``,
  the RMS of ``(b - 1)(a_true - mean)``, deg;
* ``lf``: the rest's RMS below 0.05 Hz (zero-phase second-order Butterworth: the wander), deg;
* ``hf``: the rest's RMS above 0.05 Hz (the gust band), deg.

Stages (one exact quantity swapped at a time):

* ``T0``: alpha rebuilt from JSBSim's ground velocity, attitude and total wind (sanity: 0);
* ``Tkin``: the same with the vertical wind set to 0: the best any kinematic alpha can be (misses ``w_d / V``);
* ``Tkin30``: ``Tkin`` with the horizontal wind averaged over the estimator's 30-s windows;
* ``kin``: the pipeline's kinematic alpha (GPS velocity, attitude, the estimated wind);
* ``aided``: the pipeline's aided alpha (the replay's);
* ``aid|Tkin``: the aiding run on ``Tkin`` in place of ``kin`` (the kinematic inputs' own errors removed);
* ``aid|slope``: the aiding given the CZ slopes fitted on JSBSim's regressors and coefficient (same band);
* ``pct_CZ_aided``, ``pct_Cm_aided``: ``|C_alpha x offset| / RMS(C)`` in %, what the offset alone costs a model
  learned on the flight at the true alpha in eval_jsbsim's ``error_pct`` (``C_alpha`` fitted on the truth);
* ``aid|mean``: the aiding with ``airangles.KINEMATIC_MEAN`` on (its mean kept at the kinematic alpha's);
* ``aid|V``: the aiding with JSBSim's airspeed and dynamic pressure.

Also per flight: the truth's alpha SD, the flight-mean ``w_d / V`` (deg), the mean flight-path angle (deg), the
estimated wind's mean and RMS error against JSBSim's horizontal total wind low-passed at 1/30 Hz (m/s), the ratio
of the pipeline's airspeed to JSBSim's, and ``dCZ``: the true ``CZ_alpha`` times the aided offset over the SD of
JSBSim's CZ (the share by which a model learned on the flight misses CZ at the true alpha).

The truth is read here to attribute errors; the pipeline never reads it.

Usage::

    python benchmarks/alpha_stages.py DIR [DIR ...] [--aircraft rascal] [--turbulence light]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfiltfilt

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import gcs_sysid.estimation.airangles as aa  # noqa: E402
import gcs_sysid.estimation.estimate as est  # noqa: E402
from benchmarks.alpha_budget import _highpass, flown_logs, work_parser  # noqa: E402
from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.jsbsim_harness.truth import load_truth  # noqa: E402
from gcs_sysid.airframe import load_airframe  # noqa: E402
from gcs_sysid.telemetry import read_log  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
LF_HZ = 0.05


def dcm(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """(T, 3, 3) body-to-NED direction cosines from 3-2-1 Euler angles, rad (Stevens, Lewis and Johnson 2016,
    ch. 1)."""
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    C = np.empty((len(phi), 3, 3))
    C[:, 0] = np.stack([ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp], 1)
    C[:, 1] = np.stack([ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp], 1)
    C[:, 2] = np.stack([-st, sf * ct, cf * ct], 1)
    return C


def split(a: np.ndarray, at: np.ndarray, m: np.ndarray, dt: float) -> dict:
    """The error of ``a`` against ``at`` (both (T,), rad) on rows ``m`` split as in the module docstring; deg."""
    e = (a - at)[m]
    x = at[m] - at[m].mean()
    b = float(np.dot(a[m] - a[m].mean(), x) / np.dot(x, x))
    r = e - e.mean() - (b - 1.0) * x
    lo = sosfiltfilt(butter(2, LF_HZ, "lowpass", fs=1 / dt, output="sos"), r)
    d = np.degrees
    return {"rms": float(d(np.sqrt(np.mean(e**2)))), "off": float(d(e.mean())), "scl": b - 1.0,
            "rms_scl": float(d(abs(b - 1.0) * np.sqrt(np.mean(x**2)))), "lf": float(d(np.sqrt(np.mean(lo**2)))),
            "hf": float(d(np.sqrt(np.mean((r - lo) ** 2))))}


def stages(tlog: Path, aircraft: str) -> dict:
    """Every stage's split and the flight's facts (see the module docstring) for one flight."""
    cap: dict = {}
    orig_aid, orig_wind = est.aided_air_angles, est.estimate_wind

    def cap_aid(*a, **k):
        cap["a"], cap["k"] = a, k
        return orig_aid(*a, **k)

    def cap_wind(*a, **k):
        cap["w"] = orig_wind(*a, **k)
        return cap["w"]

    est.aided_air_angles, est.estimate_wind = cap_aid, cap_wind
    try:
        st = est.estimate_states(read_log(tlog), load_airframe(REPO / "data" / "airframes" / f"jsbsim-{aircraft}.toml"))
    finally:
        est.aided_air_angles, est.estimate_wind = orig_aid, orig_wind
    args, kw = cap["a"], cap["k"]
    dt, akin, use = args[0], args[1], args[12]
    tr = load_truth(tlog.with_name(tlog.stem + "-truth.npz"))
    t = st.t
    f = tr.fields
    ip = lambda x: np.interp(t, tr.t, x, left=np.nan, right=np.nan)  # noqa: E731
    at, Vt = ip(f["alpha"]), ip(f["V"])
    C = dcm(ip(f["phi"]), ip(f["theta"]), np.unwrap(f["psi"])[np.searchsorted(tr.t, np.clip(t, tr.t[0], tr.t[-1]))])
    vg = np.stack([ip(f[k]) for k in ("vn", "ve", "vd")], 1)
    wt = np.stack([ip(f[k]) for k in ("wn", "we", "wd")], 1)
    fa = st.angle_fits.get("alpha")
    m = use & np.isfinite(at) & np.isfinite(st.data["alpha"]) & np.all(np.isfinite(vg), 1)

    def kin_alpha(w):
        vb = np.einsum("tji,tj->ti", C, vg - w)
        return np.arctan2(vb[:, 2], vb[:, 0])

    w0 = wt.copy()
    w0[:, 2] = 0.0
    lp30 = butter(2, 1 / 30.0, "lowpass", fs=1 / dt, output="sos")
    wlp = w0.copy()
    ok = np.all(np.isfinite(w0), 1)
    wlp[ok, :2] = sosfiltfilt(lp30, w0[ok, :2], axis=0)
    out = {"flight": tlog.stem, "sd": float(np.degrees(at[m].std())),
           "wV": float(np.degrees(np.mean(wt[m, 2] / Vt[m]))),
           "gamma": float(np.degrees(np.mean(np.arcsin(np.clip(-vg[m, 2] / np.linalg.norm(vg[m], axis=1), -1, 1))))),
           "V": float(Vt[m].mean()), "Vratio": float(np.mean(args[3][m] / Vt[m]))}
    S = {"T0": split(kin_alpha(wt), at, m, dt), "Tkin": split(kin_alpha(w0), at, m, dt),
         "Tkin30": split(kin_alpha(wlp), at, m, dt), "kin": split(akin, at, m, dt),
         "aided": split(st.data["alpha"], at, m, dt)}
    if "w" in cap:
        we = cap["w"].wind[:, :2]
        d = (we - wlp[:, :2])[m]
        out["wind_mean_err"] = [float(x) for x in d.mean(0)]
        out["wind_rms_err"] = float(np.sqrt(np.mean(np.sum(d**2, 1))))
    if fa is not None and fa.used:
        a2 = list(args)
        a2[1] = kin_alpha(w0)
        S["aid|Tkin"] = split(aa.aided_air_angles(*a2, **kw).alpha, at, m, dt)
        Xi = np.stack([ip(x) for x in tr.X.T], 1)
        ctr = float(np.mean(akin[m]))
        A = np.column_stack([Xi[:, 0], (Xi[:, 0] - ctr) ** 2, Xi[:, 3], Xi[:, 5]])[m]
        ct, *_ = np.linalg.lstsq(_highpass(A, dt, fa.band_hz), _highpass(ip(tr.Y[:, 2])[m], dt, fa.band_hz),
                                 rcond=None)
        out["CZ_alpha_fit"], out["CZ_alpha_true"] = float(fa.coef[1]), float(ct[0])
        out["dCZ"] = float(abs(ct[0] * np.radians(S["aided"]["off"])) / np.nanstd(ip(tr.Y[:, 2])[m]))
        # what the offset alone costs a model at the true alpha, in eval_jsbsim's error_pct (RMS error over RMS
        # of the true coefficient): |C_alpha x offset| / RMS(C), with C_alpha of CZ and Cm fitted on the truth
        B = np.column_stack([Xi[:, 0], Xi[:, 3], Xi[:, 5]])[m]
        for j, cname in ((2, "CZ"), (4, "Cm")):
            yt = ip(tr.Y[:, j])[m]
            cj, *_ = np.linalg.lstsq(_highpass(B, dt, fa.band_hz), _highpass(yt, dt, fa.band_hz), rcond=None)
            out[f"{cname}_alpha_true_lin"] = float(cj[0])     # linear fit (alpha, q_hat, delta_e)
            for k in ("aided", "kin"):
                out[f"pct_{cname}_{k}"] = float(100 * abs(cj[0] * np.radians(S[k]["off"])) / np.sqrt(np.mean(yt**2)))
        if len(fa.columns) == 5:
            given = aa.AxisFit("alpha", True, "", fa.columns, np.r_[0.0, ct], np.zeros(5))
            S["aid|slope"] = split(aa.aided_air_angles(*args, **dict(kw, models={"alpha": given})).alpha, at, m, dt)
        saved = aa.KINEMATIC_MEAN
        aa.KINEMATIC_MEAN = True
        try:
            S["aid|mean"] = split(aa.aided_air_angles(*args, **kw).alpha, at, m, dt)
        finally:
            aa.KINEMATIC_MEAN = saved
        a3 = list(args)
        a3[3], a3[4] = Vt, 0.5 * ip(f["rho"]) * Vt**2
        S["aid|V"] = split(aa.aided_air_angles(*a3, **kw).alpha, at, m, dt)
        out["note"] = fa.reason if hasattr(fa, "reason") else ""
    out["stages"] = S
    return out


def show(r: dict) -> str:
    """One flight's result as text lines."""
    head = (f"{r['flight']}: true alpha sd {r['sd']:.2f} deg, mean w_d/V {r['wV']:+.2f} deg, gamma {r['gamma']:+.1f} "
            f"deg, V {r['V']:.1f} m/s, V est/true {r['Vratio']:.3f}")
    if "wind_rms_err" in r:
        we = r["wind_mean_err"]
        head += f", wind err mean {we[0]:+.2f} {we[1]:+.2f} rms {r['wind_rms_err']:.2f} m/s"
    if "CZ_alpha_fit" in r:
        head += f", CZ_alpha fit {r['CZ_alpha_fit']:+.2f} true {r['CZ_alpha_true']:+.2f}, dCZ {r['dCZ']:.2f}"
    lines = [head]
    for k, s in r["stages"].items():
        lines.append(f"  {k:10s} rms {s['rms']:6.3f} off {s['off']:+7.3f} scl {s['scl']:+6.3f} ({s['rms_scl']:.3f}) "
                     f"lf {s['lf']:.3f} hf {s['hf']:.3f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    a = work_parser(__doc__.split("\n")[0], json_out=True).parse_args(argv)
    for tlog, ac, _ in flown_logs(a.work, a.aircraft, a.turbulence):
        r = stages(tlog, ac)
        print(show(r), flush=True)
        append_jsonl(a.json, [r])
    return 0


if __name__ == "__main__":
    sys.exit(main())
