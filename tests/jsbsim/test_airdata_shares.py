"""benchmarks/airdata_shares.py: the error's scale, the CG and reference-point air angles, the curvature read
(synthetic records; twenty-fourth session, s23-why)."""

import numpy as np
import pytest

from benchmarks import airdata_shares as ads
from benchmarks.jsbsim_harness.sensors import body_from_ned


def test_error_stats_reads_the_scale_and_the_offset():
    rng = np.random.default_rng(3)
    true = np.radians(1.0) * rng.normal(size=2000)
    est = 1.12 * true + np.radians(0.5)                 # 12 % too wide, 0.5 deg off
    s = ads.error_stats(est, true)
    assert s["k"] == pytest.approx(1.12, abs=1e-9)
    assert s["mean"] == pytest.approx(0.5 + np.degrees(0.12 * true.mean()), abs=1e-9)
    assert s["sd"] == pytest.approx(np.degrees(0.12 * true.std()), rel=1e-9)
    m = np.ones(2000, bool)
    m[:1990] = False
    assert ads.error_stats(est, true, m)["k"] == pytest.approx(1.12, abs=1e-9)
    with pytest.raises(ValueError):
        ads.error_stats(est[:2], true[:2])
    with pytest.raises(ValueError):
        ads.error_stats(np.ones(10), np.ones(10))


def _fields(rng, T=400):
    phi, theta, psi = (np.radians(s) * rng.normal(size=T) for s in (10.0, 5.0, 90.0))
    ua, va, wa = 70.0 + rng.normal(size=T), 2.0 * rng.normal(size=T), 3.0 + rng.normal(size=T)
    wind = np.stack([5.0 + rng.normal(size=T), -3.0 + rng.normal(size=T), 0.5 * rng.normal(size=T)], -1)
    wb = np.einsum("tij,tj->ti", body_from_ned(phi, theta, psi), wind)
    f = {"phi": phi, "theta": theta, "psi": psi, "u": ua + wb[:, 0], "v": va + wb[:, 1], "w": wa + wb[:, 2],
         "wn": wind[:, 0], "we": wind[:, 1], "wd": wind[:, 2],
         "p": 0.1 * rng.normal(size=T), "q": 0.1 * rng.normal(size=T), "r": 0.1 * rng.normal(size=T)}
    return f, np.arctan2(wa, ua), np.arcsin(va / np.sqrt(ua**2 + va**2 + wa**2))


def test_cg_angles_are_the_air_relative_velocitys():
    f, a, b = _fields(np.random.default_rng(4))
    ac, bc = ads.cg_angles(f)
    np.testing.assert_allclose(ac, a, atol=1e-12)
    np.testing.assert_allclose(bc, b, atol=1e-12)


def test_point_angles_add_the_rotation_at_the_lever_arm():
    f, a, _ = _fields(np.random.default_rng(6))
    ap, bp = ads.point_angles(f, (0.0, 0.0, 0.0))
    np.testing.assert_allclose(ap, a, atol=1e-12)
    # a pure pitch rate at a point 1 m ahead: w grows by -q x 1 m (omega x r, z component = -q r_x)
    g = dict(f, p=np.zeros_like(f["p"]), r=np.zeros_like(f["r"]))
    ap, _ = ads.point_angles(g, (1.0, 0.0, 0.0))
    ac, _ = ads.cg_angles(g)
    assert np.all(np.sign(ap - ac) == -np.sign(g["q"]))
    # the air's own rates, where given, replace the inertial ones
    h = dict(g, q_aero=np.zeros_like(g["q"]))
    np.testing.assert_allclose(ads.point_angles(h, (1.0, 0.0, 0.0))[0], ac, atol=1e-12)


def test_curvature_read_falls_as_one_over_k_squared():
    rng = np.random.default_rng(7)
    T = 3000
    X = np.zeros((T, 10))
    X[:, 0] = np.radians(2.0) * rng.normal(size=T)
    X[:, 3], X[:, 5] = 0.01 * rng.normal(size=T), 0.05 * rng.normal(size=T)
    ac = X[:, 0] - X[:, 0].mean()
    Cm = -0.02 - 1.0 * X[:, 0] - 8.0 * ac**2 - 20.0 * X[:, 3] - 1.5 * X[:, 5]
    m = np.ones(T, bool)
    assert ads.curvature_read(X[:, 0], X, Cm, m) == pytest.approx(-8.0, abs=1e-6)
    assert ads.curvature_read(1.12 * X[:, 0], X, Cm, m) == pytest.approx(-8.0 / 1.12**2, abs=1e-6)


def test_stated_airframe_copy_for_the_named_aircraft_only(tmp_path, monkeypatch):
    """``eval_jsbsim --stated-lift-slope``: the replay reads a copy of the airframe file with ``[aero]`` appended for
    the aircraft named, the harness's own file (the fingerprint's) otherwise."""
    from benchmarks import eval_jsbsim as ej
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from gcs_sysid.airframe import load_airframe

    path = aircraft("s23").airframe_path
    monkeypatch.setattr(ej, "STATED_AERO", {"s23": (5.5, 7.1)})
    out = ej.stated_airframe(path, tmp_path, "s23-light-s1-ahrs")
    assert out == tmp_path / "s23-light-s1-ahrs-airframe-stated.toml"
    a, b = load_airframe(out), load_airframe(path)
    assert (a.CL_alpha, a.CL_q) == (5.5, 7.1) and b.CL_alpha is None and (a.S, a.b, a.mass) == (b.S, b.b, b.mass)
    assert ej.stated_airframe(aircraft("t6").airframe_path, tmp_path, "t6") == aircraft("t6").airframe_path
    monkeypatch.setattr(ej, "STATED_AERO", {"s23": (5.5, None)})
    assert load_airframe(ej.stated_airframe(path, tmp_path, "x")).CL_q is None


def test_stated_lift_line_copy(tmp_path, monkeypatch):
    """``eval_jsbsim --stated-lift-level``: the copy carries the whole stated line; with ``--stated-lift-slope`` too the
    slope and ``CL_q`` are that option's; a malformed item is refused."""
    from benchmarks import eval_jsbsim as ej
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from gcs_sysid.airframe import load_airframe

    line = ej.parse_stated_line(["s23:5.45:6.3:0.30:0.496:0.01"])
    assert line == {"s23": {"CL_alpha": 5.45, "CL_q": 6.3, "CL_delta_e": 0.30, "CL0": 0.496, "CL0_sigma": 0.01}}
    monkeypatch.setattr(ej, "STATED_LINE", line)
    path = aircraft("s23").airframe_path
    a = load_airframe(ej.stated_airframe(path, tmp_path, "s23-light-s1-ahrs"))
    assert (a.CL_alpha, a.CL_q, a.CL0, a.CL_delta_e, a.CL0_sigma) == (5.45, 6.3, 0.496, 0.30, 0.01)
    monkeypatch.setattr(ej, "STATED_AERO", {"s23": (5.5, None)})
    a = load_airframe(ej.stated_airframe(path, tmp_path, "x"))
    assert (a.CL_alpha, a.CL_q, a.CL0) == (5.5, None, 0.496)
    assert ej.stated_airframe(aircraft("t6").airframe_path, tmp_path, "t6") == aircraft("t6").airframe_path
    with pytest.raises(SystemExit, match="needs"):
        ej.parse_stated_line(["s23:5.45:6.3"])
