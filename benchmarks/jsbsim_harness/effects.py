"""Hidden effects injected into a stock JSBSim aircraft, with the injected truth kept apart.

An effect is either an edit of a *copy* of the aircraft's XML (the wheel's files are never
touched) or a sensor error added to the logged streams:

| effect | where | injected truth (project convention, ``docs/conventions.md``) |
|---|---|---|
| ``Cm:alpha^2`` | PITCH axis: ``+ k alpha^2`` (qbar S c) | ``Cm:alpha^2`` = ``k`` (1/rad^2) |
| ``Cl:alpha*beta`` | ROLL axis: ``+ k alpha beta`` (qbar S b) | ``Cl:alpha*beta`` = ``k`` (1/rad^2) |
| ``Cn:delta_a`` | YAW axis: ``+ k delta_a`` with the project's delta_a (qbar S b) | ``Cn:delta_a`` = ``k`` (1/rad) |
| ``CY:scale`` | every SIDE-axis function times ``k`` | ``scale:CY`` = ``k - 1``, the change of the factor on the whole side force (also kept: the change of CY_beta, ``(k - 1) CY_beta`` of the stock model by least squares on the exact truth) |
| ``delay:delta_e`` | the aerodynamics read ``fcs/elevator-pos-rad`` through a pure delay of ``k`` s (an FCS ``actuator`` with a ``<delay>`` of whole frames); the logged surface position is not delayed | ``delay:delta_e`` = ``k`` (s) |
| ``bias:airspeed`` | sensor side: the logged pitot airspeed (SCALED_PRESSURE, VFR_HUD) reads ``k`` m/s too high in TAS | ``bias:airspeed`` = ``k`` (m/s TAS) |

Each aero value is the *change* the effect makes to that term: the model under test was fitted
on a clean flight of the same aircraft, so a diagnosis estimate is compared as
``estimate - model value`` (``benchmarks/eval_jsbsim_diagnose.py``). Moments added in JSBSim's
ROLL/PITCH/YAW axes are pure couples, so they reach the coefficients about the CG unchanged.

The truth is written to ``<stem>-effects.json`` beside the flight's ``-truth.npz``; neither is
read by the pipeline.

References:
    JSBSim Reference Manual, "Aerodynamics" (axis functions are summed) and "FCS components"
    (``<delay>`` of any component). Issue 9 of this project lists the effects.
"""

from __future__ import annotations

import copy
import json
import shutil
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .aircraft import AircraftSpec, aircraft
from .flight import FlightConfig, Recording, fly
from .logfile import FlightFiles, harness_fingerprint, write_log
from .sensors import make_sensors
from .truth import save_truth, truth_coefficients, truth_regressors

__all__ = ["Effect", "EFFECTS", "SIZES", "case_stem", "inject_xml", "make_effect_flight", "stock_model_dir",
           "side_force_beta"]

RHO0 = 1.225

#: The effects and their two sizes (project units: 1/rad^2, 1/rad, scale, s, m/s TAS). Chosen
#: on 2026-11-21 before any diagnosis run: each is a few percent of its coefficient's RMS in the
#: harness's maneuvers (small) and about twice that (large).
SIZES: dict[str, tuple[float, float]] = {
    "Cm:alpha^2": (-4.0, -8.0),
    "Cl:alpha*beta": (1.5, 3.0),
    "Cn:delta_a": (-0.03, -0.06),
    "CY:scale": (1.3, 1.6),
    "delay:delta_e": (0.06, 0.12),
    "bias:airspeed": (1.0, 2.0),
}
EFFECTS = tuple(SIZES)


@dataclass(frozen=True)
class Effect:
    """One injected effect.

    Attributes:
        name: one of :data:`EFFECTS`.
        value: its size in the units of :data:`SIZES` (for ``CY:scale`` the factor).
    """

    name: str
    value: float

    def __post_init__(self):
        if self.name not in SIZES:
            raise ValueError(f"unknown effect '{self.name}' (known: {', '.join(SIZES)})")


def stock_model_dir(spec: AircraftSpec) -> Path:
    """The wheel's folder of ``spec``'s model (read only)."""
    import jsbsim

    return Path(jsbsim.get_default_root_dir()) / "aircraft" / spec.model


def _prop(parent: ET.Element, name: str) -> None:
    ET.SubElement(parent, "property").text = name


def _moment_function(axis: ET.Element, name: str, ref_len: str, k: float) -> ET.Element:
    f = ET.SubElement(axis, "function", name=f"aero/coefficient/injected_{name}")
    ET.SubElement(f, "description").text = f"injected by benchmarks/jsbsim_harness/effects.py: {name}"
    prod = ET.SubElement(f, "product")
    _prop(prod, "aero/qbar-area")
    _prop(prod, ref_len)
    ET.SubElement(prod, "value").text = repr(float(k))
    return prod


