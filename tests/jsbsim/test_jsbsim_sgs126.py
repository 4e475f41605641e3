"""The sgs126 in the JSBSim harness: the fourteenth session's untouched aircraft, a tuning aircraft since its
final evaluation was read (docs/jsbsim.md, "The sgs126").

The model is the jsbsim wheel's stock Schweizer SGS 1-26 (``aircraft/sgs126/sgs126.xml``), a single-seat
glider, flown as it is (no derived model). It is flown at 3000 ft, where JSBSim's light turbulence
(MIL-F-8785C's light curve, which JSBSim's ``Milspec`` table takes to zero at 7500 ft) is active.

The checks here use the XML and JSBSim's own properties; none of them flies the harness:

- the model is the wheel's, with no propulsion at all, so every non-gravity force is aerodynamic;
- the FCS maps the commands straight to the surfaces the aerodynamics read, with no damper;
- it is statically stable about the CG, and its aileron yaws it the way its ``Cnda`` says;
- light turbulence moves the air at its altitude (and not above 7500 ft).

The summaries' label test moved to ``test_jsbsim_asw20.py`` in the fifteenth session (the asw20 is untouched).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign
map, .tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``.
All of them but the names are slow.

No pipeline fit, GP, diagnosis or scoring runs in these tests.
"""

import dataclasses
import xml.etree.ElementTree as ET

import numpy as np

from benchmarks.jsbsim_harness import FlightConfig, aircraft
from pytest import approx
from static_checks import assert_lateral_derivatives, assert_pitch_derivatives, check_direct_fcs, ic_state

FT = 0.3048


def _state(alpha_deg=4.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0):
    """:func:`static_checks.ic_state` for the sgs126."""
    return ic_state(aircraft("sgs126"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_sgs126_is_the_wheels_glider_flying_its_own_surfaces():
    """The harness flies the wheel's own ``sgs126.xml`` (no derived model): its ``<propulsion>`` is empty,
    JSBSim has no engine, and 50 frames on every non-gravity force and moment is aerodynamic. The FCS
    maps the commands straight to the surfaces the aerodynamics read:

    - elevator -0.35..+0.30 rad, zero-centred;
    - left aileron +-0.35 rad, the right its mirror;
    - rudder +-0.35 rad.

    A yaw rate does not move the rudder (no yaw damper), so the harness's own damper flies it (k_r 0.4)."""
    from benchmarks.jsbsim_harness.derived import DERIVED, REPO_DERIVED
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    spec = aircraft("sgs126")
    assert spec.model == "sgs126" and spec.model not in DERIVED and spec.model not in REPO_DERIVED
    root = ET.parse(stock_model_dir(spec) / "sgs126.xml").getroot()
    assert len(root.find("propulsion")) == 0
    assert spec.gains[5] == 0.4 and not spec.gear_up
    check_direct_fcs(spec, min_lift_lbs=100.0)


def test_the_sgs126_is_statically_stable_and_yaws_adversely():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic``, the harness's initial condition, Mach 0.075).

    - **Pitch:** without its ``Cmadot`` term (``run_ic`` gives an alpha-dot the term reads), Cm falls with
      alpha: -0.56 per rad between 0 and 4 deg, -0.65 between 4 and 8 deg (its Cmalpha -0.5, plus the
      lift and axial force acting at the reference point 6.4 in above the CG).
    - **Elevator:** Cm per rad of elevator -0.78 (Cmde -0.8 + 0.3 Mach), on both sides of zero.
    - **Roll and yaw:** Cl per rad of left aileron 0.0585 (Clda 0.06 - 0.02 Mach); Cn per rad of left
      aileron -0.02 (its Cnda: adverse yaw, Cn_delta_a +0.02 in the project's sign), per rad of rudder
      -0.03 (Cndr); Cn_beta 0.12; Cl_beta -0.1137 (Clb -0.1 plus the side force, CYb -1, acting 6.4 in
      above the CG). Cn and Cl at rest are 0.
    """
    spec = aircraft("sgs126")
    assert_pitch_derivatives(spec, ((0.0, 4.0, approx(-0.56, abs=0.02)), (4.0, 8.0, approx(-0.65, abs=0.02))),
                             ((-0.5, approx(-0.78, abs=0.01)), (0.5, approx(-0.78, abs=0.01))), alpha_e=4.0,
                             travel=(0.35, 0.30))
    assert_lateral_derivatives(spec, (approx(0.0585, rel=0.01), approx(-0.02, rel=1e-6)),
                               (approx(-0.03, rel=1e-6), None),
                               {2.0: (approx(-0.1137, rel=0.01), approx(0.12, rel=1e-3))},
                               alpha_deg=2.0, rest=1e-12, aileron_cmds=(0.4,), rudder_cmds=(0.4,))


def test_turbulence_levels_at_its_altitude():
    """JSBSim's Milspec turbulence over 10 s of the harness's initial condition, fixed surfaces, seed 1,
    gust = total wind less the steady wind. "calm" (severity 1, MIL-F-8785C's 2e-1 curve: what the
    harness called light until the fifteenth session): at the sgs126's 3000 ft every component's
    standard deviation is above 0.15 m/s, about three times that at the rascal's 6000 ft, and from
    8000 ft up there is none: why the sgs126 flew at 3000 ft in the fourteenth session. "light"
    (severity 3, the 1e-2 curve; measured 0.69-1.33 m/s at 3000 ft, 0.47-0.92 at 15000 ft) moves
    every component by more than 0.4 m/s at 3000, 8000 and 15000 ft (docs/jsbsim.md, "Turbulence
    levels")."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("sgs126")

    def gust_std(alt_ft, turbulence):
        s = dataclasses.replace(spec, altitude_ft=alt_ft)
        fdm = load_model(s, 1 / 200, seed=1)
        _set_ic(fdm, s, FlightConfig("sgs126", turbulence=turbulence, seed=1))
        w = []
        for _ in range(2000):
            fdm.run()
            w.append([fdm[f"atmosphere/total-wind-{d}-fps"] - fdm[f"atmosphere/wind-{d}-fps"]
                      for d in ("north", "east", "down")])
        return np.std(np.array(w) * FT, axis=0)

    here, rascal, high = gust_std(spec.altitude_ft, "calm"), gust_std(6000.0, "calm"), gust_std(8000.0, "calm")
    assert spec.altitude_ft == 3000.0
    assert np.all(here > 0.15) and np.all(here > 2.5 * rascal), (here, rascal)
    assert np.all(high < 1e-9), high
    light = [gust_std(alt, "light") for alt in (3000.0, 8000.0, 15000.0)]
    assert np.all(np.array(light) > 0.4), light
