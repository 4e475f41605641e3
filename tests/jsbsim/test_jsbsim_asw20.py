"""The asw20 in the JSBSim harness: the fifteenth session's untouched aircraft, a tuning aircraft since its final
evaluation was read (docs/jsbsim.md, "The asw20").

The model is FlightGear's ASW 20 sailplane (``Models/JSBSim/asw20-JSBSim.xml`` of FGMEMBERS/asw20 at commit
3ef71d9c, GPL-2.0-or-later; D-NXKT's 2013 conversion of Michael Selig's UIUC ASW 20), checked in under
``data/jsbsim_models/asw20/`` and flown as the derived model ``asw20_glide`` (``derived.py``): FlightGear's
engine and water-ballast systems and its ``Water Dumping`` channel removed, its tail table reading the elevator
through an alias. It is flown at 3000 ft, where JSBSim's light turbulence is active, as the sgs126 was.

The checks here use the XML and JSBSim's own properties; none of them flies the harness:

- the checked-in file is the one the README names, and the derivation changes only what it says;
- the alias changes no number: JSBSim's forces and moments equal those of the file without it;
- the FCS maps the commands straight to the surfaces the aerodynamics read, the aileron's the other way
  round (``cmd_per_rad`` negative), with no damper; no engine, no external force;
- it is statically stable about the CG, and its aileron and rudder act as its XML says.

The summaries' label test moved to ``test_jsbsim_iar80.py`` in the sixteenth session (the iar80 is untouched).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign
map, gear, .tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``.
All of them but the names are slow.

No pipeline fit, GP, diagnosis or scoring runs in these tests.
"""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import checked_in_model
from static_checks import assert_aero_is_the_only_force, assert_aileron_maps_back, assert_lateral_derivatives, \
    assert_pitch_derivatives, ic_state, surface_state

SRC = "data/jsbsim_models/asw20/asw20-JSBSim.xml"
SRC_SHA256 = "c3a7877a124d79fcc82340614703cc07795993a06552ad6df9f05b10d1bdbc48"


def _state(alpha_deg=-2.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0):
    """:func:`static_checks.ic_state` for the asw20 (65 kt at 3000 ft, Mach 0.108)."""
    return ic_state(aircraft("asw20"), alpha_deg, beta_deg, cmds, r_rad_s)


def test_the_derivation_removes_only_flightgears_parts_and_aliases_the_elevator():
    """The checked-in XML is the README's (40719 bytes, its SHA-256). ``asw20_glide`` is that XML with:

    - its two ``<system>`` elements (``GenericEngine``, ``WaterBallast``: files not copied) removed;
    - the ``Water Dumping`` FCS channel (it reads FlightGear's ``/sim/asw20/waterballast/valve``) removed;
    - the ``CmDe`` table's ``fcs/elevator-pos-deg`` lookup pointed at ``aero/function/elevator-pos-deg``,
      a function added first in ``<aerodynamics>``: 57.29577951... x ``fcs/elevator-pos-rad``;

    and every other element equal (metrics, mass balance, ground reactions, external reactions, propulsion,
    the other FCS channels, every aerodynamic function). The spec's notes carry the derived XML's hash."""
    from benchmarks.jsbsim_harness.derived import ELEVATOR_DEG_ALIAS, derived_xml

    src, der, spec = checked_in_model("asw20", "asw20_glide", SRC, 40719, SRC_SHA256)
    canon = lambda e: ET.tostring(e, encoding="unicode").split()       # noqa: E731  (layout aside)
    assert [c.tag for c in src if c.tag != "system"] == [c.tag for c in der]
    assert sorted(s.get("file") for s in src.findall("system")) == ["GenericEngine", "WaterBallast"]
    for tag in ("metrics", "mass_balance", "ground_reactions", "external_reactions", "propulsion"):
        assert canon(src.find(tag)) == canon(der.find(tag)), tag
    chans = lambda r: [ch for ch in r.find("flight_control") if ch.tag == "channel"]   # noqa: E731
    kept = [ch for ch in chans(src) if ch.get("name") != "Water Dumping"]
    assert len(kept) == len(chans(src)) - 1 and list(map(canon, kept)) == list(map(canon, chans(der)))
    alias = der.find("aerodynamics")[0]
    assert alias.get("name") == ELEVATOR_DEG_ALIAS
    assert float(alias.find("product/value").text) == pytest.approx(180 / np.pi, rel=1e-15)
    assert alias.find("product/property").text == "fcs/elevator-pos-rad"
    for iv in src.find("aerodynamics").iter("independentVar"):
        if iv.text.strip() == "fcs/elevator-pos-deg":
            iv.text = ELEVATOR_DEG_ALIAS
    assert [canon(a) for a in src.find("aerodynamics")] == [canon(a) for a in list(der.find("aerodynamics"))[1:]]


