"""Where the reconstructed air angles' error comes from, by oracle swaps (attribution only; twenty-fourth session,
s23-why).

For every flight that ``benchmarks/eval_jsbsim.py`` or the diagnosis eval left in a work directory (``*.tlog`` with its
``*-truth.npz``), the replay's estimator is run once with the inputs of the specific-force aiding captured
(:func:`benchmarks.alpha_budget.captured_aiding`), and the aiding is rerun with one slope of its force model swapped
for the one fitted on JSBSim's own regressors and coefficient (the same columns, above the same band edge):

* ``harness``: JSBSim's ``aero/alpha-rad``, ``aero/beta-rad`` against the angles of the CG's velocity relative to the
  air (``u v w`` less the NED wind rotated into body axes, :func:`cg_angles`): the harness logs the CG's motion (GPS,
  IMU at the CG), so the two must agree; and the angles at the aerodynamic reference point (``--arp X Z``, metres
  ahead of and above the CG, :func:`point_angles`), which differ by ``omega x r / V``;
* ``alpha``: ``main`` (the pipeline), ``CZa`` (the truth's ``CZ_alpha``), ``CZq`` (the truth's ``CZ_q_hat``),
  ``CZa+CZq`` and ``all`` (every CZ slope the truth's); ``beta``: ``main``, ``CYb`` (the truth's ``CY_beta``),
  ``all``, and ``profile`` (nothing swapped: ``CY_beta`` of the first pass by the gust model's likelihood, the opt-in
  :data:`gcs_sysid.estimation.airangles.BETA_PROFILE`; twenty-fifth session, i8-beta);
* for each: the error's mean and SD (deg) and its scale ``k``: the aided angle's variations are ``k`` times the true
  ones (:func:`error_stats`; a curvature in the angle then reads ``1 / k^2`` of the truth);
* ``curv``: the pitching moment's curvature in alpha read by least squares (:func:`curvature_read`, ``Cm`` on ``1,
  alpha, (alpha - mean)^2, q_hat, delta_e``) on the true, the aided and the oracle alpha: the diagnosis's
  ``Cm:alpha^2`` read at the angle's scale.

The truth is read here to attribute errors; the pipeline never reads it.

Usage::

    python benchmarks/airdata_shares.py /tmp/s24/s23-why/ej [--aircraft s23] [--arp 0.584 1.067]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: the truth regressors' columns (``benchmarks.jsbsim_harness.truth``): alpha beta p_hat q_hat r_hat de da dr dt V
_TRUTH_COL = {"alpha": 0, "beta": 1, "p_hat": 2, "q_hat": 3, "r_hat": 4, "delta_e": 5, "delta_a": 6, "delta_r": 7}


def error_stats(est: np.ndarray, true: np.ndarray, m: np.ndarray | None = None) -> dict[str, float]:
    """The error of an estimated angle against the true one on rows ``m``.

    Args:
        est, true: (T,) angles, rad. m: (T,) bool rows (None: every row where both are finite).

    Returns:
        ``mean``, ``sd``, ``rms`` of ``est - true`` (deg) and ``k``, the least-squares slope of ``est`` on ``true``
        (both less their means): the estimate's scale (1 when right; a curvature in the angle reads ``1 / k^2``).

    Raises:
        ValueError: fewer than 3 rows, or no variation in ``true``.
    """
    est, true = np.asarray(est, float), np.asarray(true, float)
    m = (np.isfinite(est) & np.isfinite(true) if m is None
         else np.asarray(m, bool) & np.isfinite(est) & np.isfinite(true))
    if m.sum() < 3:
        raise ValueError("error_stats: fewer than 3 rows")
    e, x = est[m] - true[m], true[m] - true[m].mean()
    vx = float(x @ x)
    if vx <= 0:
        raise ValueError("error_stats: the true angle does not vary")
    k = float(x @ (est[m] - est[m].mean())) / vx
    return {"mean": float(np.degrees(e.mean())), "sd": float(np.degrees(e.std())),
            "rms": float(np.degrees(np.sqrt(np.mean(e**2)))), "k": k}


def cg_angles(f: dict) -> tuple[np.ndarray, np.ndarray]:
    """alpha, beta (rad, (T,)) of the CG's velocity relative to the air, from a truth file's fields: ``u v w`` (body,
    m/s, relative to the earth), the NED wind ``wn we wd`` (m/s, steady plus turbulence) and the Euler angles
    ``phi theta psi`` (rad). ``alpha = atan2(w_a, u_a)``, ``beta = asin(v_a / |v_a|)`` (Stevens, Lewis and Johnson,
    *Aircraft Control and Simulation*, 3rd ed., 2016, eq. 2.3-6)."""
    from benchmarks.jsbsim_harness.sensors import body_from_ned

    R = body_from_ned(np.asarray(f["phi"]), np.asarray(f["theta"]), np.asarray(f["psi"]))
    w = np.einsum("tij,tj->ti", R, np.stack([f["wn"], f["we"], f["wd"]], -1))
    va = np.stack([f["u"], f["v"], f["w"]], -1) - w
    return np.arctan2(va[:, 2], va[:, 0]), np.arcsin(va[:, 1] / np.linalg.norm(va, axis=1))


def point_angles(f: dict, r_body: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """alpha, beta (rad, (T,)) of the air velocity at a point ``r_body`` (m, body axes x forward, y right, z down) from
    the CG: the CG's plus ``omega x r`` with the inertial body rates ``p q r`` (rad/s) less the air's (``p_aero`` etc.,
    where the truth file has them, else none)."""
    from benchmarks.jsbsim_harness.sensors import body_from_ned

    R = body_from_ned(np.asarray(f["phi"]), np.asarray(f["theta"]), np.asarray(f["psi"]))
    w = np.einsum("tij,tj->ti", R, np.stack([f["wn"], f["we"], f["wd"]], -1))
    va = np.stack([f["u"], f["v"], f["w"]], -1) - w
    om = np.stack([f.get(f"{a}_aero", f[a]) for a in "pqr"], -1)
    va = va + np.cross(om, np.asarray(r_body, float)[None, :])
    return np.arctan2(va[:, 2], va[:, 0]), np.arcsin(va[:, 1] / np.linalg.norm(va, axis=1))


def curvature_read(alpha: np.ndarray, X: np.ndarray, Cm: np.ndarray, m: np.ndarray) -> float:
    """The curvature of ``Cm`` in alpha by least squares on ``1, alpha, (alpha - mean)^2, q_hat, delta_e`` (1/rad^2).

    Args:
        alpha: (T,) alpha used as the regressor, rad. X: (T, >= 6) truth regressors (``q_hat`` column 3, ``delta_e``
        column 5). Cm: (T,) the coefficient. m: (T,) bool rows.
    """
    a = np.asarray(alpha, float)
    ac = a - a[m].mean()
    A = np.c_[np.ones(int(m.sum())), ac[m], ac[m] ** 2, X[m][:, 3], X[m][:, 5]]
    return float(np.linalg.lstsq(A, Cm[m], rcond=None)[0][2])


def _truth_slopes(Xi: np.ndarray, y: np.ndarray, cols: tuple[str, ...], ctr: float, m: np.ndarray, dt: float,
                  edge: float) -> np.ndarray:
    """The aiding's slopes fitted on the truth's regressors above ``edge`` Hz (``(alpha - alpha0)^2`` with ``ctr``)."""
    from benchmarks.alpha_budget import _highpass

    A = np.column_stack([(Xi[:, 0] - ctr) ** 2 if c == "(alpha - alpha0)^2" else Xi[:, _TRUTH_COL[c]] for c in cols])
    return np.linalg.lstsq(_highpass(A[m], dt, edge), _highpass(y[m][:, None], dt, edge)[:, 0], rcond=None)[0]


def shares(tlog: Path, aircraft: str, arp: tuple[float, float] | None = None,
           stated: tuple[float, float | None] | None = None) -> list[str]:
    """The lines of one flight (see the module docstring); ``stated``: ``(CL_alpha, CL_q)`` adds the line ``stated``,
    the aiding with that stated lift-slope floor (:func:`gcs_sysid.estimation.airangles.aided_air_angles`
    ``stated_slopes``; its passes fit as the pipeline's, nothing swapped)."""
    import gcs_sysid.estimation.airangles as aa
    from benchmarks.alpha_budget import captured_aiding
    from benchmarks.jsbsim_harness.truth import load_truth

    st, args, kw = captured_aiding(tlog, aircraft)
    if args is None:
        return [f"{tlog.stem}: the estimator did not reach the aiding"]
    tr = load_truth(tlog.with_name(tlog.stem + "-truth.npz"))
    out = [f"{tlog.stem}:"]
    ac, bc = cg_angles(tr.fields)
    line = (f"  harness: JSBSim alpha/beta - CG air angles RMS "
            f"{np.degrees(np.sqrt(np.mean((ac - tr.fields['alpha'])**2))):.4f}"
            f" / {np.degrees(np.sqrt(np.mean((bc - tr.fields['beta'])**2))):.4f} deg")
    if arp is not None:
        ap, bp = point_angles(tr.fields, (arp[0], 0.0, -arp[1]))
        line += (f"; at the reference point ({arp[0]:.2f} m ahead, {arp[1]:.2f} m above) - CG: RMS "
                 f"{np.degrees(np.sqrt(np.mean((ap - ac)**2))):.4f} / "
                 f"{np.degrees(np.sqrt(np.mean((bp - bc)**2))):.4f} deg")
    out.append(line)
    t, dt, use = st.t, args[0], args[12]
    Xi = np.stack([np.interp(t, tr.t, x, left=np.nan, right=np.nan) for x in tr.X.T], 1)
    Y = np.stack([np.interp(t, tr.t, y, left=np.nan, right=np.nan) for y in tr.Y.T], 1)
    r0 = aa.aided_air_angles(*args, **kw)
    fa, fb = r0.axes
    m = use & np.isfinite(Xi).all(1) & np.isfinite(Y).all(1) & np.isfinite(r0.alpha) & np.isfinite(r0.beta)

    def fmt(name, r, c, which):
        s = error_stats(r.alpha if which == "alpha" else r.beta, Xi[:, 0 if which == "alpha" else 1], m)
        extra = f" | Cm curvature {curvature_read(r.alpha, Xi, Y[:, 4], m):+.2f}" if which == "alpha" else ""
        return (f"  {which:5s} {name:8s} slopes {np.array2string(np.asarray(c), precision=2)} mean {s['mean']:+.3f} "
                f"sd {s['sd']:.3f} k {s['k']:.3f}" + extra)

    if fa.used and len(fa.columns) > 2:
        cols = tuple(fa.columns[1:])
        ct = _truth_slopes(Xi, Y[:, 2], cols, float(np.mean(args[1][m])), m, dt, fa.band_hz or aa.HIGHPASS_HZ)
        fit = np.asarray(fa.coef[1:], float)
        iq = cols.index("q_hat") if "q_hat" in cols else None
        out.append(f"  alpha    true alpha: Cm curvature {curvature_read(Xi[:, 0], Xi, Y[:, 4], m):+.2f}")
        cands = {"main": fit, "CZa": np.r_[ct[0], fit[1:]]}
        if iq is not None:
            cands["CZq"] = np.where(np.arange(len(fit)) == iq, ct, fit)
            cands["CZa+CZq"] = np.where(np.isin(np.arange(len(fit)), [0, iq]), ct, fit)
        cands["all"] = ct
        for name, c in cands.items():
            g = aa.AxisFit("alpha", True, "", fa.columns, np.r_[0.0, c], np.zeros(len(fa.columns)))
            r = r0 if name == "main" else aa.aided_air_angles(*args, **dict(kw, models={"alpha": g}))
            out.append(fmt(name, r, c, "alpha"))
        if stated is not None:
            r = aa.aided_air_angles(*args, **dict(kw, stated_slopes=tuple(stated)))
            out.append(fmt("stated", r, r.axes[0].coef[1:], "alpha"))
    if fb.used and len(fb.columns) > 2:
        cols = tuple(fb.columns[1:])
        ct = _truth_slopes(Xi, Y[:, 1], cols, 0.0, m, dt, fb.band_hz or aa.HIGHPASS_HZ)
        fit = np.asarray(fb.coef[1:], float)
        orig = aa._axis
        for name, c in {"main": fit, "CYb": np.r_[ct[0], fit[1:]], "all": ct}.items():
            if name == "main":
                out.append(fmt(name, r0, c, "beta"))
                continue
            g = aa.AxisFit("beta", True, "", fb.columns, np.r_[0.0, c], np.zeros(len(fb.columns)))

            def axis(nm, *a, _g=g, **k):    # the beta axis's slopes given (aided_air_angles passes none for beta)
                return orig(nm, *a, **(dict(k, given=_g) if nm == "beta" else k))

            aa._axis = axis
            try:
                out.append(fmt(name, aa.aided_air_angles(*args, **kw), c, "beta"))
            finally:
                aa._axis = orig
        r = aa.aided_air_angles(*args, **dict(kw, profile_beta=True))
        out.append(fmt("profile", r, r.axes[1].coef[1:], "beta"))
    return out


def main(argv: list[str] | None = None) -> int:
    from benchmarks.alpha_budget import flown_logs, work_parser

    ap = work_parser(__doc__.splitlines()[0])
    ap.add_argument("--arp", nargs=2, type=float, default=None, metavar=("AHEAD_M", "ABOVE_M"),
                    help="the aerodynamic reference point's offset from the CG, m (s23: 0.584 1.067)")
    ap.add_argument("--stated", nargs="+", type=float, default=None, metavar="CL",
                    help="CL_alpha (1/rad) [CL_q (per q_hat)]: add the aiding with this stated lift-slope floor")
    a = ap.parse_args(argv)
    st = None if a.stated is None else (a.stated[0], a.stated[1] if len(a.stated) > 1 else None)
    for tlog, ac, _ in flown_logs(a.work, a.aircraft, a.turbulence):
        print("\n".join(shares(tlog, ac, a.arp, st)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
