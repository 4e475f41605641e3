"""The s23 in the JSBSim harness: the twenty-fourth session's untouched aircraft, a tuning aircraft since the
twenty-fifth session (docs/jsbsim.md, "The s23").

The model is JSBSim's Short S.23 "Empire" flying boat (Anders Gidenstam 2008-2023, GPL-2.0-or-later; the jsbsim 1.3.3
wheel's ``aircraft/Short_S23/Short_S23.xml`` and ``Systems/datcom_aero.xml``), a 1936 four-engine flying boat of
33686 lb as the harness flies it and 114 ft (34.75 m) of span, whose aerodynamics are USAF DATCOM (Datcom+) tables
in alpha. Both files are checked in under ``data/jsbsim_models/shorts23/`` and flown as the derived model
``ShortS23_glide`` (``derived.py``): engines, propellers, the hull's water forces and the nine systems removed, the
aerodynamics inlined, their elevator lookups through an identity alias.

The checks here use the files and JSBSim's own properties (the harness's initial condition, ``run_ic``, no
turbulence: a mechanism check); none of them flies the harness:

- the checked-in files are the ones the README names, and the derivation makes only its five edits; JSBSim's
  aerodynamic forces and moments of the derived model equal the stock wheel model's;
- the FCS maps the commands straight to the surfaces (elevator +-18 deg, ailerons +-19.5 deg, rudder +-22.5 deg);
  no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its tables say;
- the summaries label it bare, as every tuning aircraft (until the next untouched aircraft is added, no aircraft is
  labelled "(untouched)").

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, .tlog,
hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the names
are slow.

No pipeline fit, GP, diagnosis or scoring ran on the s23 before its final evaluation (twenty-fourth session); it is
a tuning aircraft since.
"""

import dataclasses
import hashlib
import xml.etree.ElementTree as ET

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_kept_but_engines, assert_same_aero_as_stock, assert_summaries_label_bare, bare_xml, \
    checked_in_model
from static_checks import assert_aero_is_the_only_force, assert_deflections_map_back, assert_lateral_derivatives, \
    assert_pitch_derivatives, ic_state, surface_state

SRC = "data/jsbsim_models/shorts23/Short_S23.xml"
SRC_SHA256 = "b4ba55cceeaca5057bacfb59b510bf3bdc8e9ea19efbd007904700ab2439282f"
AERO = "data/jsbsim_models/shorts23/datcom_aero.xml"
AERO_SHA256 = "f115dfe222b379e3cc78090f760e154be8aa5788ab3580311bedca38715001a6"


def _state(alpha_deg=0.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), model=None):
    """:func:`static_checks.ic_state` for the s23 (130 kt at 6000 ft; it glides near alpha -2 deg), or for the same
    spec flying ``model`` (the stock wheel model)."""
    spec = aircraft("s23")
    return ic_state(dataclasses.replace(spec, model=model) if model else spec, alpha_deg, beta_deg, cmds)


def test_the_derivation_removes_the_engines_water_forces_and_systems_and_inlines_the_aerodynamics():
    """The checked-in files are the README's (28570 and 58651 bytes, their SHA-256). ``ShortS23_glide`` is the main
    file without its four ``<engine>`` elements, its ``<external_reactions>`` and its nine ``<system>`` elements, the
    ``<aerodynamics file=...>`` reference replaced by ``datcom_aero.xml``'s ``<aerodynamics>`` whose four elevator
    lookups read ``aero/function/elevator-pos-rad``, the identity function of ``fcs/elevator-pos-rad`` added as its
    first child; the twelve tanks and every other element are equal (metrics, mass balance, ground reactions, the
    flight control), and so is every aerodynamic function but the alias. The spec's notes carry the derived XML's
    hash."""
    from benchmarks.jsbsim_harness.derived import ELEVATOR_ALIAS
    from benchmarks.jsbsim_harness.logfile import _REPO

    src, der, spec = checked_in_model("s23", "ShortS23_glide", SRC, 28570, SRC_SHA256)
    raw = (_REPO / AERO).read_bytes()
    assert len(raw) == 58651 and hashlib.sha256(raw).hexdigest() == AERO_SHA256
    aero = ET.fromstring(raw)
    ET.indent(src, space=" ")
    ET.indent(aero, space=" ")
    assert_kept_but_engines(src, der, ("metrics", "mass_balance", "ground_reactions", "flight_control"), 4, 12)
    assert der.find("system") is None and der.find("external_reactions") is None
    assert [x.get("file") for x in src.findall("system")] == [
        "hydrodynamics", "hydrodynamic-planing-floats", "Short_S23-hydrodynamics", "sperry-a2-autopilot",
        "take-off-ap", "engines", "fuel-system", "electrical", "flaps"]
    assert [c.tag for c in der] == [c.tag for c in src if c.tag not in ("external_reactions", "system")]
    d_aero = der.find("aerodynamics")
    assert d_aero.get("file") is None and d_aero[0].get("name") == ELEVATOR_ALIAS
    assert [p.text for p in d_aero[0].iter("property")] == ["fcs/elevator-pos-rad"]
    lookups = [iv for iv in aero.iter("independentVar") if iv.text.strip() == "fcs/elevator-pos-rad"]
    assert len(lookups) == 4
    for iv in lookups:
        iv.text = ELEVATOR_ALIAS
    s_fun, d_fun = list(aero.iter("function")), list(d_aero.iter("function"))[1:]
    assert len(s_fun) == len(d_fun) == 36
    for a, b in zip(s_fun, d_fun):
        assert bare_xml(a) == bare_xml(b), a.get("name")


