"""The c172p in the JSBSim harness: the twentieth session's untouched aircraft, a tuning aircraft since the
twenty-first (docs/jsbsim.md, "The c172p").

The model is JSBSim's stock Cessna 172P (the jsbsim wheel's ``aircraft/c172p/c172p.xml``, FlightGear's C172P flight
model), flown as it is: engine shut down (its propeller stops: no force), fixed gear, its pilot's point mass (180 lb
at y = -14 in) emptied by the harness as the c172x's. Its term set is the tuning c172x's; the twentieth session took it
with that screening rule relaxed (its numbers differ where the method meets them: the side force's rudder, aileron,
roll-rate and yaw-rate terms, an adverse aileron yaw where the c172x's is proverse, Cmadot, Cmde, and elevator and
rudder moments on the propeller-wash dynamic pressure). It is flown at 80 kt (``ic/vc-kts``) and 4000 ft.

The checks here use JSBSim's own properties at the harness's initial condition (``run_ic``, no turbulence: a
mechanism check); none of them flies the harness:

- the FCS maps the commands straight to the surfaces (elevator -28 / +23 deg, left aileron -20 / +15 deg with the right
  its mirror, rudder +-16 deg, each x 0.01745), flaps 0; the stopped engine gives no force, and the propeller-wash
  dynamic pressure the elevator and rudder moments read is 0.5 rho u^2 on the body-axis airspeed;
- it is statically stable about the CG, and its elevator, aileron and rudder act as its XML says.

The summaries' label test moves on with the untouched aircraft (twenty-first session).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, .tlog,
hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the names
are slow.

No pipeline fit, GP, diagnosis or scoring ran on the c172p before the twentieth session's final evaluation.
"""

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from static_checks import assert_aero_is_the_only_force, assert_aileron_maps_back, assert_lateral_derivatives, \
    assert_pitch_derivatives, ic_state, surface_state

RAD_PER_DEG_FCS = 0.01745     # the c172p's FCS gain (deg -> rad)


def _state(alpha_deg=2.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0)):
    """:func:`static_checks.ic_state` for the c172p (80 kt at 4000 ft, engine stopped)."""
    return ic_state(aircraft("c172p"), alpha_deg, beta_deg, cmds)


def test_the_c172p_flies_its_stock_fcs_and_no_engine_force():
    """The spec flies the wheel's ``c172p`` (no derived model), fixed gear, the harness's gains. The FCS maps each
    command straight to its surface (``aerosurface_scale``, zero-centred, unequal ends): elevator +23 deg trailing
    edge down and -28 up, left aileron +15 / -20 deg with the right its mirror (the aerodynamics read the left
    alone: delta_a = 0.5 (left - right) = -left with ``aileron_sign`` -1), rudder +-16 deg; ``cmd_per_rad`` takes
    the larger end of each. The pilot's off-centre mass is emptied (1700 lb). One engine, stopped: its propeller
    gives no induced velocity, so the elevator's and rudder's wash dynamic pressure is 0.5 rho u^2 (body-axis u), and
    after 50 frames every non-gravity force and moment is aerodynamic."""
    from benchmarks.jsbsim_harness.derived import DERIVED, REPO_DERIVED

    spec = aircraft("c172p")
    assert spec.model == "c172p" and spec.model not in DERIVED and spec.model not in REPO_DERIVED
    assert not spec.gear_up and spec.gains == (1.0, 0.3, 0.01, 0.4, 0.1, 0.4)
    # the trailing-edge-up elevator to 1e-9 (was pytest's default 1e-6)
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 23.0 * RAD_PER_DEG_FCS),
                               "fcs/left-aileron-pos-rad": (1, 20.0 * RAD_PER_DEG_FCS),
                               "fcs/rudder-pos-rad": (2, 16.0 * RAD_PER_DEG_FCS)},
                        up=28.0 * RAD_PER_DEG_FCS, alpha_deg=2.0)
    assert fdm.get_propulsion().get_num_engines() == 1 and fdm["inertia/weight-lbs"] == pytest.approx(1700.0)
    assert fdm["fcs/flap-pos-deg"] == 0.0
    assert fdm["fcs/right-aileron-pos-rad"] == pytest.approx(-fdm["fcs/left-aileron-pos-rad"], rel=1e-9)
    assert spec.cmd_per_rad == pytest.approx((1 / (28 * RAD_PER_DEG_FCS), 1 / (20 * RAD_PER_DEG_FCS),
                                              1 / (16 * RAD_PER_DEG_FCS)))
    assert_aileron_maps_back(spec, 2.0)
    wash = _state()
    u_over_v = wash["velocities/u-aero-fps"] / wash["velocities/vt-fps"]
    assert wash["aero/function/qbar-induced-psf"] == pytest.approx(wash["aero/qbar-psf"] * u_over_v ** 2, rel=1e-9)
    assert_aero_is_the_only_force(fdm, 1000.0)      # it weighs 1700 lb
    assert fdm["propulsion/engine/prop-induced-velocity_fps"] == 0.0


def test_the_c172p_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, Mach 0.138)
    without the ``Cmadot`` term (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha, more steeply as it grows: -1.78 per rad between alpha -4 and 0 deg, -1.91
      between 0 and 4, -2.07 between 4 and 8 (Cmalpha -1.8 and the lift and drag through the arms); per rad of
      elevator -1.108 trailing edge down and -1.149 up (Cmde -1.122 on the wash dynamic pressure, CLDe 0.43 through
      the arm, and CDDe of the elevator's magnitude: a kink at zero elevator).
    - **Roll and yaw:** per rad of left aileron Cl +0.229 (the project's Cl_delta_a -0.229) and Cn -0.0053 (adverse:
      Cn_delta_a +0.0053 in the project's sign; the c172x's is proverse); per rad of rudder Cn -0.0431 and Cl
      +0.0235 (Cldr 0.0147 and CYdr 0.187 through the arm); Cl_beta -0.113 (Clb -0.092 and the side force) and
      Cn_beta 0.059, nearly constant in alpha.
    """
    spec = aircraft("c172p")
    assert _state(alpha_deg=0.0)["velocities/mach"] == pytest.approx(0.138, abs=0.003)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-1.782, abs=0.01)), (0.0, 4.0, approx(-1.914, abs=0.01)),
                                    (4.0, 8.0, approx(-2.066, abs=0.01))),
                             ((0.3, approx(-1.108, abs=0.005)), (-0.3, approx(-1.149, abs=0.005))), alpha_e=2.0)
    beta = (approx(-0.113, abs=3e-3), approx(0.0592, abs=1e-3))
    assert_lateral_derivatives(spec, (approx(0.229, abs=5e-4), approx(-0.0053, abs=2e-4)),
                               (approx(-0.0431, abs=5e-4), approx(0.0235, abs=5e-4)), {0.0: beta, 6.0: beta},
                               alpha_deg=2.0)