def test_the_alias_changes_no_force_or_moment(tmp_path):
    """JSBSim's aerodynamic forces and moments of ``asw20_glide`` equal those of the same model whose tail
    table reads ``fcs/elevator-pos-deg`` directly (the derivation without the alias), at alphas -4..4 deg,
    4 deg of sideslip and elevator commands -0.6..0.6: the alias is JSBSim's own rad-to-deg conversion."""
    from benchmarks.jsbsim_harness import FlightConfig
    from benchmarks.jsbsim_harness.derived import ELEVATOR_DEG_ALIAS, derived_xml
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("asw20")
    root = ET.fromstring(derived_xml(spec.model))
    aero = root.find("aerodynamics")
    aero.remove(aero[0])
    for iv in aero.iter("independentVar"):
        if iv.text.strip() == ELEVATOR_DEG_ALIAS:
            iv.text = "fcs/elevator-pos-deg"
    (tmp_path / spec.model).mkdir()
    ET.ElementTree(root).write(tmp_path / spec.model / f"{spec.model}.xml", encoding="unicode")

    def loads(path, alpha, de):
        fdm = load_model(spec, 1 / 200, 0, path)
        _set_ic(fdm, spec, FlightConfig("asw20", turbulence="none"))
        fdm["ic/alpha-deg"], fdm["ic/beta-deg"] = alpha, 4.0
        fdm["fcs/elevator-cmd-norm"], fdm["fcs/aileron-cmd-norm"], fdm["fcs/rudder-cmd-norm"] = de, 0.3, -0.2
        fdm.run_ic()
        return [fdm[f"forces/fb{a}-aero-lbs"] for a in "xyz"] + [fdm[f"moments/{a}-aero-lbsft"] for a in "lmn"]

    for alpha in (-4.0, 0.0, 4.0):
        for de in (-0.6, 0.0, 0.6):
            assert loads(None, alpha, de) == pytest.approx(loads(tmp_path, alpha, de), rel=1e-12, abs=1e-9)


def test_the_asw20_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps the commands straight to the surfaces (``aerosurface_scale``, no damper):

    - elevator -0.43633..+0.38397 rad (-25..+22 deg), zero-centred;
    - left and right aileron both -0.43633 x the command (the file's gain -1; the aerodynamics read the left
      alone: Clda -0.214 x left), so the harness's delta_a is +left and its aileron ``cmd_per_rad`` is
      -1 / 0.43633: a commanded delta_a comes back as the logged one;
    - rudder 31 x 0.01745 = 0.54095 rad x the command.

    No engine; the external forces (winch, aerotow, FlightGear's generic engine) are 0, and after 50 frames
    every non-gravity force and moment is aerodynamic. A yaw rate does not move the rudder (no yaw damper),
    so the harness's own damper flies it (k_r 0.4)."""
    spec = aircraft("asw20")
    assert spec.gains[5] == 0.4 and spec.gear_up and spec.aileron_props == ("fcs/left-aileron-pos-rad", None)
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 0.38397), "fcs/left-aileron-pos-rad": (1, -0.43633),
                               "fcs/right-aileron-pos-rad": (1, -0.43633), "fcs/rudder-pos-rad": (2, 31 * 0.01745)},
                        up=0.43633, alpha_deg=-2.0, r_rad_s=0.2)
    assert fdm.get_propulsion().get_num_engines() == 0
    assert_aileron_maps_back(spec, -2.0)
    assert_aero_is_the_only_force(fdm, 300.0, external_zero=True)


def test_the_asw20_is_statically_stable_and_its_controls_act_as_its_xml_says():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic``, the harness's initial condition, Mach 0.108;
    the CG and the aerodynamic reference point coincide).

    - **Pitch:** without its ``Cmadot`` term, Cm falls with alpha: -1.14 per rad between -4 and 0 deg, -1.38
      between 0 and 4 deg (its wing-body ``Cmalpha`` table rises +0.62 then +0.37 per rad with a break at 0;
      the tail's ``CmDe`` table falls -1.76 per rad at zero elevator). Cm is about 0 at alpha -2 deg.
    - **Elevator:** Cm per rad of elevator -0.786 at alpha -2 deg (its CmDe table, breakpoints -20, 0, +20 deg), on
      both sides of zero.
    - **Roll and yaw:** per rad of left aileron Cl -0.214 (Clda) and Cn -0.017 (Cnda: the project's
      Cn_delta_a -0.017, proverse); per rad of rudder Cl 0.0065 (ClDr) and Cn -0.041 (CnDr); Cl_beta -0.0693
      (Clb), Cn_beta 0.1007 (Cnb). Cl and Cn at rest are 0.
    """
    spec = aircraft("asw20")
    # Cm at alpha -2 within 0.01 (was < 0.01: the same but for Cm exactly 0.01)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-1.14, abs=0.02)), (0.0, 4.0, approx(-1.38, abs=0.02))),
                             ((-0.5, approx(-0.786, abs=0.005)), (0.5, approx(-0.786, abs=0.005))),
                             cm_at={-2.0: approx(0.0, abs=0.01)}, alpha_e=-2.0, travel=(0.43633, 0.38397))
    assert_lateral_derivatives(spec, (approx(-0.214, rel=1e-6), approx(-0.017, rel=1e-6)),
                               (approx(-0.041, rel=1e-6), approx(0.0065, rel=1e-6)),
                               {-2.0: (approx(-0.0693, rel=1e-6), approx(0.1007, rel=1e-6))},
                               alpha_deg=-2.0, rest=1e-12, aileron_cmds=(0.4,), rudder_cmds=(0.4,))
