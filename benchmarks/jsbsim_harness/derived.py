"""Derived JSBSim models: a stock model of the installed ``jsbsim`` wheel with its flight-control
system replaced by a direct mapping from the harness's commands to the surfaces (``f16_direct``), or
given the empty ``<flight_control>`` element the harness's injected elevator delay needs
(``F4N_fcs``, :func:`derive_f4n_fcs`; twelfth session), or a model from outside the wheel, checked into
this repository, with its engine removed (``Rascal110_glide``, :func:`derive_rascal_glide`: ArduPilot's
SITL Rascal 110; thirteenth session, :data:`REPO_DERIVED`), or FlightGear's ASW 20 sailplane with the
parts that need FlightGear removed and its elevator table reading an alias (``asw20_glide``,
:func:`derive_asw20_glide`; fifteenth session), or FlightGear's JSBSim IAR-80 fighter with its engine and
propeller removed (``IAR80_glide``, :func:`derive_iar80_glide`; sixteenth session), or FlightGear's JSBSim
Caudron C.684 racer with its engine, propeller and engine system removed (``C684_glide``,
:func:`derive_c684_glide`; seventeenth session), or the University of Minnesota UAS Lab's JSBSim Ultra Stick 120
UAV assembled from its files into one, gliding, with direct surfaces (``UltraStick120_glide``,
:func:`derive_ultrastick120_glide`; eighteenth session), or ENAC's Eternity UAV from Paparazzi with its motor and
propeller removed and its elevator moment reading an alias (``Eternity_glide``, :func:`derive_eternity_glide`;
twenty-first session), or the same lab's Ultra Stick 25e with its OpenFlight aerodynamics, assembled and
flown as the Ultra Stick 120 (``UltraStick25e_glide``, :func:`derive_ultrastick25e_glide`; twenty-second session),
or a JSBSim Beechcraft King Air 350 twin turboprop gliding, its engines, systems, autopilot inputs, rudder boost
and yaw damper removed (``KingAir350_glide``, :func:`derive_kingair350_glide`; twenty-third session), or JSBSim's
Short S.23 flying boat gliding in one file, its engines, hull forces and systems removed (``ShortS23_glide``,
:func:`derive_shorts23_glide`; twenty-fourth session), or JSBSim's Fokker Dr.I triplane gliding, its rotary engine,
propeller and pushback removed and its pitch table reading the elevator through an alias (``Dr1_glide``,
:func:`derive_dr1_glide`; twenty-fifth session), or JSBSim's Ryan Navion (the wheel's ``L17``) gliding, its engine
and propeller removed and its flap normaliser reading the flap kinematic's output (``Navion_glide``,
:func:`derive_navion_glide`; twenty-sixth session), or JSBSim's Fokker 50 gliding, its engines and propellers, the
channels and propwash terms that read them, and its yaw damper removed (``Fokker50_glide``,
:func:`derive_fokker50_glide`; twenty-seventh session).

The harness flies stock models whose surfaces follow the normalised commands
(``fcs/{elevator,aileron,rudder}-cmd-norm``). JSBSim's F-16 (``f16.xml``, Erik Hofman 2001) puts a
fly-by-wire system between them: a roll-rate PID law, a g-command PID law with an alpha limiter,
a yaw PID on yaw rate and lateral load, leading-edge flaps switched on alpha, trailing-edge flaps
on airspeed and flaperons. This module writes a variant, ``f16_direct``, whose aerodynamics,
metrics, mass and inertia, ground reactions, propulsion and systems are the wheel's, with:

* ``<flight_control>`` replaced: ``fcs/elevator-pos-rad`` = 0.436 x ``fcs/elevator-cmd-norm``,
  ``fcs/aileron-pos-rad`` = 0.375 x ``fcs/aileron-cmd-norm`` (the property the aerodynamics read;
  ``fcs/left-aileron-pos-rad`` and ``fcs/right-aileron-pos-rad`` are written as +- that, for
  display), ``fcs/rudder-pos-rad`` = 0.524 x ``fcs/rudder-cmd-norm`` (the stock surface ranges,
  ``aerosurface_scale``, no actuator dynamics: the harness's servos are the actuators);
  ``fcs/lef-pos-rad``, ``fcs/flaperon-mix-rad`` (the stock model drives it from the ailerons, so
  its CLDflaps / CDDflaps terms made lift and drag follow the aileron) fixed at 0 (the speed
  brake, no longer commanded by an FCS channel, stays at JSBSim's 0), because the harness's log carries no flap channel;
  the stock ``Landing Gear`` and ``Throttle`` channels kept as they are (they drive no surface).
* one identity function added to ``<aerodynamics>``: ``aero/function/elevator-pos-rad`` =
  ``fcs/elevator-pos-rad``, and the tables that looked the elevator up as an ``independentVar``
  (CDdHT, CLDh, CmDh) look it up there. The numbers are unchanged (a test checks JSBSim's
  forces and moments against the stock tables read with the elevator directly); the alias gives
  the aerodynamics one ``<property>`` read of the elevator, which ``effects.py``'s
  ``delay:delta_e`` redirects.

The derived folder is generated from the installed wheel (LGPL-2.1; nothing of JSBSim is copied
into this repository; the one exception is ArduPilot's Rascal 110, a model from outside the wheel, whose
XML is checked in under ``data/jsbsim_models/rascal/`` with its GPL-3.0 provenance) into the wheel's own
``aircraft/`` folder, beside the stock models, because
the harness's loader (``flight.load_model``) loads models from there by name and must not change
(its code is part of every aircraft's harness fingerprint, ``logfile.harness_fingerprint``).
:func:`install_derived_models` runs when ``benchmarks.jsbsim_harness`` is imported; it rewrites the
folder only when its XML differs from the derivation. The derived XML's SHA-256 (first 16 hex
digits) is written in the aircraft's ``AircraftSpec.notes``, so it is part of that aircraft's
fingerprint; a test checks that it matches.

References:
    JSBSim Reference Manual, "Flight control and systems" (aerosurface_scale, switch) and
    "Aerodynamics" (functions evaluated before the axes). Nguyen et al., NASA TP-1538 (1979),
    the F-16 wind-tunnel data the model's tables come from.
"""

from __future__ import annotations

import copy
import hashlib
import os
import shutil
import tempfile
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import NamedTuple

__all__ = ["DERIVED", "REPO_DERIVED", "derive_f16_direct", "derive_f4n_fcs", "derive_rascal_glide",
           "derive_asw20_glide", "derive_iar80_glide", "derive_c684_glide", "derive_ultrastick120_glide",
           "derive_eternity_glide", "derive_ultrastick25e_glide", "derive_kingair350_glide", "derive_shorts23_glide",
           "derive_dr1_glide", "derive_navion_glide", "derive_fokker50_glide",
           "US120_SURFACE_RAD", "derived_xml", "derived_sha",
           "install_derived_models", "ELEVATOR_ALIAS",
           "ELEVATOR_DEG_ALIAS"]

#: The elevator alias the derived F-16's tables read (see the module docstring).
ELEVATOR_ALIAS = "aero/function/elevator-pos-rad"

#: The elevator alias, in degrees, the derived ASW 20's pitch table reads (:func:`derive_asw20_glide`).
ELEVATOR_DEG_ALIAS = "aero/function/elevator-pos-deg"

#: JSBSim's radians-to-degrees factor (``FGJSBBase::radtodeg``), with which it writes ``fcs/elevator-pos-deg``.
_RADTODEG = 57.295779513082320876798154814105


def _wheel_root() -> Path:
    import jsbsim

    return Path(jsbsim.get_default_root_dir())


def _el(parent: ET.Element, tag: str, text: str | None = None, **attrib) -> ET.Element:
    e = ET.SubElement(parent, tag, attrib)
    if text is not None:
        e.text = text
    return e


class _Parts(NamedTuple):
    """The elements of a JSBSim model that the glide derivations remove or edit (:func:`_parts`)."""

    prop: ET.Element | None
    engines: list[ET.Element]
    systems: list[ET.Element]
    external: list[ET.Element]
    fc: ET.Element | None
    aero: ET.Element | None


def _parts(root: ET.Element) -> _Parts:
    """``root``'s ``<propulsion>`` and its ``<engine>`` children (none where it has no propulsion), its ``<system>``
    and ``<external_reactions>`` children, its ``<flight_control>`` and its ``<aerodynamics>`` (None where missing):
    what each derivation checks before it edits the copy (twenty-eighth session: one lookup for nine copies)."""
    prop = root.find("propulsion")
    return _Parts(prop, prop.findall("engine") if prop is not None else [], root.findall("system"),
                  root.findall("external_reactions"), root.find("flight_control"), root.find("aerodynamics"))


def _scale(channel: ET.Element, name: str, cmd: str, half_range: float, out: str) -> None:
    c = _el(channel, "aerosurface_scale", name=name)
    _el(c, "input", cmd)
    r = _el(c, "range")
    _el(r, "min", repr(-half_range))
    _el(r, "max", repr(half_range))
    _el(c, "output", out)