def _axis(root: ET.Element, name: str) -> ET.Element:
    for ax in root.iter("axis"):
        if ax.get("name") == name:
            return ax
    raise ValueError(f"the model has no aerodynamics axis '{name}'")


def inject_xml(root: ET.Element, spec: AircraftSpec, effects: list[Effect],
               sim_rate_hz: float = 200.0) -> ET.Element:
    """Return a copy of the aircraft XML ``root`` with the aero/FCS ``effects`` edited in.

    ``sim_rate_hz``: JSBSim's integration rate (the delay is a whole number of frames of it).

    Sensor effects (``bias:airspeed``) are not XML edits and are skipped here.

    Raises:
        ValueError: the model lacks the axis or property an effect needs.
    """
    root = copy.deepcopy(root)
    for e in effects:
        if e.name == "Cm:alpha^2":
            p = _moment_function(_axis(root, "PITCH"), "Cm_alpha2", "metrics/cbarw-ft", e.value)
            _prop(p, "aero/alpha-rad")
            _prop(p, "aero/alpha-rad")
        elif e.name == "Cl:alpha*beta":
            p = _moment_function(_axis(root, "ROLL"), "Cl_alpha_beta", "metrics/bw-ft", e.value)
            _prop(p, "aero/alpha-rad")
            _prop(p, "aero/beta-rad")
        elif e.name == "Cn:delta_a":
            left, right = spec.aileron_props
            if right is None:
                p = _moment_function(_axis(root, "YAW"), "Cn_delta_a", "metrics/bw-ft", e.value * spec.aileron_sign)
                _prop(p, left)
            else:
                p = _moment_function(_axis(root, "YAW"), "Cn_delta_a", "metrics/bw-ft",
                                     0.5 * e.value * spec.aileron_sign)
                d = ET.SubElement(p, "difference")
                _prop(d, left)
                _prop(d, right)
        elif e.name == "CY:scale":
            for f in _axis(root, "SIDE").findall("function"):
                body = [c for c in f if c.tag != "description"]
                if len(body) != 1:
                    raise ValueError(f"SIDE function {f.get('name')}: expected one expression")
                prod = ET.Element("product")
                ET.SubElement(prod, "value").text = repr(float(e.value))
                prod.append(body[0])
                f.remove(body[0])
                f.append(prod)
        elif e.name == "delay:delta_e":
            fc = root.find("flight_control")
            if fc is None:
                raise ValueError("the model has no <flight_control> to add the delay to")
            ch = ET.SubElement(fc, "channel", name="injected elevator delay")
            g = ET.SubElement(ch, "actuator", name="injected elevator delay")
            ET.SubElement(g, "input").text = "fcs/elevator-pos-rad"
            # frames, not type="time": JSBSim converts a time with the dt at load time (1/120 s),
            # before the harness sets its own; a pure_gain ignored the delay on jsbsim 1.3
            ET.SubElement(g, "delay", type="frames").text = str(int(round(e.value * sim_rate_hz)))
            ET.SubElement(g, "output").text = "fcs/elevator-pos-delayed-rad"
            aero = root.find("aerodynamics")
            n = 0
            for el in aero.iter("property"):
                if el.text and el.text.strip() == "fcs/elevator-pos-rad":
                    el.text = "fcs/elevator-pos-delayed-rad"
                    n += 1
            if n == 0:
                raise ValueError("the aerodynamics never read fcs/elevator-pos-rad")
    return root


def _write_model(spec: AircraftSpec, effects: list[Effect], dest: Path, sim_rate_hz: float = 200.0) -> Path:
    """Copy the stock model folder into ``dest/<model>`` and write the edited XML there."""
    src = stock_model_dir(spec)
    out = dest / spec.model
    shutil.copytree(src, out)
    xml = out / f"{spec.model}.xml"
    tree = ET.parse(xml)
    tree._setroot(inject_xml(tree.getroot(), spec, effects, sim_rate_hz))
    tree.write(xml, encoding="utf-8", xml_declaration=True)
    return dest


