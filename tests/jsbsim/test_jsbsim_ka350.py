"""The ka350 in the JSBSim harness: the twenty-third session's untouched aircraft, a tuning aircraft since the
twenty-fourth session (docs/jsbsim.md, "The ka350").

The model is the JSBSim flight model of a FlightGear Beechcraft King Air 350 (B300) package rebuilt in 2026
(itaalh/FlightGear-Beechcraft-350ER ``Aero/KingAir-350.xml`` at 0298d965, GPL-2.0-or-later), a 13319-lb, 17.65-m-span
twin turboprop with a T-tail whose aerodynamics are tables in alpha and flaps with rate and aileron cross terms
linear in the basic lift coefficient. Its XML is checked in under ``data/jsbsim_models/kingair350/`` and flown as the
derived model ``KingAir350_glide`` (``derived.py``): engines, propellers and systems removed, the autopilot inputs,
rudder boost and feathered-propeller drag that read them removed, its yaw damper off.

The checks here use the file and JSBSim's own properties (the harness's initial condition, ``run_ic``, no
turbulence: a mechanism check); none of them flies the harness:

- the checked-in file is the one the README names, and the derivation makes only its six edits;
- the FCS maps the commands straight to the surfaces (elevator -20 / +14 deg, ailerons 25 up / 15 down with the
  mean of the two read by the aerodynamics, rudder +-25 deg), the yaw damper off; no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its XML says.

The summaries' label test moves on with the untouched aircraft (twenty-fourth session: ``test_jsbsim_s23.py``).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, gear,
.tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but
the names are slow.

No pipeline fit, GP, diagnosis or scoring ran on the ka350 before its final evaluation (twenty-third session); it
is a tuning aircraft since.
"""

import copy
import xml.etree.ElementTree as ET

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_kept_but_engines, checked_in_model, same_xml
from static_checks import assert_aero_is_the_only_force, assert_deflections_map_back, assert_lateral_derivatives, \
    assert_pitch_derivatives, ic_state, surface_state

SRC = "data/jsbsim_models/kingair350/KingAir-350.xml"
SRC_SHA256 = "f89a9376371cbbe4f08060548aee36a25d645620943f5e7273c59e3164c9675d"
#: The aerodynamics' aileron: 0.5 (left - right), rad (``fcs/aileron-eff-rad``).
AILERON = "fcs/aileron-eff-rad"


def _state(alpha_deg=0.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0)):
    """:func:`static_checks.ic_state` for the ka350 (160 kt at 8000 ft; it glides near alpha 0)."""
    return ic_state(aircraft("ka350"), alpha_deg, beta_deg, cmds)


def test_the_derivation_removes_the_engines_systems_and_what_reads_them():
    """The checked-in XML is the README's (34611 bytes, its SHA-256). ``KingAir350_glide`` is that XML with its two
    ``<engine>`` elements and four ``<system>`` elements removed, the pitch and roll summers without
    ``ap/elevator-cmd`` and ``ap/aileron-cmd``, the yaw channel without its four rudder-boost components and the
    summer's ``fcs/rudder-boost-lag``, ``/controls/flight/yaw-damper`` 0 and no ``Drag_feathered``; the four tanks
    and every other element are equal (metrics, mass balance, ground reactions, the flaps and gear channels, every
    other aerodynamic function, the external reactions). The spec's notes carry the derived XML's hash."""
    src, der, spec = checked_in_model("ka350", "KingAir350_glide", SRC, 34611, SRC_SHA256)
    ET.indent(src, space=" ")
    assert_kept_but_engines(src, der, ("metrics", "mass_balance", "ground_reactions", "external_reactions"), 2, 4)
    assert der.find("system") is None
    assert [x.get("file") for x in src.findall("system")] == ["engine-control", "fuel-system", "nws", "autopilot"]
    fc_s, fc_d = src.find("flight_control"), der.find("flight_control")
    assert [(p.text.strip(), p.get("value")) for p in fc_d.findall("property")] == [
        ("/controls/flight/yaw-damper", "0"), ("/controls/flight/rudder-boost", "1")]
    gone = {"ap/elevator-cmd", "ap/aileron-cmd", "fcs/rudder-boost-lag", "fcs/torque-diff", "fcs/rudder-boost-raw",
            "fcs/rudder-boost-cmd"}
    for a, b in zip(fc_s.findall("channel"), fc_d.findall("channel"), strict=True):
        a = copy.deepcopy(a)
        for comp in list(a):
            if comp.get("name") in gone:
                a.remove(comp)
                continue
            for i in comp.findall("input"):
                if i.text.strip() in gone:
                    comp.remove(i)
        assert same_xml(a, b), a.get("name")
    s_fun = [f for f in src.find("aerodynamics").iter("function") if f.get("name") != "aero/force/Drag_feathered"]
    d_fun = list(der.find("aerodynamics").iter("function"))
    assert len(s_fun) == len(d_fun) == 33
    for a, b in zip(s_fun, d_fun):
        assert same_xml(a, b), a.get("name")