def derive_f16_direct(root: ET.Element) -> ET.Element:
    """The F-16's XML ``root`` with its FCS replaced by the direct mapping (module docstring).

    Args:
        root: the parsed stock ``f16.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the stock XML lacks the elements the derivation expects (another jsbsim
            version): the ``flight_control``, its ``Landing Gear`` or ``Throttle`` channel, the
            aerodynamics, or a table reading ``fcs/elevator-pos-rad``.
    """
    root = copy.deepcopy(root)
    fc = root.find("flight_control")
    if fc is None:
        raise ValueError("f16.xml: no <flight_control>")
    keep = {ch.get("name"): ch for ch in fc.findall("channel") if ch.get("name") in ("Landing Gear", "Throttle")}
    if set(keep) != {"Landing Gear", "Throttle"}:
        raise ValueError("f16.xml: the <flight_control> lacks its 'Landing Gear' or 'Throttle' channel")
    new = ET.Element("flight_control",
                     name="F-16 direct surfaces (gcs-sysid harness, benchmarks/jsbsim_harness/derived.py)")
    pitch = _el(new, "channel", name="Pitch")
    _scale(pitch, "fcs/elevator-control", "fcs/elevator-cmd-norm", 0.436, "fcs/elevator-pos-rad")
    roll = _el(new, "channel", name="Roll")
    _scale(roll, "fcs/aileron-control", "fcs/aileron-cmd-norm", 0.375, "fcs/aileron-pos-rad")
    _scale(roll, "fcs/left-aileron-control", "fcs/aileron-cmd-norm", 0.375, "fcs/left-aileron-pos-rad")
    _scale(roll, "fcs/right-aileron-control", "-fcs/aileron-cmd-norm", 0.375, "fcs/right-aileron-pos-rad")
    yaw = _el(new, "channel", name="Yaw")
    _scale(yaw, "fcs/rudder-control", "fcs/rudder-cmd-norm", 0.524, "fcs/rudder-pos-rad")
    fixed = _el(new, "channel", name="Fixed flaps")
    for name in ("fcs/lef-pos-rad", "fcs/flaperon-mix-rad"):
        _el(_el(fixed, "switch", name=name), "default", value="0.0")
    new.append(keep["Landing Gear"])
    new.append(keep["Throttle"])
    index = list(root).index(fc)
    root.remove(fc)
    root.insert(index, new)

    aero = root.find("aerodynamics")
    if aero is None:
        raise ValueError("f16.xml: no <aerodynamics>")
    if _alias_elevator_lookups(aero) == 0:
        raise ValueError("f16.xml: no aerodynamic table looks up fcs/elevator-pos-rad")
    return root


def _alias_elevator_lookups(aero: ET.Element) -> int:
    """Point every table lookup (``independentVar``) of ``fcs/elevator-pos-rad`` in ``aero`` (an
    ``<aerodynamics>`` element, modified in place) at :data:`ELEVATOR_ALIAS`, and insert that identity function
    (``fcs/elevator-pos-rad``) as ``aero``'s first child; the numbers are unchanged (:func:`derive_f16_direct`,
    :func:`derive_shorts23_glide`). Returns the number of lookups rewritten (the alias is inserted even for 0)."""
    n = 0
    for iv in aero.iter("independentVar"):
        if iv.text and iv.text.strip() == "fcs/elevator-pos-rad":
            iv.text = ELEVATOR_ALIAS
            n += 1
    alias = ET.Element("function", name=ELEVATOR_ALIAS)
    _el(alias, "description", "elevator position the tables read (identity; added by the harness's derivation)")
    _el(alias, "property", "fcs/elevator-pos-rad")
    aero.insert(0, alias)
    return n


def derive_f4n_fcs(root: ET.Element) -> ET.Element:
    """The F-4N's XML ``root`` with an empty ``<flight_control>`` element added (twelfth session).

    The stock ``F4N.xml`` flies its surfaces through ``<system>`` files (``FCS-pitch``, ``FCS-roll``,
    ``FCS-yaw``: the commands straight to the surfaces plus a yaw damper) and has its
    ``<flight_control name="FCS">`` commented out, so ``effects.py``'s ``delay:delta_e``, which adds
    its delay channel to the model's ``<flight_control>``, had nowhere to go. The derivation adds that
    element, empty, where the stock comment stands (after the last ``<system>``, before
    ``<aerodynamics>``); nothing else changes. JSBSim runs the ``<system>`` channels before the
    ``<flight_control>`` ones (it loads them first), so an injected delay reads the elevator the
    systems wrote in the same frame, as on the other aircraft. An empty ``<flight_control>`` computes
    nothing: a test checks every force and moment against the stock model's to 1e-12.

    Args:
        root: the parsed stock ``F4N.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the stock XML already has a ``<flight_control>`` or lacks ``<aerodynamics>``
            (another jsbsim version).
    """
    root = copy.deepcopy(root)
    if root.find("flight_control") is not None:
        raise ValueError("F4N.xml: already has a <flight_control>")
    aero = root.find("aerodynamics")
    if aero is None:
        raise ValueError("F4N.xml: no <aerodynamics>")
    fc = ET.Element("flight_control", name="FCS (empty; added by gcs-sysid's benchmarks/jsbsim_harness/derived.py)")
    root.insert(list(root).index(aero), fc)
    return root


def derive_rascal_glide(root: ET.Element) -> ET.Element:
    """The Rascal 110's XML ``root`` with its engine and propeller removed (thirteenth session).

    ArduPilot's SITL Rascal 110 (``data/jsbsim_models/rascal/Rascal110-JSBSim.xml``) drives an 18x8
    propeller with a Zenoah G-26A piston engine, whose files are not in the jsbsim wheel. The harness
    glides every aircraft with its engines stopped, so that every non-gravity force is aerodynamic;
    a stopped engine would still leave JSBSim's windmilling propeller (the rule that rejected the
    p51d, B17 and C130). The derivation removes the ``<engine>`` element (engine and thruster): the
    glide of a UAV with its propeller folded or stopped and no propeller force. Its fuel tank (1.5 lb
    on the centre line) stays as mass; the aerodynamics, metrics, mass balance, ground reactions and
    flight control are unchanged (a test checks every other element).

    Args:
        root: the parsed ``Rascal110-JSBSim.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML has no ``<propulsion>`` with an ``<engine>`` or no ``<aerodynamics>``.
    """
    root = copy.deepcopy(root)
    prop, engines, *_ = _parts(root)
    if not engines or root.find("aerodynamics") is None:
        raise ValueError("Rascal110-JSBSim.xml: no <propulsion><engine> to remove or no <aerodynamics>")
    for e in engines:
        prop.remove(e)
    return root


def _insert_elevator_deg_alias(aero: ET.Element, reader: str) -> None:
    """Insert, as the first child of ``aero`` (an ``<aerodynamics>`` element, modified in place), the function
    :data:`ELEVATOR_DEG_ALIAS` = :data:`_RADTODEG` x ``fcs/elevator-pos-rad`` (JSBSim's own conversion, so the
    numbers are unchanged), described as what ``reader`` (the model's term that reads it) looks up. The derivations
    of the asw20 and the eternity point their one read of ``fcs/elevator-pos-deg`` at it."""
    alias = ET.Element("function", name=ELEVATOR_DEG_ALIAS)
    _el(alias, "description", f"elevator position, deg, {reader} reads (added by the harness's derivation)")
    prod = _el(alias, "product")
    _el(prod, "value", repr(_RADTODEG))
    _el(prod, "property", "fcs/elevator-pos-rad")
    aero.insert(0, alias)


