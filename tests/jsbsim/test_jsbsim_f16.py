"""The f16 in the JSBSim harness: the eleventh session's untouched aircraft (docs/jsbsim.md, "The f16"),
a tuning aircraft since its final evaluation was read (the twelfth session's untouched one is the f4n,
``test_jsbsim_f4n.py``, which now holds the summaries' label check).

The F-16 is flown as a derived model (``benchmarks/jsbsim_harness/derived.py``): the wheel's
``f16.xml`` with its fly-by-wire replaced by a direct map of the commands to the surfaces and its
flaps fixed. Its own checks are here, on the XML and JSBSim's own properties, no flight: the derived
XML is the stock one but for the flight control and the elevator alias, its hash is the one in the
spec (so in the fingerprint), the commands reach the surfaces the aerodynamics read and nothing else
moves them, the aerodynamics read through the alias give the stock tables' forces and moments, and
it is statically stable about the CG. The checks it shares with the other aircraft (names, rigid
body, sign map, gear, .tlog, hidden effects, airspeed bias, the evaluation's flights in the
envelope, ``--fly-only``; slow but the names') are in ``test_jsbsim_roster.py``.
No pipeline fit, GP, diagnosis or scoring runs here.
"""

import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft
from benchmarks.jsbsim_harness.derived import ELEVATOR_ALIAS, derived_sha, derived_xml


def _state(spec, aircraft_path=None, alpha_deg=4.0, beta_deg=4.0, cmds=(0.3, -0.4, 0.2)):
    """JSBSim at the harness's initial condition with the given alpha, sideslip and fixed commands,
    after ``run_ic`` (models evaluated, nothing integrated)."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    fdm = load_model(spec, 1 / 200, 0, aircraft_path)
    _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
    fdm["ic/alpha-deg"], fdm["ic/beta-deg"] = alpha_deg, beta_deg
    fdm["fcs/elevator-cmd-norm"], fdm["fcs/aileron-cmd-norm"], fdm["fcs/rudder-cmd-norm"] = cmds
    fdm.run_ic()
    return fdm


def test_the_derived_model_is_the_wheels_f16_with_direct_surfaces():
    """The derived XML (hash in the spec's notes, so in the f16's fingerprint; the installed copy
    is it) keeps every element of the stock f16.xml but the flight control, with the aerodynamics
    equal once the elevator alias is undone; its flight control reads only the three commands, the
    gear and the throttle commands (no sensor, no law). In JSBSim, at alpha 4 deg, sideslip 4 deg
    and commands (0.3, -0.4, 0.2): the surfaces are the commands times 0.436, 0.375 and 0.524 rad,
    the flaps 0; and every force and moment equals that of the same model whose tables read
    ``fcs/elevator-pos-rad`` directly (the alias changes no number)."""
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    spec = aircraft("f16")
    xml = derived_xml("f16_direct")
    assert f"XML sha256 {derived_sha('f16_direct')}" in spec.notes
    assert (stock_model_dir(spec) / "f16_direct.xml").read_bytes() == xml
    derived = ET.fromstring(xml)
    stock = ET.parse(stock_model_dir(aircraft("f16")).parent / "f16" / "f16.xml").getroot()
    aero = derived.find("aerodynamics")
    alias = aero.find("function")
    assert alias.get("name") == ELEVATOR_ALIAS and alias.find("property").text == "fcs/elevator-pos-rad"
    aero.remove(alias)
    for iv in aero.iter("independentVar"):
        if iv.text == ELEVATOR_ALIAS:
            iv.text = "fcs/elevator-pos-rad"
    canon = lambda e: ET.tostring(e, encoding="unicode").replace(" ", "").replace("\n", "")   # noqa: E731
    assert [c.tag for c in derived] == [c.tag for c in stock]
    for d, s in zip(derived, stock):
        assert d.tag == "flight_control" or canon(d) == canon(s), d.tag
    inputs = {i.text.strip().lstrip("-") for i in derived.find("flight_control").iter("input")}
    assert inputs == {"fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm", "gear/gear-cmd-norm",
                      "fcs/steer-cmd-norm", "fcs/throttle-cmd-norm"}, inputs

    fdm = _state(spec)
    assert fdm["fcs/elevator-pos-rad"] == pytest.approx(0.3 * 0.436, rel=1e-12)
    assert fdm["fcs/aileron-pos-rad"] == pytest.approx(-0.4 * 0.375, rel=1e-12)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.2 * 0.524, rel=1e-12)
    assert fdm["fcs/lef-pos-rad"] == fdm["fcs/flaperon-mix-rad"] == fdm["fcs/speedbrake-pos-rad"] == 0.0
    assert fdm[ELEVATOR_ALIAS] == fdm["fcs/elevator-pos-rad"]
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copytree(stock_model_dir(spec), Path(tmp) / "f16_direct")     # its Systems/ too
        root = ET.fromstring(xml)
        a = root.find("aerodynamics")
        a.remove(a.find("function"))
        for iv in a.iter("independentVar"):
            if iv.text == ELEVATOR_ALIAS:
                iv.text = "fcs/elevator-pos-rad"
        ET.ElementTree(root).write(Path(tmp) / "f16_direct" / "f16_direct.xml")
        direct = _state(spec, tmp)
        for k in ("forces/fbx-aero-lbs", "forces/fby-aero-lbs", "forces/fbz-aero-lbs", "moments/l-aero-lbsft",
                  "moments/m-aero-lbsft", "moments/n-aero-lbsft"):
            assert fdm[k] == pytest.approx(direct[k], rel=1e-12, abs=1e-9), k
            assert abs(fdm[k]) > 10.0, k


def test_the_f16_is_statically_stable_about_its_cg():
    """JSBSim's pitching moment about the CG at fixed surfaces (``run_ic``, the harness's initial
    condition, sideslip 0) falls with alpha: Cm_alpha -0.026 per rad between 0 and 4 deg and -0.079
    between 4 and 8 deg (relaxed: the CG is 2.4 in ahead of the reference point), and the elevator
    is powerful (Cm per rad of elevator -0.54)."""
    spec = aircraft("f16")

    def cm(alpha, de=0.0):
        fdm = _state(spec, alpha_deg=alpha, beta_deg=0.0, cmds=(de, 0.0, 0.0))
        return fdm["moments/m-aero-lbsft"] / (fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm["metrics/cbarw-ft"])

    c0, c4, c8 = cm(0.0), cm(4.0), cm(8.0)
    slope = lambda a, b: (b - a) / np.radians(4.0)   # noqa: E731
    assert slope(c0, c4) == pytest.approx(-0.026, abs=0.005) and slope(c4, c8) == pytest.approx(-0.079, abs=0.005)
    assert (cm(4.0, 0.2 / 0.436) - c4) / 0.2 == pytest.approx(-0.54, abs=0.02)