def test_the_derived_aerodynamics_are_the_stock_models():
    """At three states (alpha, sideslip, the three commands), JSBSim's aerodynamic forces and moments of
    ``ShortS23_glide`` equal those of the wheel's stock ``Short_S23`` (four windmilling engines, its systems idle)
    to the last bit: the derivation changes no number."""
    assert_same_aero_as_stock(_state, lambda *a: _state(*a, model="Short_S23"), 4)


def test_the_s23_flies_its_own_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface (``aerosurface_scale``): elevator +-0.3142 rad (18 deg),
    both ailerons +-0.3403 rad (19.5 deg) with the command's sign (the aerodynamics read the left one: delta_a =
    -left with ``aileron_sign`` -1), rudder +-0.3927 rad (22.5 deg). No engine; 33686 lb (the crew's off-centre
    seats and the engines' oil emptied); after 50 frames every non-gravity force and moment is aerodynamic and the
    external forces are 0."""
    spec = aircraft("s23")
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 0.3142), "fcs/left-aileron-pos-rad": (1, 0.3403),
                               "fcs/right-aileron-pos-rad": (1, 0.3403), "fcs/rudder-pos-rad": (2, 0.3927)},
                        alpha_deg=0.0, rel=1e-6)
    assert fdm.get_propulsion().get_num_engines() == 0 and fdm["inertia/weight-lbs"] == pytest.approx(33685.7, abs=0.1)
    assert spec.cmd_per_rad == pytest.approx((1 / 0.3142, 1 / 0.3403, 1 / 0.3927))
    assert_deflections_map_back(spec)
    assert_aero_is_the_only_force(fdm, 10000.0, external_zero=True)


def test_the_s23_is_statically_stable_and_its_controls_act_as_its_tables_say():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, 130 kt at
    6000 ft, Mach 0.239) without the ``Cmadot`` term (``run_ic`` gives an alpha-dot the term reads).

    - **Pitch:** Cm falls with alpha: -0.530 per rad between alpha -4 and 0 deg, -0.546 between 0 and 4, -0.809
      between 4 and 8 (Cm_basic's DATCOM table and the lift through the reference point 23 in ahead of and 42 in
      above the CG); Cm +0.048 at alpha 0; per rad of elevator -1.07 to -1.08 (CmDe's table).
    - **Roll and yaw:** per rad of the left aileron Cl +0.1216 (ClDs4; the project's Cl_delta_a -0.1216) and Cn
      -0.0098 (CnDa at alpha 0; Cn_delta_a +0.0098, adverse); per rad of rudder Cn -0.060 (CnDr) and Cl 0 (ClDr and
      CyDr are 0); Cl_beta -0.128 at alpha 0 and -0.121 at 6 deg (Clb's table and the side force through the
      reference point's height), Cn_beta 0.069 and 0.068 (Cnb's table).
    """
    spec = aircraft("s23")
    assert _state()["velocities/mach"] == pytest.approx(0.2395, abs=0.002)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.530, abs=0.005)), (0.0, 4.0, approx(-0.546, abs=0.005)),
                                    (4.0, 8.0, approx(-0.809, abs=0.005))),
                             ((0.3, approx(-1.076, abs=0.006)), (-0.3, approx(-1.076, abs=0.006))),
                             cm_at={0.0: approx(0.048, abs=0.002)})
    # ClDr and CyDr are 0: the rudder's Cl per rad within 1e-9 (|dCl| < 1.2e-10; the check was |dCl| < 1e-9)
    assert_lateral_derivatives(spec, (approx(0.1216, abs=2e-4), approx(-0.0098, abs=2e-4)),
                               (approx(-0.060, abs=1e-6), approx(0.0, abs=1e-9)),
                               {0.0: (approx(-0.1281, abs=5e-4), approx(0.0692, abs=5e-4)),
                                6.0: (approx(-0.1206, abs=5e-4), approx(0.0681, abs=5e-4))})


def test_summaries_mark_no_aircraft_untouched_the_s23_included(tmp_path):
    """The markdown summaries of eval_jsbsim and eval_jsbsim_diagnose label the s23 bare, as every other aircraft
    (synthetic rows): the twenty-fifth session moved it to tuning, and no aircraft is "(untouched)" or "(held out)"
    until the next one is added."""
    assert_summaries_label_bare(tmp_path, "s23", ("s23", "ka350"))
