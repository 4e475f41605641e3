"""The reconstructed alpha's error budget on eval_jsbsim's flights (attribution only; fourteenth session, i8-alpha).

For every flight that ``benchmarks/eval_jsbsim.py`` left in a work directory (``*.tlog`` with its
``*-truth.npz``), the replay's estimator is run once with the inputs of the specific-force aiding captured
(:func:`gcs_sysid.estimation.airangles.aided_air_angles`), and the aided alpha is compared with JSBSim's
(``aero/alpha-rad``, gusts included), all airborne rows:

* ``mean`` and ``w/V``: the error's mean and the flight-mean vertical wind over the airspeed (unobservable:
  ``docs/estimation.md``, "What the reconstructed alpha's error is made of");
* ``sd`` and the bands below 0.05, 0.05-0.2, 0.2-2 and above 2 Hz (zero-phase second-order Butterworth) of the
  error less its mean, deg;
* ``kin``: the same for the kinematic alpha;
* ``slopes``: the aiding's fitted CZ slopes (``CZ_alpha``, curvature, ``CZ_q_hat``, ``CZ_delta_e``), the band edge,
  and the same slopes fitted on JSBSim's own regressors and coefficient (the truth);
* swaps, one exact quantity at a time: ``trueslope`` (the aiding with the truth's slopes as a given model,
  ``aided_air_angles(models=)``), ``trueV`` (JSBSim's airspeed and dynamic pressure: EAS/TAS, pitot),
  ``fixed`` (the band edge fixed at ``HIGHPASS_HZ``, as before the fourteenth session).

The truth is read here to attribute errors; the pipeline never reads it.

Usage::

    python benchmarks/alpha_budget.py /tmp/i8-alpha/ej [--aircraft rascal] [--turbulence light]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfiltfilt

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import gcs_sysid.estimation.airangles as aa  # noqa: E402
import gcs_sysid.estimation.estimate as est  # noqa: E402
from benchmarks.jsbsim_harness.truth import load_truth  # noqa: E402
from gcs_sysid.airframe import load_airframe  # noqa: E402
from gcs_sysid.telemetry import read_log  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
EDGES_HZ = (0.05, 0.2, 2.0)


def bands_deg(e: np.ndarray, dt: float, edges: tuple[float, ...] = EDGES_HZ) -> list[float]:
    """RMS (deg) of ``e`` (T,) rad, less its mean, in the bands cut at ``edges`` (Hz): below the first, between,
    above the last (zero-phase second-order Butterworth)."""
    e = e - e.mean()
    out, lo = [], None
    for hi in list(edges) + [None]:
        if lo is None:
            sos = butter(2, hi, "lowpass", fs=1 / dt, output="sos")
        elif hi is None:
            sos = butter(2, lo, "highpass", fs=1 / dt, output="sos")
        else:
            sos = butter(2, [lo, hi], "bandpass", fs=1 / dt, output="sos")
        out.append(float(np.degrees(np.sqrt(np.mean(sosfiltfilt(sos, e) ** 2)))))
        lo = hi
    return out


def _line(name: str, a: np.ndarray, at: np.ndarray, m: np.ndarray, dt: float) -> str:
    e = (a - at)[m]
    return (f"  {name:9s} rms {np.degrees(np.sqrt(np.mean(e**2))):.3f} mean {np.degrees(e.mean()):+.3f} "
            f"sd {np.degrees(e.std()):.3f} | " + " ".join(f"{x:.3f}" for x in bands_deg(e, dt)))


def _highpass(x: np.ndarray, dt: float, edge: float) -> np.ndarray:
    sos = butter(2, edge, "highpass", fs=1 / dt, output="sos")
    return sosfiltfilt(sos, x - x.mean(axis=0), axis=0)


def captured_aiding(tlog: Path, aircraft: str) -> tuple:
    """Run the replay's estimator on ``tlog`` with the JSBSim airframe of ``aircraft`` and capture the inputs of the
    specific-force aiding: ``(states, args, kwargs)`` of the
    :func:`gcs_sysid.estimation.airangles.aided_air_angles` call (``args`` None where the estimator did not reach
    the aiding)."""
    cap: dict = {}
    orig = est.aided_air_angles

    def capture(*a, **k):
        cap["a"], cap["k"] = a, k
        return orig(*a, **k)

    est.aided_air_angles = capture
    try:
        st = est.estimate_states(read_log(tlog), load_airframe(REPO / "data" / "airframes" / f"jsbsim-{aircraft}.toml"))
    finally:
        est.aided_air_angles = orig
    return st, cap.get("a"), cap.get("k")


def budget(tlog: Path, aircraft: str) -> str:
    """The budget of one flight as text (see the module docstring)."""
    st, args, kw = captured_aiding(tlog, aircraft)
    if args is None:
        return f"{tlog.stem}: the estimator did not reach the aiding"
    dt, akin, _, _, _, _, rates, ctrl, _, _, _, c, use = args[:13]
    tr = load_truth(tlog.with_name(tlog.stem + "-truth.npz"))
    t = st.t
    ip = lambda x: np.interp(t, tr.t, x, left=np.nan, right=np.nan)  # noqa: E731
    at, Vt, wd = ip(tr.fields["alpha"]), ip(tr.fields["V"]), ip(tr.fields["wd"])
    m = use & np.isfinite(at) & np.isfinite(st.data["alpha"])
    fa = st.angle_fits.get("alpha")
    e0, e1, e2 = EDGES_HZ
    out = [f"{tlog.stem}: alpha sd {np.degrees(at[m].std()):.3f} deg, w/V {np.degrees(np.mean(wd[m] / Vt[m])):+.3f} "
           f"deg, V {Vt[m].mean():.1f} m/s; bands < {e0} / {e0}-{e1} / {e1}-{e2} / > {e2} Hz"]
    out.append(_line("aided", st.data["alpha"], at, m, dt))
    out.append(_line("kin", akin, at, m, dt))
    if fa is None or not fa.used:
        out.append(f"  alpha not aided: {fa.reason if fa is not None else 'no fit'}")
        return "\n".join(out)
    Xi = np.stack([ip(x) for x in tr.X.T], 1)
    ctr = float(np.mean(akin[m]))
    A = np.column_stack([Xi[:, 0], (Xi[:, 0] - ctr) ** 2, Xi[:, 3], Xi[:, 5]])[m]
    ct, *_ = np.linalg.lstsq(_highpass(A, dt, fa.band_hz), _highpass(ip(tr.Y[:, 2])[m], dt, fa.band_hz), rcond=None)
    out.append(f"  slopes above {fa.band_hz:.2f} Hz: fitted {np.round(fa.coef[1:], 3)}, on the truth {np.round(ct, 3)}")
    if len(fa.columns) == 5:
        given = aa.AxisFit("alpha", True, "", fa.columns, np.r_[0.0, ct], np.zeros(5))
        out.append(_line("trueslope", aa.aided_air_angles(*args, **dict(kw, models={"alpha": given})).alpha, at, m, dt))
    a2 = list(args)
    a2[3], a2[4] = Vt, 0.5 * ip(tr.fields["rho"]) * Vt**2
    out.append(_line("trueV", aa.aided_air_angles(*a2, **kw).alpha, at, m, dt))
    saved = aa.HEAVE_EDGE
    aa.HEAVE_EDGE = None
    try:
        out.append(_line("fixed", aa.aided_air_angles(*args, **kw).alpha, at, m, dt))
    finally:
        aa.HEAVE_EDGE = saved
    return "\n".join(out)


def flown_logs(work: list[str], aircraft: str | None = None, turbulence: str | None = None):
    """The eval_jsbsim flights in the work directories ``work`` that have their truth file beside them.

    Yields ``(tlog Path, aircraft name, turbulence level)`` read from the file name
    (``<aircraft>-<turbulence>-...tlog``), sorted per directory, only ``aircraft`` / ``turbulence`` where given.
    """
    for w in work:
        for tlog in sorted(Path(w).glob("*.tlog")):
            ac, turb = tlog.stem.split("-")[:2]
            if (aircraft and ac != aircraft) or (turbulence and turb != turbulence):
                continue
            if tlog.with_name(tlog.stem + "-truth.npz").exists():
                yield tlog, ac, turb


def work_parser(description: str, json_out: bool = False) -> argparse.ArgumentParser:
    """The command line of the flight-walking attribution scripts: work directories, ``--aircraft``,
    ``--turbulence`` (:func:`flown_logs`) and, with ``json_out``, ``--json`` (one JSON line per flight)."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("work", nargs="+", help="directories with eval_jsbsim's *.tlog and *-truth.npz")
    ap.add_argument("--aircraft", default=None, help="only this aircraft (default: all found)")
    ap.add_argument("--turbulence", default=None, help="only this level")
    if json_out:
        ap.add_argument("--json", default=None, help="append one JSON line per flight here")
    return ap


def main(argv: list[str] | None = None) -> int:
    a = work_parser(__doc__.split("\n")[0]).parse_args(argv)
    for tlog, ac, _ in flown_logs(a.work, a.aircraft, a.turbulence):
        print(budget(tlog, ac), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