def derive_asw20_glide(root: ET.Element) -> ET.Element:
    """FlightGear's ASW 20 sailplane (``data/jsbsim_models/asw20/asw20-JSBSim.xml``) as JSBSim alone can
    fly it, with one ``<property>`` read of the elevator in its aerodynamics (fifteenth session).

    The file is D-NXKT's January 2013 conversion of Michael Selig's UIUC ASW 20 to JSBSim, written for
    FlightGear. Three edits; nothing else changes:

    - **Systems removed.** The two ``<system file=...>`` elements (``GenericEngine``: FlightGear's
      generic motor, a thrust written into the ``GenericEngine`` external force; ``WaterBallast``:
      dumping) name files that are not copied. Without them the external forces (winch, aerotow,
      engine) keep JSBSim's magnitude 0, so every non-gravity force is aerodynamic.
    - **One FlightGear channel removed.** The ``Water Dumping`` channel of ``<flight_control>`` tests
      FlightGear's ``/sim/asw20/waterballast/valve``, which JSBSim alone does not have (``run_ic``
      raises, as for the L17 and dr1). It writes only ``/sim/asw20/waterballast/dumping``, which nothing
      reads.
    - **Elevator alias.** The ``CmDe`` table (the tail's whole pitching moment: a 3-D table in alpha
      with elevator breakpoints -20, 0, +20 deg) looks the elevator up as ``fcs/elevator-pos-deg``. A
      function ``aero/function/elevator-pos-deg`` = 57.2957795... x ``fcs/elevator-pos-rad`` (JSBSim's
      own conversion) is added to ``<aerodynamics>`` and the table looks it up there, so that
      ``effects.py``'s ``delay:delta_e`` reaches the tail as it does the elevator's lift (``CLDe``).
      The numbers are unchanged (a test checks JSBSim's moments against the file as copied).

    Args:
        root: the parsed ``asw20-JSBSim.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): the
            two systems, the ``Water Dumping`` channel, ``<aerodynamics>`` or one table reading
            ``fcs/elevator-pos-deg``.
    """
    root = copy.deepcopy(root)
    systems = root.findall("system")
    if sorted(s.get("file") for s in systems) != ["GenericEngine", "WaterBallast"]:
        raise ValueError("asw20-JSBSim.xml: expected the systems GenericEngine and WaterBallast")
    for s in systems:
        root.remove(s)
    fc = root.find("flight_control")
    dump = [ch for ch in fc.findall("channel") if ch.get("name") == "Water Dumping"] if fc is not None else []
    if len(dump) != 1:
        raise ValueError("asw20-JSBSim.xml: no <flight_control> channel 'Water Dumping'")
    fc.remove(dump[0])
    aero = root.find("aerodynamics")
    if aero is None:
        raise ValueError("asw20-JSBSim.xml: no <aerodynamics>")
    reads = [iv for iv in aero.iter("independentVar") if iv.text and iv.text.strip() == "fcs/elevator-pos-deg"]
    if len(reads) != 1:
        raise ValueError("asw20-JSBSim.xml: expected one table looking up fcs/elevator-pos-deg")
    reads[0].text = ELEVATOR_DEG_ALIAS
    _insert_elevator_deg_alias(aero, "the CmDe table")
    return root


def derive_iar80_glide(root: ET.Element) -> ET.Element:
    """FlightGear's JSBSim IAR-80 (``data/jsbsim_models/iar80/IAR80-Jsb.xml``) with its engine and propeller
    removed (sixteenth session).

    The file (FGMEMBERS/IAR-80-JSB, Aeromatic v0.95, 2015) drives a propeller (``Prop``) with a 14-cylinder
    radial (``IAR-K14-1000A``); neither file is copied (the repository holds the engine only as an editor's
    backup, ``Engines/IAR-K14-1000A~``, so JSBSim could not load it anyway). The harness glides every aircraft
    with its engines stopped, so that every non-gravity force is aerodynamic, and a stopped engine would leave
    JSBSim's windmilling propeller (the rule that rejected the p51d, B17 and C130). As for the rascal, the
    ``<engine>`` element (engine, its two ``<feed>`` and the thruster) is removed; the two fuel tanks (399 and
    462.6 lb, both at the CG) stay as mass. Everything else (metrics, mass balance, ground reactions, flight
    control, aerodynamics, external reactions) is the file's (a test checks every other element).

    Args:
        root: the parsed ``IAR80-Jsb.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML has no ``<propulsion>`` with exactly one ``<engine>`` or no ``<aerodynamics>``
            (another version of the file).
    """
    root = copy.deepcopy(root)
    prop, engines, *_ = _parts(root)
    if len(engines) != 1 or root.find("aerodynamics") is None:
        raise ValueError("IAR80-Jsb.xml: expected one <propulsion><engine> to remove and an <aerodynamics>")
    prop.remove(engines[0])
    return root


def derive_c684_glide(root: ET.Element) -> ET.Element:
    """FlightGear's JSBSim Caudron C.684 (``data/jsbsim_models/c684/C684.xml``) with its engine, propeller and
    engine system removed, as JSBSim 1.3.3 can load it (seventeenth session).

    The file (FGMEMBERS/C684, Guillaume Chauvat 2008, version 0.4.13) drives a variable-pitch propeller
    (``ratier_variable``) with a six-cylinder engine (``6Pfi``) and names one system file (``engine``: the
    pitch selector and starter logic of FlightGear's cockpit). Three edits; nothing else changes (a test
    checks every other element):

    - **Engine removed.** The ``<engine>`` element (engine, its two ``<feed>`` and the thruster) is removed,
      as the rascal's and iar80's: the harness glides every aircraft with its engines stopped, so that every
      non-gravity force is aerodynamic, and a stopped engine would leave JSBSim's windmilling propeller. The
      two fuel tanks (80 kg each, 0.2 m either side of the centre line) stay as mass.
    - **Engine system removed.** ``<system file="engine"/>`` names a file that is not copied (it drives the
      removed engine's propeller pitch and starter).
    - **Gear flag.** The three wheels say ``<retractable>FIXED</retractable>``, the 2008 syntax; JSBSim 1.3.3
      expects a number and refuses to load the file ("Expecting a numeric attribute value, but got: FIXED").
      They are written ``0`` (not retractable), which is what FIXED meant. The gear touches nothing in
      flight (no aerodynamic function reads it).

    Args:
        root: the parsed ``C684.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): one
            ``<propulsion><engine>``, the one system ``engine``, three ``retractable`` flags reading FIXED,
            or ``<aerodynamics>``.
    """
    root = copy.deepcopy(root)
    prop, engines, systems, *_ = _parts(root)
    flags = list(root.iter("retractable"))
    if (len(engines) != 1 or [s.get("file") for s in systems] != ["engine"] or root.find("aerodynamics") is None
            or len(flags) != 3 or any((f.text or "").strip() != "FIXED" for f in flags)):
        raise ValueError("C684.xml: expected one <propulsion><engine>, the system 'engine', three <retractable>"
                         "FIXED</retractable> and an <aerodynamics>")
    prop.remove(engines[0])
    root.remove(systems[0])
    for f in flags:
        f.text = "0"
    return root


#: The checked-in UltraStick 120 files :func:`derive_ultrastick120_glide` assembles (beside the main file).
_US120_DIR = Path(__file__).resolve().parents[2] / "data" / "jsbsim_models" / "ultrastick120"

#: The main file's sections (tag, file) in the stored version (UASLab/OpenFlightSim at 1650a6e3).
_US120_SECTIONS = [("flight_control", "Systems/FlightControl.xml"), ("system", "Systems/Effectors.xml"),
                   ("mass_balance", "Mass.xml"), ("ground_reactions", "Gear.xml"), ("propulsion", "Propulsion.xml"),
                   ("metrics", "Metrics.xml"), ("aerodynamics", "Aero.xml"), ("system", "Systems/SensorImu.xml"),
                   ("system", "Systems/SensorGps.xml"), ("system", "Systems/SensorPitot.xml"),
                   ("system", "Systems/Sensor5Hole.xml")]

#: Surface travel of the UltraStick 120's actuators (``Systems/Effectors.xml``: every actuator clips at
#: +-0.5235987755982988 rad, 30 deg).
US120_SURFACE_RAD = 0.5235987755982988


def derive_ultrastick120_glide(root: ET.Element) -> ET.Element:
    """The University of Minnesota UAS Lab's JSBSim Ultra Stick 120 (``data/jsbsim_models/ultrastick120/``,
    UASLab/OpenFlightSim ``Simulation/aircraft/UltraStick120`` at 1650a6e3, MIT) as one file, gliding, with
    a direct flight-control system (eighteenth session).

    The model is split over files the main ``UltraStick120.xml`` names (``<metrics file="Metrics.xml"/>``
    and so on). The derivation reads the checked-in ``Metrics.xml``, ``Mass.xml``, ``Gear.xml`` and
    ``Aero.xml`` (unchanged) into one ``<fdm_config>``, and:

    - **No propulsion.** ``Propulsion.xml`` (an electric motor and an APC 16x8 propeller) is not copied: an
      empty ``<propulsion/>``, so that every non-gravity force is aerodynamic (the harness glides every aircraft).
    - **A direct flight-control system** replaces ``Systems/FlightControl.xml`` (the lab's control laws and
      excitation) and ``Systems/Effectors.xml`` (six actuators: first-order lag 57 rad/s, 0.02-s delay,
      2-deg hysteresis, +-30 deg): ``aerosurface_scale`` of the harness's normalised commands, +-30 deg
      (:data:`US120_SURFACE_RAD`), as the other derived models (the harness's servos are the actuators).
      Elevator -> ``fcs/elevator-pos-rad``, rudder -> ``fcs/rudder-pos-rad``, aileron -> ``fcs/posAilL_rad``
      and its mirror ``fcs/posAilR_rad`` (the lab's names; each has its own tables); the two flaps
      (``fcs/posFlapL_rad``, ``fcs/posFlapR_rad``) are declared 0 (the harness's log has no flap channel).
    - **Surface names.** The aerodynamics' reads of ``fcs/posElev_rad`` and ``fcs/posRud_rad`` are written
      ``fcs/elevator-pos-rad`` and ``fcs/rudder-pos-rad`` (the properties the harness logs and ``effects.py``'s
      ``delay:delta_e`` redirects); no number changes.
    - **Sensors** (``Systems/Sensor*.xml``: the lab's IMU, GPS, pitot and five-hole-probe models) are not
      copied: the harness has its own sensors.

    Args:
        root: the parsed ``UltraStick120.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the main file does not name the expected sections (another version), or a checked-in
            section file has another root element.
    """
    return _openflightsim_glide(root, "UltraStick120", _US120_SECTIONS, _US120_DIR, "UltraStick120_glide",
                                "Ultra Stick 120 UAV, gliding, direct surfaces (gcs-sysid derivation)")


