"""The b737 in the JSBSim harness: the nineteenth session's untouched aircraft, a tuning aircraft since the twentieth
(docs/jsbsim.md, "The b737").

The model is JSBSim's stock Boeing 737 (the jsbsim wheel's ``aircraft/737/737.xml``: Dave Culp and Aeromatic, GPL
in its header), flown as it is: both CFM56 shut down on their "direct" thrusters, gear up, its own yaw damper in the
rudder channel (kept in the loop, as the b747's). It was set aside in the thirteenth session as a near-copy of the
b747's term set; the nineteenth session took it with that rule relaxed (its numbers differ: Cnb 0.26, Cnr -0.35,
Cndr -0.20, Cmadot -16, Cmq -27). It is flown at 250 kt (``ic/vc-kts``) and 12000 ft.

The checks here use JSBSim's own properties at the harness's initial condition (``run_ic``, no turbulence: a
mechanism check); none of them flies the harness:

- the FCS maps the commands straight to the surfaces (elevator +-0.3 rad, ailerons +-0.35 rad with the right the
  left's mirror, rudder +-0.35 rad) and adds its yaw damper (1.0 x ``velocities/r-aero-rad_sec`` to the normalised
  rudder above Mach 0.11); the engines give no force once stopped;
- it is statically stable about the CG, and its elevator, aileron and rudder act as its XML says.

The summaries' label test moved to ``test_jsbsim_c172p.py`` in the twentieth session (the c172p is untouched now).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, gear,
.tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the
names are slow.

No pipeline fit, GP, diagnosis or scoring ran on the b737 before the nineteenth session's final evaluation.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from static_checks import assert_aero_is_the_only_force, assert_lateral_derivatives, assert_pitch_derivatives, ic_state


def _state(alpha_deg=2.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0):
    """:func:`static_checks.ic_state` for the b737 (250 kt at 12000 ft, engines stopped, gear command up)."""
    return ic_state(aircraft("b737"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_b737_flies_its_stock_fcs_with_its_yaw_damper_and_no_engine_force():
    """The spec flies the wheel's ``737`` (no derived model), gear up, the harness's yaw damper off (k_r 0: the
    model's own stays in the loop). The FCS maps each command straight to its surface (``aerosurface_scale``):
    elevator +-0.3 rad, left aileron +-0.35 rad with the right its mirror (the aerodynamics read the left alone:
    delta_a = -left), rudder +-0.35 rad plus the yaw damper: 1.0 x the air-relative yaw rate added to the
    normalised rudder above Mach 0.11. Two engines, stopped: after 50 frames every non-gravity force and
    moment is aerodynamic."""
    from benchmarks.jsbsim_harness.derived import DERIVED, REPO_DERIVED
    from benchmarks.jsbsim_harness.flight import _deflections

    spec = aircraft("b737")
    assert spec.model == "737" and spec.model not in DERIVED and spec.model not in REPO_DERIVED
    assert spec.gear_up and spec.gains[5] == 0.0 and spec.aileron_props == ("fcs/left-aileron-pos-rad", None)
    fdm = _state(beta_deg=4.0, cmds=(0.3, -0.4, 0.2))
    assert fdm.get_propulsion().get_num_engines() == 2
    assert fdm["velocities/mach"] > 0.11
    assert fdm["fcs/elevator-pos-rad"] == pytest.approx(0.3 * 0.3, rel=1e-9)
    assert fdm["fcs/left-aileron-pos-rad"] == pytest.approx(-0.4 * 0.35, rel=1e-9)
    assert fdm["fcs/right-aileron-pos-rad"] == pytest.approx(0.4 * 0.35, rel=1e-9)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.35 * (0.2 + fdm["velocities/r-aero-rad_sec"]), rel=1e-9)
    damped = _state(r_rad_s=0.05)
    assert damped["fcs/yaw-damper-final"] == pytest.approx(damped["velocities/r-aero-rad_sec"], rel=1e-9)
    assert damped["fcs/rudder-pos-rad"] == pytest.approx(0.35 * damped["velocities/r-aero-rad_sec"], rel=1e-9)
    assert damped["fcs/rudder-pos-rad"] > 0.015
    da = np.radians(5.0)      # trailing edge down on the right
    cmd = da * spec.aileron_sign * spec.cmd_per_rad[1]
    assert _deflections(_state(cmds=(0.0, cmd, 0.0)), spec)[1] == pytest.approx(da, rel=1e-9)
    assert_aero_is_the_only_force(fdm, 1e5)      # it weighs 107000 lb


def test_the_b737_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, Mach 0.556)
    without the ``Cmadot`` term (``run_ic`` gives an alpha-dot the term reads). The aerodynamic reference point is
    15 in aft of the loaded CG (the fuel sits ahead of the empty CG) and 64 in above it.

    - **Pitch:** Cm falls with alpha, more steeply as it grows: -1.01 per rad between alpha -4 and 0 deg, -1.14
      between 0 and 4 (Cmalpha -0.6, the lift acting aft of the CG, the drag above it); per rad of elevator
      -0.993 trailing edge up and -0.946 down ((-1.2 + 0.45 Mach), CLde 0.2 through the arm, and CDde 0.059 of the
      elevator's magnitude acting above the CG: a kink at zero elevator).
    - **Roll and yaw:** per rad of left aileron Cl +0.0814 ((0.1 - 0.0335 Mach): the project's Cl_delta_a
      -0.081), Cn 0 (no aileron yaw); per rad of rudder Cn -0.200 and Cl +0.010; Cl_beta -0.145 (Clb -0.09 and
      the side force, CYb -1, acting 64 in above the CG), Cn_beta 0.273 (Cnb 0.26 and the side force aft of it).
    """
    spec = aircraft("b737")
    assert _state(alpha_deg=0.0)["velocities/mach"] == pytest.approx(0.556, abs=0.005)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-1.008, abs=0.01)), (0.0, 4.0, approx(-1.138, abs=0.01))),
                             ((-0.3, approx(-0.993, abs=0.005)), (0.3, approx(-0.946, abs=0.005))), alpha_e=2.0,
                             travel=(0.3, 0.3))
    # no aileron yaw: |dCn / da| <= 1e-9 (was |dCn| < 1e-9; |da| < 1 rad: stronger); dCn is exactly 0
    assert_lateral_derivatives(spec, (approx(0.0814, abs=5e-4), approx(0.0, abs=1e-9)),
                               (approx(-0.200, abs=2e-3), approx(0.010, abs=1e-3)),
                               {2.0: (approx(-0.145, abs=2e-3), approx(0.273, abs=3e-3))},
                               alpha_deg=2.0, rest=1e-5, rudder_cmds=(0.3,))