def test_the_ka350_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface (``aerosurface_scale``, zero-centred): elevator +14 deg
    trailing edge down and -20 up; left aileron +15 / -25 deg, the right its mirror (-cmd), so the aerodynamics'
    aileron 0.5 (left - right) is 0.349 rad per unit command both ways (delta_a = -0.5 (left - right) with
    ``aileron_sign`` -1); rudder +-25 deg. The yaw damper is off (the rudder is the command alone, a yaw rate moves
    nothing). No engine; 13319 lb (the pilot emptied); after 50 frames every non-gravity force and moment is
    aerodynamic."""
    spec = aircraft("ka350")
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 0.2443), "fcs/left-aileron-pos-rad": (1, 0.4363),
                               "fcs/right-aileron-pos-rad": (1, -0.2618), AILERON: (1, 0.34905),
                               "fcs/rudder-pos-rad": (2, 0.4363)}, up=0.3491, alpha_deg=0.0)
    assert fdm.get_propulsion().get_num_engines() == 0 and fdm["inertia/weight-lbs"] == pytest.approx(13319.0)
    yawing = ic_state(spec, 0.0, 0.0, (0.0, 0.0, 0.2), r_rad_s=0.1)
    assert yawing["fcs/yaw-damper-cmd"] == 0.0 and yawing["fcs/rudder-pos-rad"] == pytest.approx(0.2 * 0.4363)
    assert spec.cmd_per_rad == pytest.approx((1 / 0.3491, 1 / 0.34905, 1 / 0.4363))
    assert_deflections_map_back(spec)
    assert_aero_is_the_only_force(fdm, 1000.0, external_zero=True)


def test_the_ka350_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 160 kt at
    8000 ft, Mach 0.315) without the ``Pitch_alphadot`` term (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha: -0.774 per rad between alpha -4 and 0 deg, -0.805 between 0 and 4, -0.738
      between 4 and 8 (Pitch_alpha's table, -0.9 per rad near 0, and the lift through the reference point 2.5 in
      behind and 11 in below the CG); Cm +0.036 at alpha 0; per rad of elevator -1.40 (Pitch_elevator -1.40 and
      Lift_elevator 0.40 through the arm).
    - **Roll and yaw:** per rad of 0.5 (left - right) Cl +0.100 (the project's Cl_delta_a -0.100) and Cn -0.0082
      (adverse: -0.004 - 0.012 CL at CL 0.35; Cn_delta_a +0.0082); per rad of rudder Cn -0.0949 and Cl +0.0161
      (Roll_rudder 0.018, Side_rudder 0.16 through the arm); Cl_beta -0.0771 at alpha 0 and -0.0976 at 6 deg
      (Roll_beta's table, -0.085 and -0.106, and the side force -0.60 beta through the 11-in arm); Cn_beta 0.0947.
    """
    spec = aircraft("ka350")
    assert _state()["velocities/mach"] == pytest.approx(0.315, abs=0.002)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.774, abs=0.005)), (0.0, 4.0, approx(-0.805, abs=0.005)),
                                    (4.0, 8.0, approx(-0.738, abs=0.005))),
                             ((0.3, approx(-1.398, abs=0.006)), (-0.3, approx(-1.398, abs=0.006))),
                             cm_at={0.0: approx(0.036, abs=0.002)}, term="aero/moment/Pitch_alphadot")
    assert_lateral_derivatives(spec, (approx(0.100, abs=1e-4), approx(-0.0082, abs=1e-4)),
                               (approx(-0.0949, abs=2e-4), approx(0.0161, abs=2e-4)),
                               {0.0: (approx(-0.0771, abs=5e-4), approx(0.0947, abs=5e-4)),
                                6.0: (approx(-0.0976, abs=5e-4), approx(0.0947, abs=5e-4))}, aileron_prop=AILERON)