def _openflightsim_glide(root: ET.Element, main: str, sections: list, folder: Path, name: str,
                         description: str) -> ET.Element:
    """Assemble one of UASLab/OpenFlightSim's split JSBSim models into one gliding file with direct surfaces
    (:func:`derive_ultrastick120_glide`, :func:`derive_ultrastick25e_glide`).

    Args:
        root: the parsed main file (``<main>.xml``, not modified).
        main: the main file's stem, for the error messages.
        sections: the main file's ``(tag, file)`` children expected, in order.
        folder: the checked-in folder holding the section files.
        name: the derived model's ``fdm_config`` name.
        description: its ``fileheader`` description.

    Returns:
        a new root element: metrics, mass, gear and aerodynamics as checked in, an empty ``<propulsion/>``,
        and a ``<flight_control>`` of ``aerosurface_scale`` components (+-:data:`US120_SURFACE_RAD`, the lab's
        actuator travel) from the harness's normalised commands; flaps 0; ``fcs/posElev_rad`` and
        ``fcs/posRud_rad`` read as ``fcs/elevator-pos-rad`` and ``fcs/rudder-pos-rad``.

    Raises:
        ValueError: the main file does not name ``sections`` (another version), or a checked-in section file
            has another root element.
    """
    got = [(c.tag, c.get("file")) for c in root]
    if got != sections:
        raise ValueError(f"{main}.xml: expected the sections {sections}, got {got}")
    new = ET.Element("fdm_config", {"name": name, "version": "2.0", "release": "ALPHA"})
    head = ET.SubElement(new, "fileheader")
    ET.SubElement(head, "author").text = "University of Minnesota UAS Laboratories (OpenFlightSim, MIT)"
    ET.SubElement(head, "description").text = description
    parts = {}
    for tag in ("metrics", "mass_balance", "ground_reactions", "aerodynamics"):
        f = dict((t, f) for t, f in sections if t == tag)[tag]
        part = ET.parse(folder / f).getroot()
        if part.tag != tag:
            raise ValueError(f"{f}: root <{part.tag}>, expected <{tag}>")
        parts[tag] = part
    new.append(parts["metrics"])
    new.append(parts["mass_balance"])
    new.append(parts["ground_reactions"])
    ET.SubElement(new, "propulsion")
    fcs = ET.SubElement(new, "flight_control", {"name": f"{name} direct surfaces"})
    for flap in ("fcs/posFlapL_rad", "fcs/posFlapR_rad"):
        ET.SubElement(fcs, "property", {"value": "0"}).text = flap
    for channel, cmd, outs in (("Pitch", "fcs/elevator-cmd-norm", [("Elevator", "", "fcs/elevator-pos-rad")]),
                               ("Roll", "fcs/aileron-cmd-norm", [("Left Aileron", "", "fcs/posAilL_rad"),
                                                                 ("Right Aileron", "-", "fcs/posAilR_rad")]),
                               ("Yaw", "fcs/rudder-cmd-norm", [("Rudder", "", "fcs/rudder-pos-rad")])):
        ch = ET.SubElement(fcs, "channel", {"name": channel})
        for surface, sign, out in outs:
            comp = ET.SubElement(ch, "aerosurface_scale", {"name": f"{surface} Control"})
            ET.SubElement(comp, "input").text = sign + cmd
            rng = ET.SubElement(comp, "range")
            ET.SubElement(rng, "min").text = repr(-US120_SURFACE_RAD)
            ET.SubElement(rng, "max").text = repr(US120_SURFACE_RAD)
            ET.SubElement(comp, "output").text = out
    aero = parts["aerodynamics"]
    rename = {"fcs/posElev_rad": "fcs/elevator-pos-rad", "fcs/posRud_rad": "fcs/rudder-pos-rad"}
    for el in aero.iter("property"):
        t = (el.text or "").strip()
        if t in rename:
            el.text = rename[t]
    new.append(aero)
    return new


#: The checked-in UltraStick 25e files :func:`derive_ultrastick25e_glide` assembles (beside the main file).
_US25E_DIR = Path(__file__).resolve().parents[2] / "data" / "jsbsim_models" / "ultrastick25e"

#: The main file's sections (tag, file) in the stored version (UASLab/OpenFlightSim
#: ``Simulation/aircraft/UltraStick25e/UltraStick25e.xml`` at 06a2b255).
_US25E_SECTIONS = [("flight_control", "Systems\\FlightControl.xml"), ("system", "Systems\\Effectors.xml"),
                   ("mass_balance", "MassOpenFlight.xml"), ("ground_reactions", "Gear.xml"),
                   ("propulsion", "PropulsionDirect.xml"), ("metrics", "MetricsOpenFlight.xml"),
                   ("aerodynamics", "AeroOpenFlight.xml"), ("system", "Systems\\SensorImu.xml"),
                   ("system", "Systems\\SensorGps.xml"), ("system", "Systems\\SensorPitot.xml")]


def derive_ultrastick25e_glide(root: ET.Element) -> ET.Element:
    """The University of Minnesota UAS Lab's JSBSim Ultra Stick 25e with its OpenFlight aerodynamics
    (``data/jsbsim_models/ultrastick25e/``, UASLab/OpenFlightSim ``Simulation/aircraft/UltraStick25e``, MIT) as one
    file, gliding, with a direct flight-control system (twenty-second session).

    The main ``UltraStick25e.xml`` names ``MassOpenFlight.xml``, ``Gear.xml``, ``MetricsOpenFlight.xml`` and
    ``AeroOpenFlight.xml`` (the lab's earlier OpenFlight linear model of the 1.96-kg, 1.27-m Ultra Stick 25e: one
    constant per derivative on all six axes). Assembled as :func:`derive_ultrastick120_glide` does
    (:func:`_openflightsim_glide`): the four files unchanged, no propulsion (``PropulsionDirect.xml`` not copied),
    the lab's control laws (``Systems/FlightControl.xml``), actuators (``Systems/Effectors.xml``: lag 33 rad/s,
    0.02-s delay, 1-deg hysteresis, +-30 deg) and sensors replaced by direct surfaces of +-30 deg, flaps 0,
    ``fcs/posElev_rad`` and ``fcs/posRud_rad`` read as ``fcs/elevator-pos-rad`` and ``fcs/rudder-pos-rad``. No
    number changes.

    Args:
        root: the parsed ``UltraStick25e.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the main file does not name the expected sections (another version), or a checked-in
            section file has another root element.
    """
    return _openflightsim_glide(root, "UltraStick25e", _US25E_SECTIONS, _US25E_DIR, "UltraStick25e_glide",
                                "Ultra Stick 25e UAV (OpenFlight aerodynamics), gliding, direct surfaces "
                                "(gcs-sysid derivation)")


def derive_eternity_glide(root: ET.Element) -> ET.Element:
    """ENAC's Eternity UAV from Paparazzi (``data/jsbsim_models/eternity/Eternity.xml``: paparazzi/paparazzi
    ``conf/simulator/jsbsim/aircraft/Eternity.xml`` at 5399bd98, Murat Bronz 2015, GPL-2.0-or-later) with its motor
    and propeller removed and its elevator moment reading an alias (twenty-first session).

    Three edits; nothing else changes (a test checks every other element):

    - **Motor removed.** The ``<engine>`` element (the ``HB2815-2000`` motor, its ``<feed>`` and the ``apc6x4``
      propeller; neither file is copied) is removed, as the rascal's, iar80's and c684's: the harness glides every
      aircraft, so that every non-gravity force is aerodynamic. The empty fuel tank (0 lb) stays.
    - **Throttle channel removed.** The ``Throttle`` channel of ``<flight_control>`` reads
      ``fcs/throttle-cmd-norm``, which JSBSim creates per engine: without the engine ``run_ic`` raises. It writes
      only ``fcs/throttle-pos-norm``, which only the removed engine read.
    - **Elevator alias.** ``Pitch_elevator`` (the elevator's whole pitching moment, -0.0119 per deg) reads
      ``fcs/elevator-pos-deg``. A function :data:`ELEVATOR_DEG_ALIAS` = 57.2957795... x ``fcs/elevator-pos-rad``
      (JSBSim's own conversion) is added to ``<aerodynamics>`` and the moment reads it there, so that
      ``effects.py``'s ``delay:delta_e`` reaches the moment as it does the elevator's lift (``Lift_elevator``), as
      for the asw20 (:func:`derive_asw20_glide`). The numbers are unchanged. ``Drag_elevator`` reads the
      normalised command ``fcs/elevator-pos-norm`` (0.03 x its magnitude) and is left as it is (the injected
      delay does not reach it: a drag term of at most 0.03).

    Args:
        root: the parsed ``Eternity.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): one
            ``<propulsion><engine>``, the ``Throttle`` channel, ``<aerodynamics>`` or one ``<property>`` read of
            ``fcs/elevator-pos-deg``.
    """
    root = copy.deepcopy(root)
    prop, engines, _, _, fc, aero = _parts(root)
    throttle = [ch for ch in fc.findall("channel") if ch.get("name") == "Throttle"] if fc is not None else []
    reads = [p for p in aero.iter("property") if (p.text or "").strip() == "fcs/elevator-pos-deg"] \
        if aero is not None else []
    if len(engines) != 1 or len(throttle) != 1 or len(reads) != 1:
        raise ValueError("Eternity.xml: expected one <propulsion><engine>, the Throttle channel, an <aerodynamics> "
                         "and one <property> read of fcs/elevator-pos-deg")
    prop.remove(engines[0])
    fc.remove(throttle[0])
    reads[0].text = ELEVATOR_DEG_ALIAS
    _insert_elevator_deg_alias(aero, "Pitch_elevator")
    return root


