"""The eternity in the JSBSim harness: the twenty-first session's untouched aircraft, a tuning aircraft since the
twenty-second session (docs/jsbsim.md, "The eternity").

The model is ENAC's Eternity UAV in Paparazzi's JSBSim simulator (``conf/simulator/jsbsim/aircraft/Eternity.xml`` of
paparazzi/paparazzi at commit 5399bd98, Murat Bronz 2015, GPL-2.0-or-later; its coefficients from wind-tunnel
measurements and AVL), a 0.90-kg, 1.0-m-span fixed-wing UAV, checked in under ``data/jsbsim_models/eternity/`` and
flown as the derived model ``Eternity_glide`` (``derived.py``): its motor, propeller and throttle channel removed,
its elevator moment reading an alias in degrees. It is flown at 34 kt (``ic/vc-kts``) and 10000 ft.

The checks here use the XML and JSBSim's own properties (the harness's initial condition, ``run_ic``, no
turbulence: a mechanism check); none of them flies the harness:

- the checked-in file is the one the README names, and the derivation makes only its three edits;
- the FCS maps the commands straight to the surfaces (elevator -20 / +15 deg, both ailerons +-20 deg with the same
  sign, rudder +-27 deg with a negative gain); no engine, no force but the aerodynamic one;
- it is statically stable about the CG, and its elevator, aileron and rudder act as its XML says.

The summaries' label test moves on with the untouched aircraft (twenty-second session: ``test_jsbsim_us25e.py``).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, .tlog,
hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the names
are slow.

No pipeline fit, GP, diagnosis or scoring ran on the eternity before its final evaluation (twenty-first session);
it is a tuning aircraft since.
"""

import copy
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import checked_in_model
from static_checks import assert_aero_is_the_only_force, assert_lateral_derivatives, assert_pitch_derivatives, ic_state

SRC = "data/jsbsim_models/eternity/Eternity.xml"
SRC_SHA256 = "2341802f2ba31fea2d561a94a66957f88fa478ffcdc8fedb45f70f4772fa4bc7"
RAD_PER_DEG_FCS = 0.01745     # the model's FCS gain (deg -> rad)


def _state(alpha_deg=-2.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0)):
    """:func:`static_checks.ic_state` for the eternity (34 kt at 10000 ft; it trims near alpha -2 deg)."""
    return ic_state(aircraft("eternity"), alpha_deg, beta_deg, cmds)


def test_the_derivation_removes_the_motor_and_throttle_and_aliases_the_elevator():
    """The checked-in XML is the README's (22336 bytes, its SHA-256). ``Eternity_glide`` is that XML with its one
    ``<engine>`` (``HB2815-2000``, its feed and the ``apc6x4`` thruster) removed from ``<propulsion>``, its
    ``Throttle`` channel removed, and ``Pitch_elevator`` reading the alias ``aero/function/elevator-pos-deg`` (57.29...
    x ``fcs/elevator-pos-rad``) for ``fcs/elevator-pos-deg``; the empty tank and every other element are equal
    (metrics, mass balance, ground reactions, the other FCS channels, every aerodynamic function but that read).
    The spec's notes carry the derived XML's hash."""
    from benchmarks.jsbsim_harness.derived import ELEVATOR_DEG_ALIAS

    src, der, spec = checked_in_model("eternity", "Eternity_glide", SRC, 22336, SRC_SHA256)
    ET.indent(src, space=" ")

    def same(a, b):      # the elements, their text and children, not their own tails (the last child's differs)
        a, b = map(copy.deepcopy, (a, b))
        a.tail = b.tail = None
        return ET.tostring(a) == ET.tostring(b)

    for tag in ("metrics", "mass_balance", "ground_reactions"):
        assert same(src.find(tag), der.find(tag)), tag
    assert [e.get("file") for e in der.find("propulsion").iter("engine")] == []
    assert same(src.find("propulsion/tank"), der.find("propulsion/tank"))
    assert [c.get("name") for c in der.find("flight_control")] == ["Pitch", "Roll", "Yaw"]
    for a, b in zip(src.find("flight_control"), der.find("flight_control")):
        assert same(a, b), a.get("name")
    s_fun, d_fun = list(src.find("aerodynamics").iter("function")), list(der.find("aerodynamics").iter("function"))
    assert d_fun[0].get("name") == ELEVATOR_DEG_ALIAS and len(d_fun) == len(s_fun) + 1
    for a, b in zip(s_fun, d_fun[1:]):
        if a.get("name") == "aero/moment/Pitch_elevator":
            assert [p.text.strip() for p in b.iter("property")][-1] == ELEVATOR_DEG_ALIAS
            [p for p in a.iter("property") if p.text.strip() == "fcs/elevator-pos-deg"][0].text = ELEVATOR_DEG_ALIAS
        assert same(a, b), a.get("name")


