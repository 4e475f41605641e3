"""Dynamics: trim is an equilibrium, RK4/quaternion integration against a slow Euler-angle reference,
torque-free motion conserves angular momentum, and the truth forces and moments reproduce the model."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.estimation.states import STATE_KEYS
from gcs_sysid.sim import AeroModel, Effects, control_limits, propagate, simulate, state_from_measurements, trim
from gcs_sysid.sim.dynamics import make_params
from gcs_sysid.sim.environment import isa

T5 = 30.0 + np.arange(250) * 0.02        # 5 s at 50 Hz: the one shape propagate is compiled for here


def _trim(airframe, model, V=20.0):
    lo, hi = control_limits(airframe)
    return trim(make_params(airframe, model), V, 150.0, 0.3, lo, hi)


def test_trim_is_equilibrium(airframe, model):
    tr = _trim(airframe, model)
    assert tr.residual < 1e-9 and 0 < tr.alpha < 0.1 and 0 < tr.controls[3] < 1
    assert abs(tr.beta) < 1e-9 and abs(tr.controls[1]) < 1e-9
    x0 = state_from_measurements(0.0, tr.theta, 0.3, 0, 0, 0, 150.0, V=20.0, alpha=tr.alpha, beta=0.0)
    out = propagate(airframe, model, x0, T5, np.tile(tr.controls, (250, 1)))
    for k, ref in (("V", 20.0), ("alpha", tr.alpha), ("theta", tr.theta), ("alt", 150.0), ("q", 0.0), ("phi", 0.0)):
        assert np.max(np.abs(out[k] - ref)) < 1e-7, k
    # slower flight needs more alpha and a more trailing-edge-up elevator
    tr16 = _trim(airframe, model, 16.0)
    assert tr16.alpha > tr.alpha and tr16.controls[0] < tr.controls[0]


def _reference(airframe, model, s0, t, U, wind):
    """Slow, obvious 6-DOF: Euler-angle kinematics, numpy, DOP853 (Stevens, Lewis and Johnson, sec. 2.5)."""
    J = airframe.inertia
    Jinv = np.linalg.inv(J)
    th = airframe.thrust

    def f(_, s, d):
        u, v, w, phi, the, psi, p, q, r = s[3:12]
        cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(the), np.sin(the), np.cos(psi), np.sin(psi)
        C = np.array([[ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
                      [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
                      [-st, sf * ct, cf * ct]])
        va = np.array([u, v, w]) - C.T @ wind
        V = np.linalg.norm(va)
        al, be = np.arctan2(va[2], va[0]), np.arcsin(va[1] / V)
        rho = isa(-s[2])[2]
        qS = 0.5 * rho * V**2 * airframe.S
        X = np.array([al, be, p * airframe.b / (2 * V), q * airframe.c / (2 * V), r * airframe.b / (2 * V), *d, V])
        Y = model.evaluate(X[None])[0]
        F = qS * Y[:3] + np.array([th.thrust(d[3], V), 0, 0])
        M = qS * np.array([airframe.b * Y[3], airframe.c * Y[4], airframe.b * Y[5]])
        om = np.array([p, q, r])
        g = 9.80665 * np.array([-st, sf * ct, cf * ct])
        vdot = F / airframe.mass + g - np.cross(om, [u, v, w])
        eul = [p + st / ct * (q * sf + r * cf), q * cf - r * sf, (q * sf + r * cf) / ct]
        return np.concatenate([C @ [u, v, w], vdot, eul, Jinv @ (M - np.cross(om, J @ om))])

    out = [s0]
    s = s0
    for k in range(len(t) - 1):
        s = solve_ivp(f, (t[k], t[k + 1]), s, method="DOP853", rtol=1e-11, atol=1e-11, args=(U[k],)).y[:, -1]
        out.append(s)
    return np.array(out)


def test_quaternion_rk4_matches_euler_angle_reference(airframe, model):
    tr = _trim(airframe, model)
    n = 60                                   # compare over the first 1.2 s (the reference is slow)
    U = np.tile(tr.controls, (250, 1))
    U[5:30, 0] += np.radians(2.0)
    U[10:40, 1] += np.radians(4.0)
    U[20:50, 2] -= np.radians(5.0)
    wind = np.array([2.0, -3.0, 0.5])
    x0 = state_from_measurements(0.1, tr.theta, 0.3, 0.2, -0.1, 0.05, 150.0, V=20.0, alpha=tr.alpha, beta=0.02,
                                 wind_ned=wind)
    out = propagate(airframe, model, x0, T5, U, wind_ned=wind)
    s0 = np.concatenate([x0[:6], [0.1, tr.theta, 0.3], x0[10:13]])
    ref = _reference(airframe, model, s0, T5[:n], U[:n], wind)
    for i, k in enumerate(("u", "v", "w", "phi", "theta", "psi", "p", "q", "r")):
        assert np.max(np.abs(out[k][:n] - ref[:, 3 + i])) < 2e-6, k
    assert np.max(np.abs(out["alt"][:n] + ref[:, 2])) < 1e-6
    assert set(STATE_KEYS) <= set(out)


def test_torque_free_motion_conserves_angular_momentum(airframe):
    forces_only = AeroModel({"CX": {"1": -0.03}, "CZ": {"1": -0.2, "alpha": -4.8}, "CY": {"beta": -0.3}})
    x0 = state_from_measurements(0.0, 0.05, 0.0, 1.0, 0.6, -0.8, 150.0, V=20.0, alpha=0.05, beta=0.0)
    out = propagate(airframe, forces_only, x0, T5, np.zeros((250, 4)))
    quat = np.stack([out[f"quat{i}"] for i in range(4)], 1)
    assert np.max(np.abs(np.sum(quat**2, 1) - 1)) < 1e-9
    from gcs_sysid.sim.dynamics import dcm

    om = np.stack([out["p"], out["q"], out["r"]], 1)
    H = np.einsum("nij,jk,nk->ni", dcm(quat), airframe.inertia, om)
    assert np.max(np.abs(H - H[0])) < 1e-7 * np.abs(H[0]).max()
    E = 0.5 * np.einsum("ni,ij,nj->n", om, airframe.inertia, om)
    assert np.max(np.abs(E - E[0])) < 1e-7 * E[0]


def _reconstruct(res, af, d=(0.0, 0.0, 0.0)):
    """Coefficients from truth accelerations by Newton-Euler, about the nominal CG (offset d)."""
    tr = res.truth
    qS = tr["qbar"] * af.S
    thrust = af.thrust.thrust(tr["delta_t"], tr["V"])
    F = af.mass * np.stack([tr["ax"], tr["ay"], tr["az"]], 1)
    om = np.stack([tr["p"], tr["q"], tr["r"]], 1)
    omd = np.stack([tr["p_dot"], tr["q_dot"], tr["r_dot"]], 1)
    J = af.inertia
    M = omd @ J.T + np.cross(om, om @ J.T)
    M_ref = M + np.cross(np.asarray(d), F)
    F_aero = F - np.stack([thrust, 0 * thrust, 0 * thrust], 1)
    C = np.column_stack([F_aero / qS[:, None], M_ref[:, 0] / (qS * af.b), M_ref[:, 1] / (qS * af.c),
                         M_ref[:, 2] / (qS * af.b)])
    X = np.column_stack([tr["alpha"], tr["beta"], tr["p"] * af.b / (2 * tr["V"]), tr["q"] * af.c / (2 * tr["V"]),
                         tr["r"] * af.b / (2 * tr["V"]), tr["delta_e"], tr["delta_a"], tr["delta_r"], tr["delta_t"],
                         tr["V"]])
    return X, C


def test_truth_forces_and_moments_reproduce_the_model(short_flight, airframe, model):
    X, C = _reconstruct(short_flight, airframe)
    assert np.allclose(X, short_flight.X, atol=1e-10)
    Y = model.evaluate(X)
    assert np.allclose(C, Y, rtol=1e-8, atol=1e-9)
    assert np.allclose(short_flight.Y, Y, atol=1e-12)
    assert np.std(short_flight.truth["p"]) > 0.1 and np.std(short_flight.truth["q"]) > 0.05


def test_mass_inertia_and_cg_effects_enter_the_dynamics(airframe, model, short_plan):
    eff = Effects(mass_delta=0.4, inertia_delta=(0.03, 0.05, -0.04, 0.01), cg_offset=(0.03, 0.0, 0.01))
    res = simulate(airframe, model, short_plan, effects=eff)
    af_true = res.truth_airframe
    assert af_true.mass == pytest.approx(3.4) and af_true.Izz == pytest.approx(0.56)
    X, C = _reconstruct(res, af_true, eff.cg_offset)
    assert np.allclose(C, model.evaluate(X), rtol=1e-8, atol=1e-9)
    X0, C0 = _reconstruct(res, airframe)               # with the nominal airframe it does not fit
    err = np.abs(C0 - model.evaluate(X0)).max(0)
    assert err[COEFFICIENTS.index("CZ")] > 0.01 and err[COEFFICIENTS.index("Cm")] > 0.002