#: The King Air 350's ``<system>`` files, none of them copied (:func:`derive_kingair350_glide`).
_KA350_SYSTEMS = ["engine-control", "fuel-system", "nws", "autopilot"]

#: The King Air 350's rudder-boost components, which read the removed engines' propeller torque.
_KA350_BOOST = ["fcs/torque-diff", "fcs/rudder-boost-raw", "fcs/rudder-boost-cmd", "fcs/rudder-boost-lag"]


def derive_kingair350_glide(root: ET.Element) -> ET.Element:
    """A JSBSim Beechcraft King Air 350 (``data/jsbsim_models/kingair350/KingAir-350.xml``:
    itaalh/FlightGear-Beechcraft-350ER ``Aero/KingAir-350.xml`` at 0298d965, GPL-2.0-or-later) gliding, as
    JSBSim alone can fly it (twenty-third session).

    The file is the flight model of a FlightGear package rebuilt in 2026 (engines, propellers, systems and an
    autopilot that runs in JSBSim). Six edits; nothing else changes (a test checks every other element):

    - **Engines removed.** The two ``<engine>`` elements (``PT6A-60A`` turboprops, their feeds and the
      ``Hartzell-4B-105`` propellers; neither file is copied) are removed, as the rascal's, iar80's, c684's and
      eternity's: the harness glides every aircraft, so that every non-gravity force is aerodynamic. The four fuel
      tanks (2888 lb in two symmetric pairs) stay as mass.
    - **Systems removed.** The four ``<system file=...>`` elements (:data:`_KA350_SYSTEMS`: engine control,
      fuel, nose-wheel steering, autopilot) name files that are not copied.
    - **Autopilot inputs removed.** The pitch and roll summers add ``ap/elevator-cmd`` and ``ap/aileron-cmd``,
      which only the removed autopilot system writes (without it ``run_ic`` raises).
    - **Rudder boost removed.** Its four components (:data:`_KA350_BOOST`: a rudder command proportional to the
      two propellers' torque difference, lagged) read ``propulsion/engine[n]/propeller-torque-ftlb``, gone with
      the engines; the rudder summer's input ``fcs/rudder-boost-lag`` goes with them.
    - **Yaw damper off.** ``/controls/flight/yaw-damper`` is set to 0 (the file sets 1): its washed-out yaw-rate
      feedback (2.2 x r, clipped at +-0.35 of the command) would move the rudder with the yaw rate in every flight.
      The channel stays; its switch then passes 0. The harness's own autopilot damps yaw (``gains``' k_r).
    - **Feathered-propeller drag removed.** ``Drag_feathered`` (0.003 per feathered propeller) reads the removed
      engine-control system's ``fcs/feather-pos-norm[n]``; without propellers there is nothing to feather.

    Args:
        root: the parsed ``KingAir-350.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): two
            ``<propulsion><engine>``, the four systems, the two autopilot inputs, the four boost components and
            the boost input, the yaw-damper property, or one ``Drag_feathered`` function.
    """
    root = copy.deepcopy(root)
    prop, engines, systems, _, fc, aero = _parts(root)
    if (len(engines) != 2 or [x.get("file") for x in systems] != _KA350_SYSTEMS or fc is None or aero is None):
        raise ValueError("KingAir-350.xml: expected two <propulsion><engine>, the systems "
                         f"{_KA350_SYSTEMS}, a <flight_control> and an <aerodynamics>")
    for e in engines:
        prop.remove(e)
    for x in systems:
        root.remove(x)
    ap = [(summer, i) for ch in fc.findall("channel") for summer in ch for i in summer.findall("input")
          if (i.text or "").strip() in ("ap/elevator-cmd", "ap/aileron-cmd", "fcs/rudder-boost-lag")]
    boost = [(ch, c) for ch in fc.findall("channel") for c in ch if c.get("name") in _KA350_BOOST]
    damper = [p for p in fc.findall("property") if (p.text or "").strip() == "/controls/flight/yaw-damper"]
    feathered = [(axis, f) for axis in aero.findall("axis") for f in axis.findall("function")
                 if f.get("name") == "aero/force/Drag_feathered"]
    if len(ap) != 3 or len(boost) != 4 or len(damper) != 1 or len(feathered) != 1:
        raise ValueError("KingAir-350.xml: expected the inputs ap/elevator-cmd, ap/aileron-cmd and "
                         "fcs/rudder-boost-lag, the four rudder-boost components, the yaw-damper property and "
                         "one Drag_feathered function")
    for parent, child in ap + boost + feathered:
        parent.remove(child)
    damper[0].set("value", "0")
    return root


#: The checked-in Short S.23 folder (the main file and the DATCOM+ aerodynamics it names).
_S23_DIR = Path(__file__).resolve().parents[2] / "data" / "jsbsim_models" / "shorts23"

#: The Short S.23's ``<system>`` elements (their ``file`` attributes) in the checked-in version.
_S23_SYSTEMS = ["hydrodynamics", "hydrodynamic-planing-floats", "Short_S23-hydrodynamics", "sperry-a2-autopilot",
                "take-off-ap", "engines", "fuel-system", "electrical", "flaps"]


def derive_shorts23_glide(root: ET.Element) -> ET.Element:
    """JSBSim's Short S.23 "Empire" flying boat (``data/jsbsim_models/shorts23/``: the jsbsim 1.3.3 wheel's
    ``aircraft/Short_S23/Short_S23.xml`` and ``Systems/datcom_aero.xml``, Anders Gidenstam 2008-2023,
    GPL-2.0-or-later) gliding, in one file, as JSBSim alone can fly it (twenty-fourth session).

    The model is a 1936 four-engine flying boat: Pegasus radials with de Havilland propellers, a planing hull and
    wing-tip floats modelled by hydrodynamic systems that write external forces, a Sperry A-2 autopilot, engine,
    fuel, electrical and flap systems, and DATCOM+ aerodynamics in a second file. Five edits; nothing else changes
    (a test checks every other element, and every aerodynamic function against the checked-in file):

    - **Engines removed.** The four ``<engine>`` elements (``eng_PegasusXc`` with ``prop_deHavilland5000``, their
      feeds) are removed, as the ka350's and the iar80's: the harness glides every aircraft, so that every
      non-gravity force is aerodynamic (a stopped engine leaves JSBSim's windmilling propeller). The twelve fuel
      tanks stay as mass (2 x 2352 lb in the two inner wing tanks, the others empty).
    - **Hull forces removed.** ``<external_reactions>`` (three forces and three moments at the hull, whose
      magnitudes only the hydrodynamic systems write: the hull on the water) is removed.
    - **Systems removed.** The nine ``<system>`` elements (:data:`_S23_SYSTEMS`: the hull's and floats'
      hydrodynamics, the Sperry autopilot, a take-off autopilot, engines, fuel, electrical and flaps) are removed;
      the flap stays at JSBSim's ``fcs/flap-pos-deg`` 0 (flaps up). The FCS's summers keep their Sperry and
      co-pilot inputs, which the FCS itself declares 0 and nothing writes once the systems are gone.
    - **Aerodynamics in one file.** ``<aerodynamics file="Systems/datcom_aero.xml"/>`` is replaced by the
      checked-in ``datcom_aero.xml``'s ``<aerodynamics>`` element (the derived model is one file, as the other
      repository-derived models).
    - **Elevator alias.** Its tables look the elevator up as an ``independentVar`` (CLDe, CdDe, CmDe and the
      elevator hinge moment's Ch-delta, four lookups), which ``effects.py``'s ``delay:delta_e`` (it redirects
      ``<property>`` reads) would not reach; as for the f16 (:func:`derive_f16_direct`) they look it up in the
      identity function :data:`ELEVATOR_ALIAS` = ``fcs/elevator-pos-rad``, added as the aerodynamics' first
      child. The numbers are unchanged (a test checks JSBSim's forces and moments against the stock model's).

    Args:
        root: the parsed ``Short_S23.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): four
            ``<propulsion><engine>``, one ``<external_reactions>``, the nine systems, and an ``<aerodynamics>``
            naming ``Systems/datcom_aero.xml``; or the checked-in ``datcom_aero.xml`` has another root.
    """
    root = copy.deepcopy(root)
    prop, engines, systems, ext, _, aero = _parts(root)
    if (len(engines) != 4 or len(ext) != 1 or [x.get("file") for x in systems] != _S23_SYSTEMS or aero is None
            or aero.get("file") != "Systems/datcom_aero.xml" or len(aero)):
        raise ValueError("Short_S23.xml: expected four <propulsion><engine>, one <external_reactions>, the systems "
                         f"{_S23_SYSTEMS} and <aerodynamics file=\"Systems/datcom_aero.xml\"/>")
    datcom = ET.parse(_S23_DIR / "datcom_aero.xml").getroot()
    if datcom.tag != "aerodynamics":
        raise ValueError(f"datcom_aero.xml: root <{datcom.tag}>, expected <aerodynamics>")
    for e in engines:
        prop.remove(e)
    root.remove(ext[0])
    for x in systems:
        root.remove(x)
    n = _alias_elevator_lookups(datcom)
    if n != 4:
        raise ValueError(f"datcom_aero.xml: {n} table lookups of fcs/elevator-pos-rad, expected 4")
    root.insert(list(root).index(aero), datcom)
    root.remove(aero)
    return root