def side_force_beta(truth: dict, rows=slice(None)) -> float:
    """CY_beta of the flown model: least squares of the exact CY on beta, p_hat, r_hat, delta_a, delta_r, 1.

    Args:
        truth: arrays of a truth file (``X`` (T, 10), ``Y`` (T, 6)).
    """
    X, Y = np.asarray(truth["X"])[rows], np.asarray(truth["Y"])[rows]
    if X.shape[0] == 10 and X.shape[1] != 10:
        X, Y = X.T, Y.T
    A = np.column_stack([np.ones(len(X)), X[:, 1], X[:, 2], X[:, 4], X[:, 6], X[:, 7]])
    ok = np.isfinite(A).all(1) & np.isfinite(Y[:, 1])
    th, *_ = np.linalg.lstsq(A[ok], Y[ok, 1], rcond=None)
    return float(th[1])


def _bias_airspeed(sensors: dict, rec: Recording, bias: float) -> dict:
    """Add ``bias`` m/s of TAS to the logged pitot (airspeed EAS stream, differential pressure)."""
    tr = rec.truth
    k = np.sqrt(np.asarray(tr["rho"]) / RHO0)            # EAS per TAS
    eas = np.maximum(sensors["airspeed"]["eas"] + bias * k, 0.0)
    sensors["airspeed"]["eas"] = eas
    tp = sensors["pressure"]["t"]
    sensors["pressure"]["diff_pressure"] = 0.5 * RHO0 * np.interp(tp, sensors["airspeed"]["t"], eas) ** 2
    return sensors


def case_stem(aircraft_name: str, seed: int, effects) -> str:
    """The file stem of a case, ``<aircraft>-s<seed>-<name>=<value>[+...]`` or ``...-clean``, with the
    characters a file name should not carry replaced (``:`` -> ``_``, ``*`` -> ``x``, ``^`` dropped).

    Args:
        aircraft_name: harness aircraft name. seed: the flight's seed. effects: ``(name, value)`` pairs.
    """
    tag = "+".join(f"{n}={v:g}" for n, v in effects) or "clean"
    return f"{aircraft_name}-s{seed}-{tag}".replace(":", "_").replace("*", "x").replace("^", "")


def make_effect_flight(config: FlightConfig, effects: list[Effect], out_dir: str | Path, aoa: str = "ahrs",
                       stem: str | None = None) -> FlightFiles:
    """Fly ``config`` with ``effects`` injected; write ``<stem>.tlog``, ``-truth.npz`` and ``-effects.json``.

    ``-effects.json`` also holds the flight's configuration and the harness fingerprint
    (:func:`~benchmarks.jsbsim_harness.logfile.harness_fingerprint`), by which
    ``benchmarks/eval_jsbsim_diagnose.py`` decides whether the files can be reused.

    Returns:
        the :class:`FlightFiles` (the airframe is the aircraft's checked-in file: the engineer's
        nominal data, unaware of the effect).

    Raises:
        ValueError: unknown effect or one the model cannot take.
        RuntimeError: JSBSim failed or the aircraft left the envelope (:func:`fly`).
    """
    spec = aircraft(config.aircraft)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = stem or case_stem(config.aircraft, config.seed, [(e.name, e.value) for e in effects])
    xml_effects = [e for e in effects if e.name != "bias:airspeed"]
    if xml_effects:
        with tempfile.TemporaryDirectory(prefix="jsbsim-effect-") as tmp:
            rec = fly(config, _write_model(spec, xml_effects, Path(tmp), config.sim_rate_hz))
    else:
        rec = fly(config)
    sensors = make_sensors(rec, aoa)
    for e in effects:
        if e.name == "bias:airspeed":
            sensors = _bias_airspeed(sensors, rec, e.value)
    tlog, truth = out / f"{stem}.tlog", out / f"{stem}-truth.npz"
    write_log(rec, tlog, aoa, sensors=sensors)
    save_truth(rec, truth)
    injected = []
    for e in effects:
        if e.name == "CY:scale":
            cyb = side_force_beta({"X": truth_regressors(rec), "Y": truth_coefficients(rec)})
            stock = cyb / e.value
            injected.append({"effect": e.name, "cause": "scale:CY", "value": e.value - 1.0, "unit": "1",
                             "scale": e.value, "CY_beta_change": (e.value - 1.0) * stock, "stock_CY_beta": stock})
        else:
            unit = {"Cm:alpha^2": "1/rad^2", "Cl:alpha*beta": "1/rad^2", "Cn:delta_a": "1/rad",
                    "delay:delta_e": "s", "bias:airspeed": "m/s"}[e.name]
            injected.append({"effect": e.name, "cause": e.name, "value": e.value, "unit": unit})
    doc = {"aircraft": spec.name, "config": asdict(config), "injected": injected,
           "note": "change made to each term (aero terms: relative to the stock model)",
           "harness": harness_fingerprint(spec.name)}
    (out / f"{stem}-effects.json").write_text(json.dumps(doc, indent=1))
    return FlightFiles(tlog, truth, spec.airframe_path, rec)