def test_the_eternity_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface (``aerosurface_scale``, zero-centred, x 0.01745):
    elevator +15 deg trailing edge down and -20 up, both ailerons the same +-20 deg (the aerodynamics read the left
    alone: delta_a = -left with ``aileron_sign`` -1), rudder +-27 deg with gain -0.01745 (a positive command, a
    negative position: delta_r = -position, ``cmd_per_rad`` negative). The alias reads the elevator in degrees.
    No engine; after 50 frames every non-gravity force and moment is aerodynamic (0.90 kg: 1.98 lb)."""
    from benchmarks.jsbsim_harness.flight import _deflections

    spec = aircraft("eternity")
    fdm = _state(beta_deg=4.0, cmds=(0.3, -0.4, 0.2))
    assert fdm.get_propulsion().get_num_engines() == 0 and fdm["inertia/weight-lbs"] == pytest.approx(1.98416, rel=1e-5)
    assert fdm["fcs/elevator-pos-rad"] == pytest.approx(0.3 * 15.0 * RAD_PER_DEG_FCS, rel=1e-9)
    assert fdm["aero/function/elevator-pos-deg"] == pytest.approx(np.degrees(fdm["fcs/elevator-pos-rad"]), rel=1e-12)
    assert _state(cmds=(-0.3, 0.0, 0.0))["fcs/elevator-pos-rad"] == pytest.approx(-0.3 * 20.0 * RAD_PER_DEG_FCS)
    assert fdm["fcs/left-aileron-pos-rad"] == pytest.approx(-0.4 * 20.0 * RAD_PER_DEG_FCS, rel=1e-9)
    assert fdm["fcs/right-aileron-pos-rad"] == pytest.approx(fdm["fcs/left-aileron-pos-rad"], rel=1e-9)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(-0.2 * 27.0 * RAD_PER_DEG_FCS, rel=1e-9)
    for k, ends in enumerate(((20.0, 20.0, -27.0))):
        assert spec.cmd_per_rad[k] == pytest.approx(1.0 / (ends * RAD_PER_DEG_FCS))
    da, dr = np.radians(5.0), np.radians(4.0)
    cmd = (0.0, da * spec.aileron_sign * spec.cmd_per_rad[1], dr * spec.rudder_sign * spec.cmd_per_rad[2])
    assert _deflections(_state(cmds=cmd), spec)[1:] == pytest.approx((da, dr), rel=1e-9)
    assert_aero_is_the_only_force(fdm, 0.2, external_zero=True)    # 0.3-0.4 lb of lift at 0.7 psf


def test_the_eternity_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 23.7 m/s,
    Mach 0.072) without the ``Pitch_alphadot`` term (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha: -1.55 per rad between alpha -8 and -4 deg, -1.94 between -4 and 0, -1.74
      between 0 and 4 (Pitch_alpha -0.3215 and the lift table, whose slope kinks at -5 and 0 deg, through the lift's
      2-in arm behind the CG); Cm -0.175 at alpha 0 (the lift's arm: no Cm0 in the file), so it trims at a negative
      alpha with the elevator trailing edge up; per rad of elevator -0.761 (Pitch_elevator -0.0119 per deg and
      Lift_elevator 0.229 through the arm).
    - **Roll and yaw:** per rad of left aileron Cl +0.2966 (the project's Cl_delta_a -0.2966) and Cn -0.021 (adverse:
      Cn_delta_a +0.021); per rad of rudder position Cn +0.043 and Cl +0.00166 (the project's delta_r is minus the
      position: Cn_delta_r -0.043); Cl_beta -0.094 and Cn_beta 0.065 (Yaw_beta 0.0517 and the side force's arm).
    """
    spec = aircraft("eternity")
    assert _state(alpha_deg=0.0)["velocities/mach"] == pytest.approx(0.072, abs=0.002)
    assert_pitch_derivatives(spec, ((-8.0, -4.0, approx(-1.552, abs=0.01)), (-4.0, 0.0, approx(-1.938, abs=0.01)),
                                    (0.0, 4.0, approx(-1.741, abs=0.01))),
                             ((0.3, approx(-0.761, abs=0.005)), (-0.3, approx(-0.761, abs=0.005))),
                             cm_at={0.0: approx(-0.175, abs=0.002)}, alpha_e=-2.0, term="aero/moment/Pitch_alphadot")
    beta = (approx(-0.094, abs=1e-3), approx(0.065, abs=1e-3))
    assert_lateral_derivatives(spec, (approx(0.2966, abs=1e-4), approx(-0.021, abs=1e-4)),
                               (approx(0.043, abs=1e-4), approx(0.00166, abs=1e-5)), {-4.0: beta, 0.0: beta},
                               alpha_deg=-2.0)