def derive_dr1_glide(root: ET.Element) -> ET.Element:
    """JSBSim's Fokker Dr.I triplane (``data/jsbsim_models/fokkerdr1/dr1.xml``: the jsbsim 1.3.3 wheel's
    ``aircraft/dr1/dr1.xml``, Ron Jensen and Erik Hofman 2008 from an Aeromatic 0.9 start, LGPL-2.1 with JSBSim)
    gliding, as JSBSim alone can fly it (twenty-fifth session).

    The model is the 1917 triplane fighter: an Oberursel UR.II rotary engine with its propeller, a FlightGear
    pushback system that writes an external force at the tail skid (the reason the ninth session could not
    initialise it: the system reads ``/sim/model/pushback/position-norm``), and its own aerodynamics (a lift table
    over +-180 deg of alpha, the pitch moment as a table in alpha and a second table in alpha and elevator,
    constant lateral-directional derivatives that are not Aeromatic's set). Four edits; nothing else changes (a test
    checks every other element, and that JSBSim's aerodynamic forces and moments equal the stock wheel model's):

    - **Engine removed.** The ``<engine>`` element (``Oberursel-UrII`` with ``Dr1_propeller``, its feed) is
      removed, as the s23's and the iar80's: the harness glides every aircraft, so that every non-gravity force is
      aerodynamic (a stopped engine leaves JSBSim's windmilling propeller). The fuel tank (50 lb on the centre
      line) stays as mass.
    - **Pushback force removed.** ``<external_reactions>`` (one body-axis force at the tail skid, whose magnitude
      only the pushback system writes) is removed.
    - **Pushback system removed.** ``<system file="pushback"/>`` (FlightGear's ground tug) is removed; the chocks
      system is commented out in the file and stays so.
    - **Elevator alias.** The ``Cmde`` table looks the elevator up as its column ``independentVar`` (one lookup),
      which ``effects.py``'s ``delay:delta_e`` (it redirects ``<property>`` reads) would not reach; as for the f16
      and the s23 it looks it up in the identity function :data:`ELEVATOR_ALIAS` = ``fcs/elevator-pos-rad``, added
      as the aerodynamics' first child. ``CLde`` reads the elevator as a ``<property>`` (reached directly);
      ``CDde`` reads JSBSim's ``fcs/mag-elevator-pos-rad`` (not delayed, as on the b747 and c172x).

    Args:
        root: the parsed ``dr1.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): one
            ``<propulsion><engine>``, one ``<external_reactions>``, the one ``pushback`` system, an
            ``<aerodynamics>`` with one table lookup of ``fcs/elevator-pos-rad``.
    """
    root = copy.deepcopy(root)
    prop, engines, systems, ext, _, aero = _parts(root)
    if len(engines) != 1 or len(ext) != 1 or [x.get("file") for x in systems] != ["pushback"] or aero is None:
        raise ValueError("dr1.xml: expected one <propulsion><engine>, one <external_reactions>, the system "
                         "'pushback' and an <aerodynamics>")
    prop.remove(engines[0])
    root.remove(ext[0])
    root.remove(systems[0])
    n = _alias_elevator_lookups(aero)
    if n != 1:
        raise ValueError(f"dr1.xml: {n} table lookups of fcs/elevator-pos-rad, expected 1")
    return root


def derive_navion_glide(root: ET.Element) -> ET.Element:
    """JSBSim's Ryan Navion (``data/jsbsim_models/navion/L17.xml``: the jsbsim 1.3.3 wheel's ``aircraft/L17/L17.xml``,
    "Originally from Bruce Jackson (LaRCSim)?", LGPL-2.1 with JSBSim) gliding, as JSBSim alone can fly it (twenty-sixth
    session).

    The model is the Navion four-seat light aircraft (the Army's L-17) with the textbook stability derivatives of
    the Navion (Teper, NASA CR-96008, 1969; Nelson, *Flight Stability and Automatic Control*, 2nd ed., 1998, appendix
    B: Cm_alpha -0.683, Cm_q -9.96, Cm_alphadot -4.36, CY_beta -0.564, Cl_beta -0.074, Cl_p -0.410, Cl_r 0.107,
    Cn_beta 0.071, Cn_p -0.0575, Cn_r -0.125, Cn_delta_r -0.072, CL_delta_e 0.355, Cm_delta_e -0.923 at Mach 0),
    a Continental IO-470-D with a 75-in propeller, and a flap channel whose normaliser reads
    ``fcs/flaps-pos-deg``, a property nothing writes (the flap kinematic writes ``fcs/flap-pos-deg``): ``run_ic``
    raises, the ninth session's reason for setting it aside. Two edits; nothing else changes (a test checks every
    other element, and that JSBSim's aerodynamic forces and moments equal the stock wheel model's):

    - **Engine removed.** The ``<engine>`` element (``engIO470D`` with ``prop_75in2f``, its feed) is removed, as
      the dr1's and the iar80's: the harness glides every aircraft, so that every non-gravity force is
      aerodynamic (a stopped engine leaves JSBSim's windmilling propeller). The two fuel tanks (10 lb each, on
      the centre line) stay as mass. No aerodynamic function reads the propeller.
    - **Flap normaliser input.** The ``Flap Position Normalizer``'s ``<input>`` ``fcs/flaps-pos-deg`` reads
      ``fcs/flap-pos-deg``, the ``Flaps Control`` kinematic's output in the same channel. The harness never
      commands the flaps: both are 0, so ``fcs/flap-pos-norm`` (read by ``CDflap`` and ``dCLflap``) is 0 as the
      stock model's is once ``fcs/flaps-pos-deg`` exists at 0.

    The elevator is read as a ``<property>`` only (``CLde``, ``Cmde``), so ``effects.py``'s ``delay:delta_e``
    reaches it without an alias; ``CDde`` reads JSBSim's ``fcs/mag-elevator-pos-rad`` (not delayed, as on the b747,
    c172x and dr1).

    Args:
        root: the parsed ``L17.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): one
            ``<propulsion><engine>``, one ``Flap Position Normalizer`` reading ``fcs/flaps-pos-deg``, an
            ``<aerodynamics>``.
    """
    root = copy.deepcopy(root)
    prop, engines, *_ = _parts(root)
    norm = [c for c in root.iterfind("flight_control/channel/aerosurface_scale")
            if c.get("name") == "Flap Position Normalizer"]
    if len(engines) != 1 or len(norm) != 1 or root.find("aerodynamics") is None:
        raise ValueError("L17.xml: expected one <propulsion><engine>, one 'Flap Position Normalizer' and an "
                         "<aerodynamics>")
    inp = norm[0].find("input")
    if inp is None or (inp.text or "").strip() != "fcs/flaps-pos-deg":
        raise ValueError("L17.xml: the flap normaliser does not read fcs/flaps-pos-deg")
    prop.remove(engines[0])
    inp.text = "fcs/flap-pos-deg"
    return root


#: The Fokker 50's propwash functions (axis, name): each a product with a propeller thrust coefficient.
_F50_PROPWASH = [("LIFT", "aero/force/Lift_propwash"), ("ROLL", "aero/moment/Roll_differential_propwash"),
                 ("PITCH", "aero/moment/Pitch_propwash")]

#: The Fokker 50's yaw-damper components (the ``Yaw`` channel's), removed with the rudder summer's input.
_F50_DAMPER = ["Yaw Damper Rate", "Yaw Damper Beta", "Yaw Damper Sum", "Yaw Damper Final"]


def derive_fokker50_glide(root: ET.Element) -> ET.Element:
    """JSBSim's Fokker 50 (``data/jsbsim_models/fokker50/fokker50.xml``: the jsbsim 1.3.3 wheel's
    ``aircraft/fokker50/fokker50.xml``, Erik Hofman 2002, LGPL-2.1 with JSBSim) gliding, as JSBSim alone can fly it
    (twenty-seventh session).

    The model is the Fokker 50 twin-turboprop regional airliner: two PW125B engines with Dowty Rotol propellers, an
    engine-control channel (``EEC``) that reads FlightGear's ``/controls/engines/engine[n]/throttle`` (so ``run_ic``
    raises in JSBSim alone: the ninth session's reason for setting it aside), a ``Thruster`` channel that sums the
    propellers' thrust coefficients, three propwash terms that multiply them, and a yaw damper. Five edits; nothing
    else changes (a test checks every other element, and that JSBSim's aerodynamic forces and moments equal the stock
    model's less its three propwash terms):

    - **Engines removed.** The two ``<engine>`` elements (``PW125BX`` with ``dowty-rotol-aero``, their feeds) are
      removed, as the navion's, dr1's and ka350's: the harness glides every aircraft, so that every non-gravity force
      is aerodynamic (a stopped engine leaves JSBSim's windmilling propeller). The two fuel tanks (1100 lb each,
      3 in either side of the centre line) stay as mass.
    - **Engine control removed.** The ``EEC`` channel (throttle and propeller-speed commands from FlightGear's
      throttle and ``/systems/fokker50/erp/*`` settings) and the two ``<property>`` declarations of those settings;
      they drive the engines only.
    - **Thrust coefficients removed.** The ``Thruster`` channel (four summers of
      ``propulsion/engine[n]/thrust-coefficient``), gone with the engines.
    - **Propwash terms removed.** ``Lift_propwash``, ``Roll_differential_propwash`` and ``Pitch_propwash``
      (:data:`_F50_PROPWASH`) are products with the total or the left-less-right thrust coefficient: without
      propellers the coefficient is 0 and so is each term. No other aerodynamic function reads the propellers.
    - **Yaw damper removed.** Its four components (:data:`_F50_DAMPER`: 2 x r above 11 psf of dynamic pressure,
      clipped at +-0.2 of the command) and the rudder summer's input ``fcs/yaw-damper-final``: it would move the
      rudder with the yaw rate in every flight (the ka350's damper is off for the same reason). The rudder then
      follows the command, as the elevator and ailerons do.

    The elevator is read as a ``<property>`` only (``CLde``, ``Cmde``), so ``effects.py``'s ``delay:delta_e``
    reaches it without an alias; ``CDde`` reads JSBSim's ``fcs/mag-elevator-pos-rad`` (not delayed, as on the
    navion).

    Args:
        root: the parsed ``fokker50.xml`` (not modified).

    Returns:
        a new root element.

    Raises:
        ValueError: the XML lacks an element the derivation expects (another version of the file): two
            ``<propulsion><engine>``, the ``EEC``, ``Thruster`` and ``Yaw`` channels, the two ERP properties, the
            three propwash functions, the four damper components and the rudder summer's damper input.
    """
    root = copy.deepcopy(root)
    prop, engines, _, _, fc, aero = _parts(root)
    if len(engines) != 2 or fc is None or aero is None:
        raise ValueError("fokker50.xml: expected two <propulsion><engine>, a <flight_control> and an <aerodynamics>")
    channels = {ch.get("name"): ch for ch in fc.findall("channel")}
    erp = [p for p in fc.findall("property") if (p.text or "").strip().startswith("/systems/fokker50/erp/")]
    axes = {a.get("name"): a for a in aero.findall("axis")}
    wash = [(axes[ax], f) for ax, name in _F50_PROPWASH if ax in axes
            for f in axes[ax].findall("function") if f.get("name") == name]
    yaw = channels.get("Yaw")
    damper = [c for c in yaw if c.get("name") in _F50_DAMPER] if yaw is not None else []
    rsum = [c for c in yaw if c.get("name") == "Rudder Sum"] if yaw is not None else []
    dinp = [i for i in rsum[0].findall("input") if (i.text or "").strip() == "fcs/yaw-damper-final"] if rsum else []
    if ("EEC" not in channels or "Thruster" not in channels or len(erp) != 2 or len(wash) != 3
            or len(damper) != 4 or len(dinp) != 1):
        raise ValueError("fokker50.xml: expected the EEC, Thruster and Yaw channels, two /systems/fokker50/erp "
                         "properties, the three propwash functions, the four yaw-damper components and the rudder "
                         "summer's fcs/yaw-damper-final input")
    for e in engines:
        prop.remove(e)
    for x in [channels["EEC"], channels["Thruster"]] + erp:
        fc.remove(x)
    for axis, f in wash:
        axis.remove(f)
    for c in damper:
        yaw.remove(c)
    rsum[0].remove(dinp[0])
    return root


#: Derived model name -> (stock model it comes from, derivation, what the derivation did: the
#: derived XML's header comment).
DERIVED = {
    "f16_direct": ("f16", derive_f16_direct, "flight control replaced by a direct mapping of the commands to the "
                                             "surfaces, flaps fixed at 0; aerodynamics, mass and propulsion "
                                             "unchanged."),
    "F4N_fcs": ("F4N", derive_f4n_fcs, "an empty <flight_control> added (the stock one is commented out), for the "
                                       "harness's injected elevator delay; everything else unchanged."),
}

_REPO = Path(__file__).resolve().parents[2]

#: Derived models whose source XML is checked into this repository (a model from outside the wheel;
#: provenance and licence in the folder's README.md): name -> (source XML relative to the
#: repository root, where it comes from, derivation, what the derivation did).
REPO_DERIVED = {
    "Rascal110_glide": ("data/jsbsim_models/rascal/Rascal110-JSBSim.xml",
                        "ArduPilot's Tools/autotest/aircraft/Rascal/Rascal110-JSBSim.xml (GPL-3.0), copied into "
                        "gcs-sysid's data/jsbsim_models/rascal/",
                        derive_rascal_glide, "engine and propeller removed (a glide with no propeller force); "
                                             "everything else unchanged."),
    "asw20_glide": ("data/jsbsim_models/asw20/asw20-JSBSim.xml",
                    "FlightGear's ASW 20 (FGMEMBERS/asw20 Models/JSBSim/asw20-JSBSim.xml at 3ef71d9c, "
                    "GPL-2.0-or-later), "
                    "copied into gcs-sysid's data/jsbsim_models/asw20/",
                    derive_asw20_glide, "the GenericEngine and WaterBallast systems and the Water Dumping channel "
                                        "(FlightGear's) removed; the CmDe table reads the elevator through an alias "
                                        "in degrees of fcs/elevator-pos-rad; everything else unchanged."),
    "IAR80_glide": ("data/jsbsim_models/iar80/IAR80-Jsb.xml",
                    "FlightGear's JSBSim IAR-80 (FGMEMBERS/IAR-80-JSB IAR80-Jsb.xml at 6d011335, GPL-2.0-or-later), "
                    "copied into gcs-sysid's data/jsbsim_models/iar80/",
                    derive_iar80_glide, "engine and propeller removed (a glide with no propeller force); the fuel "
                                        "tanks stay as mass; everything else unchanged."),
    "C684_glide": ("data/jsbsim_models/c684/C684.xml",
                   "FlightGear's JSBSim Caudron C.684 (FGMEMBERS/C684 C684.xml at 05ad4b2c, GPL-2.0-or-later), "
                   "copied into gcs-sysid's data/jsbsim_models/c684/",
                   derive_c684_glide, "engine, propeller and the engine system removed (a glide with no propeller "
                                      "force); the fuel tanks stay as mass; the gear's FIXED flags written 0 "
                                      "(JSBSim 1.3.3's syntax); everything else unchanged."),
    "UltraStick120_glide": ("data/jsbsim_models/ultrastick120/UltraStick120.xml",
                            "the University of Minnesota UAS Lab's JSBSim Ultra Stick 120 (UASLab/OpenFlightSim "
                            "Simulation/aircraft/UltraStick120 at 1650a6e3, MIT), copied into gcs-sysid's "
                            "data/jsbsim_models/ultrastick120/",
                            derive_ultrastick120_glide, "its Metrics, Mass, Gear and Aero files in one file; no "
                            "propulsion; the lab's control laws, actuators and sensors replaced by direct surfaces "
                            "(+-30 deg); the aerodynamics read fcs/elevator-pos-rad and fcs/rudder-pos-rad for the "
                            "lab's posElev_rad and posRud_rad; flaps 0; no number changed."),
    "Eternity_glide": ("data/jsbsim_models/eternity/Eternity.xml",
                       "ENAC's Eternity UAV from Paparazzi (paparazzi/paparazzi conf/simulator/jsbsim/aircraft/"
                       "Eternity.xml at 5399bd98, Murat Bronz 2015, GPL-2.0-or-later), copied into gcs-sysid's "
                       "data/jsbsim_models/eternity/",
                       derive_eternity_glide, "motor, propeller and throttle channel removed (a glide with no "
                                              "propeller force); "
                                              "Pitch_elevator reads the elevator through an alias in degrees of "
                                              "fcs/elevator-pos-rad; everything else unchanged."),
    "UltraStick25e_glide": ("data/jsbsim_models/ultrastick25e/UltraStick25e.xml",
                            "the University of Minnesota UAS Lab's JSBSim Ultra Stick 25e with its OpenFlight "
                            "aerodynamics (UASLab/OpenFlightSim Simulation/aircraft/UltraStick25e, MIT), copied into "
                            "gcs-sysid's data/jsbsim_models/ultrastick25e/",
                            derive_ultrastick25e_glide, "its MetricsOpenFlight, MassOpenFlight, Gear and "
                            "AeroOpenFlight files in one file; no propulsion; the lab's control laws, actuators and "
                            "sensors replaced by direct surfaces (+-30 deg); the aerodynamics read "
                            "fcs/elevator-pos-rad and fcs/rudder-pos-rad for the lab's posElev_rad and posRud_rad; "
                            "flaps 0; no number changed."),
    "KingAir350_glide": ("data/jsbsim_models/kingair350/KingAir-350.xml",
                         "a JSBSim Beechcraft King Air 350 (itaalh/FlightGear-Beechcraft-350ER Aero/KingAir-350.xml "
                         "at 0298d965, GPL-2.0-or-later), copied into gcs-sysid's data/jsbsim_models/kingair350/",
                         derive_kingair350_glide, "engines, propellers and the four systems removed (a glide with "
                         "no propeller force); the autopilot's inputs, the rudder boost and the feathered-propeller "
                         "drag (which read them) removed; yaw damper off; the fuel tanks stay as mass; everything "
                         "else unchanged."),
    "ShortS23_glide": ("data/jsbsim_models/shorts23/Short_S23.xml",
                       "JSBSim's Short S.23 flying boat (the jsbsim 1.3.3 wheel's aircraft/Short_S23/Short_S23.xml "
                       "and Systems/datcom_aero.xml, Anders Gidenstam 2008-2023, GPL-2.0-or-later), copied into "
                       "gcs-sysid's data/jsbsim_models/shorts23/",
                       derive_shorts23_glide, "engines and propellers, the hull's external forces and the nine "
                       "systems (hydrodynamics, autopilots, engines, fuel, electrical, flaps) removed (a glide with "
                       "no propeller or water force); the DATCOM+ aerodynamics file inlined, its tables reading the "
                       "elevator through an identity alias; the fuel tanks stay as mass; everything else "
                       "unchanged."),
    "Dr1_glide": ("data/jsbsim_models/fokkerdr1/dr1.xml",
                  "JSBSim's Fokker Dr.I triplane (the jsbsim 1.3.3 wheel's aircraft/dr1/dr1.xml, Ron Jensen and "
                  "Erik Hofman 2008, LGPL-2.1 with JSBSim), copied into gcs-sysid's data/jsbsim_models/fokkerdr1/",
                  derive_dr1_glide, "rotary engine and propeller, the pushback force and the pushback system "
                  "removed (a glide with no propeller or ground-tug force); the Cmde table reads the elevator "
                  "through an identity alias; the fuel tank stays as mass; everything else unchanged."),
    "Navion_glide": ("data/jsbsim_models/navion/L17.xml",
                     "JSBSim's Ryan Navion (the jsbsim 1.3.3 wheel's aircraft/L17/L17.xml, from LaRCSim's Navion, "
                     "LGPL-2.1 with JSBSim), copied into gcs-sysid's data/jsbsim_models/navion/",
                     derive_navion_glide, "engine and propeller removed (a glide with no propeller force); the flap "
                     "normaliser reads the flap kinematic's output fcs/flap-pos-deg (the file's fcs/flaps-pos-deg "
                     "exists nowhere, so JSBSim alone could not initialise it); the fuel tanks stay as mass; "
                     "everything else unchanged."),
    "Fokker50_glide": ("data/jsbsim_models/fokker50/fokker50.xml",
                       "JSBSim's Fokker 50 (the jsbsim 1.3.3 wheel's aircraft/fokker50/fokker50.xml, Erik Hofman "
                       "2002, LGPL-2.1 with JSBSim), copied into gcs-sysid's data/jsbsim_models/fokker50/",
                       derive_fokker50_glide, "engines and propellers removed (a glide with no propeller force), "
                       "with the engine-control and thrust-coefficient channels that read them and the three "
                       "propwash terms that multiply the thrust coefficients (0 without propellers); yaw damper "
                       "removed; the fuel tanks stay as mass; everything else unchanged."),
}


def derived_xml(name: str, stock_dir: Path | None = None) -> bytes:
    """The derived model ``name``'s XML as bytes, from the installed wheel's stock model.

    ``stock_dir`` is ignored for the :data:`REPO_DERIVED` models (their source is in the repository).

    Raises:
        KeyError: ``name`` is in neither :data:`DERIVED` nor :data:`REPO_DERIVED`.
        ValueError: the stock XML does not take the derivation.
    """
    if name in REPO_DERIVED:
        rel, origin, derive, what = REPO_DERIVED[name]
        src = _REPO / rel
        source = origin
    else:
        stock, derive, what = DERIVED[name]
        src = (stock_dir or _wheel_root() / "aircraft" / stock) / f"{stock}.xml"
        source = f"the jsbsim wheel's aircraft/{stock}/{stock}.xml (LGPL-2.1)"
    root = derive(ET.parse(src).getroot())
    ET.indent(root, space=" ")
    header = (f"<?xml version=\"1.0\"?>\n<!-- Derived from {source} by "
              f"gcs-sysid's benchmarks/jsbsim_harness/derived.py: {what} -->\n")
    return header.encode() + ET.tostring(root, encoding="unicode").encode() + b"\n"


def derived_sha(name: str) -> str:
    """First 16 hex digits of the SHA-256 of :func:`derived_xml` (recorded in the spec's notes)."""
    return hashlib.sha256(derived_xml(name)).hexdigest()[:16]


def _move_into_place(src: Path, dest: Path, want: bytes, old: Path) -> None:
    """Rename the folder ``src`` to ``dest`` (an existing ``dest`` moved to ``old`` first and removed after). Where a
    concurrent writer (another test worker on a fresh installation) put its own copy at ``dest`` between the check and
    the rename, the rename fails; that is success if ``dest`` now holds ``want`` as its model XML.

    Raises:
        OSError: the rename failed and ``dest`` does not hold ``want``.
    """
    moved = False
    try:
        if dest.exists():
            dest.rename(old)
            moved = True
        src.rename(dest)
    except OSError:
        xml = dest / f"{dest.name}.xml"
        if not (xml.is_file() and xml.read_bytes() == want):
            raise
    finally:
        if moved:
            shutil.rmtree(old, ignore_errors=True)


def install_derived_models(aircraft_dir: Path | None = None) -> list[Path]:
    """Write every model of :data:`DERIVED` into the wheel's ``aircraft/`` folder (or ``aircraft_dir``)
    where it is missing or differs; returns the folders written.

    Each is the stock folder copied (its ``Systems/`` included) with the XML replaced by
    :func:`derived_xml` as ``<name>/<name>.xml`` (a :data:`REPO_DERIVED` model: a folder with that
    XML alone); written in a temporary folder beside it and renamed into place, so that a concurrent
    reader sees the old folder or the new one, and a concurrent writer that got there first leaves its copy
    (:func:`_move_into_place`).

    A folder that cannot be written (a read-only installation) gives a ``UserWarning`` naming it;
    flying that model then fails in JSBSim's loader.
    """
    base = Path(aircraft_dir) if aircraft_dir else _wheel_root() / "aircraft"
    written = []
    for name in list(DERIVED) + list(REPO_DERIVED):
        stock = DERIVED[name][0] if name in DERIVED else None
        try:
            want = derived_xml(name, base / stock if stock else None)
            dest = base / name
            if (dest / f"{name}.xml").is_file() and (dest / f"{name}.xml").read_bytes() == want:
                continue
            tmp = Path(tempfile.mkdtemp(prefix=f".{name}-", dir=base))
            if stock:
                shutil.copytree(base / stock, tmp / name)
                (tmp / name / f"{stock}.xml").unlink()
            else:
                (tmp / name).mkdir()
            (tmp / name / f"{name}.xml").write_bytes(want)
            try:
                _move_into_place(tmp / name, dest, want, base / f".{name}-old-{os.getpid()}")
            finally:
                shutil.rmtree(tmp, ignore_errors=True)
            written.append(dest)
        except OSError as e:
            warnings.warn(f"could not write the derived JSBSim model '{name}' into {base}: {e}; "
                          f"the harness cannot fly it from this installation", stacklevel=2)
    return written
