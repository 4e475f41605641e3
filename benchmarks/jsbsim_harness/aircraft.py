"""Stock JSBSim aircraft flown by the harness: model name, trim point, sign map, autopilot gains.

JSBSim models do not share one sign convention for their surface positions (the c172x's
``fcs/aileron-*-pos-rad`` come in pairs, the SGS moves one aileron property only),
so each aircraft carries the signs that turn JSBSim's positions into the project's conventions
(``docs/conventions.md``: delta_e trailing edge down, delta_a right aileron trailing edge down,
delta_r trailing edge left, all positive). The signs were read from each model's response to a
positive command (``docs/jsbsim.md``) and are checked against the truth in
``tests/jsbsim/test_harness.py`` (Cm_delta_e, Cl_delta_a, Cn_delta_r all negative).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

__all__ = ["AircraftSpec", "AIRCRAFT", "TUNING_AIRCRAFT", "HELD_OUT_AIRCRAFT", "UNTOUCHED_AIRCRAFT", "aircraft",
           "canonical_name", "aircraft_argument", "summary_label"]

REPO = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class AircraftSpec:
    """One stock JSBSim aircraft and how the harness flies it.

    Attributes:
        name: harness name (also the airframe file ``data/airframes/jsbsim-<name>.toml``).
        model: JSBSim model directory name shipped by the ``jsbsim`` wheel (or written there by ``derived.py``).
        airspeed_kts: calibrated airspeed of the glide, kt (JSBSim's ``ic/vc-kts``).
        altitude_ft: initial altitude above sea level, ft.
        elevator_sign: delta_e = sign * ``fcs/elevator-pos-rad``.
        aileron_sign: delta_a = sign * 0.5 * (left - right) of the two JSBSim aileron position
            properties, or sign * left when the model has only one (``aileron_props[1]`` None;
            the right aileron is then the mirror of the left).
        aileron_props: (left, right) JSBSim aileron position properties, rad.
        rudder_sign: delta_r = sign * ``fcs/rudder-pos-rad``.
        cmd_per_rad: (elevator, aileron, rudder) JSBSim normalised command (-1..1) per rad of the
            raw JSBSim deflection (the autopilot thinks in the project's deflections; the command
            is ``delta * sign * cmd_per_rad``).
        amplitude_deg: (delta_e, delta_a, delta_r) maneuver amplitudes, deg.
        pulse_s: (pitch, roll, yaw) pulse width of doublets and 3-2-1-1s, s.
        gains: autopilot gains (k_theta, k_q, k_v, k_phi, k_p, k_r), rad/rad, rad/(rad/s), rad/(m/s).
        gear_up: retract the landing gear (``gear/gear-cmd-norm`` = 0 at the initial condition;
            the model's gear channel moves it up during the settling phase) for a model whose
            retractable gear adds drag while down; False leaves a fixed gear as the model has it.
        notes: provenance.
    """

    name: str
    model: str
    airspeed_kts: float
    altitude_ft: float
    elevator_sign: float
    aileron_sign: float
    aileron_props: tuple[str, str | None]
    rudder_sign: float
    cmd_per_rad: tuple[float, float, float]
    amplitude_deg: tuple[float, float, float]
    pulse_s: tuple[float, float, float]
    gains: tuple[float, float, float, float, float, float] = (1.0, 0.3, 0.01, 0.4, 0.1, 0.4)
    gear_up: bool = False
    notes: str = ""

    @property
    def airframe_path(self) -> Path:
        """The airframe file the pipeline reads for this aircraft."""
        return REPO / "data" / "airframes" / f"jsbsim-{self.name}.toml"


_DEG = 57.29577951308232

#: Aircraft the harness knows. ``c172x`` and ``sgs`` were used to set up the harness and the test
#: thresholds; ``pa28`` (held out since 2026-11-21), ``j3cub`` (untouched until the sixth
#: session's final evaluation, 2026-11-22), ``c182`` (untouched until the seventh session's)
#: have since been evaluated and their results read, so they count as used (``TUNING_AIRCRAFT``).
#: ``t37``, ``t6``, ``b747``, ``f16``, ``f4n`` and ``rascal`` (untouched until the eighth to thirteenth
#: sessions' final evaluations; the f16 flown as the derived model ``f16_direct``, the f4n as ``F4N_fcs``,
#: the rascal, ArduPilot's SITL Rascal 110 checked into ``data/jsbsim_models``, as ``Rascal110_glide``:
#: ``derived.py``) and ``sgs126`` (the fourteenth session's: the wheel's Schweizer SGS 1-26 glider, flown at
#: 3000 ft where JSBSim's light turbulence is active) and ``asw20`` (the fifteenth session's: FlightGear's ASW 20
#: sailplane, checked into ``data/jsbsim_models/asw20`` and flown as ``asw20_glide``, at 3000 ft) are used since as
#: well, as is ``iar80`` (the sixteenth session's: FlightGear's JSBSim IAR-80 fighter, checked into
#: ``data/jsbsim_models/iar80`` and flown as ``IAR80_glide``, engine and propeller removed, at 10000 ft) and ``c684``
#: (the seventeenth session's: FlightGear's JSBSim Caudron C.684 racer, checked into ``data/jsbsim_models/c684`` and
#: flown as ``C684_glide``, engine and propeller removed, at 6000 ft) and ``ultrastick`` (the eighteenth session's:
#: the University of Minnesota UAS Lab's JSBSim Ultra Stick 120 UAV, checked into ``data/jsbsim_models/ultrastick120``
#: and flown as ``UltraStick120_glide``, no propulsion, direct surfaces, at 10000 ft) and ``b737`` (the nineteenth
#: session's: JSBSim's stock Boeing 737, the wheel's ``737``, engines shut down, gear up, its own yaw damper in the
#: loop, at 12000 ft) and ``c172p`` (the twentieth session's: JSBSim's stock Cessna 172P, the wheel's ``c172p``,
#: engine shut down, fixed gear, at 4000 ft) and ``eternity`` (the twenty-first session's: ENAC's Eternity UAV from
#: Paparazzi, checked into ``data/jsbsim_models/eternity`` and flown as ``Eternity_glide``, motor removed, at
#: 10000 ft) and ``us25e`` (the twenty-second session's: the University of Minnesota UAS Lab's Ultra Stick 25e with
#: its OpenFlight aerodynamics, checked into ``data/jsbsim_models/ultrastick25e`` and flown as
#: ``UltraStick25e_glide``, no propulsion, direct surfaces, at 10000 ft) and ``ka350`` (the twenty-third session's: a
#: JSBSim Beechcraft King Air 350 twin turboprop from a FlightGear package, checked into
#: ``data/jsbsim_models/kingair350`` and flown as ``KingAir350_glide``, engines and systems removed, gear up, at
#: 8000 ft) and ``s23`` (the twenty-fourth session's: JSBSim's Short S.23 "Empire" flying boat, Anders Gidenstam's
#: model with DATCOM+ aerodynamics, checked into ``data/jsbsim_models/shorts23`` and flown as ``ShortS23_glide``,
#: engines, hull forces and systems removed, at 6000 ft) and ``dr1`` (the twenty-fifth session's: JSBSim's Fokker
#: Dr.I triplane, the wheel's ``dr1`` checked into ``data/jsbsim_models/fokkerdr1`` and flown as ``Dr1_glide``, rotary
#: engine, propeller and pushback removed, at 8000 ft) and ``navion`` (the twenty-sixth session's: JSBSim's Ryan
#: Navion, the wheel's ``L17`` with the textbook Navion derivatives, checked into ``data/jsbsim_models/navion`` and
#: flown as ``Navion_glide``, engine and propeller removed, gear up, at 10000 ft). ``fokker50`` (JSBSim's Fokker 50
#: twin-turboprop airliner, the wheel's ``fokker50`` checked into ``data/jsbsim_models/fokker50`` and flown as
#: ``Fokker50_glide``, engines, propellers, propwash terms and yaw damper removed, gear up, at 10000 ft; the
#: twenty-seventh session's untouched aircraft, moved to tuning in the twenty-eighth). No aircraft is held out now:
#: the pool of stock and outside models that pass screening is exhausted (docs/jsbsim.md, "Choosing the untouched
#: aircraft"); the next final evaluation needs a model from outside the project.
AIRCRAFT: dict[str, AircraftSpec] = {
    "c172x": AircraftSpec(
        name="c172x", model="c172x", airspeed_kts=80.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(_DEG / 19.48, _DEG / 17.35, _DEG / 16.0),
        amplitude_deg=(3.0, 5.0, 6.0), pulse_s=(0.7, 0.8, 1.0),
        notes="Cessna 172 (JSBSim c172x), engine shut down, gliding; lateral point masses emptied"),
    "sgs": AircraftSpec(
        name="sgs", model="SGS", airspeed_kts=50.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None),
        rudder_sign=1.0, cmd_per_rad=(_DEG / 28.0, _DEG / 20.0, _DEG / 16.0),
        amplitude_deg=(3.0, 5.0, 6.0), pulse_s=(0.8, 0.9, 1.0),
        notes="Schweizer SGS 2-33 glider (JSBSim SGS)"),
    "pa28": AircraftSpec(
        name="pa28", model="pa28", airspeed_kts=80.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(_DEG / 23.0, _DEG / 22.5, _DEG / 27.0),
        amplitude_deg=(3.0, 5.0, 6.0), pulse_s=(0.7, 0.8, 1.0),
        notes="Piper PA-28 (JSBSim pa28), engine shut down, gliding; held out of all tuning"),
    # J3Cub: Aeromatic model (Erik Hofman, 2015) with Du (2011) derivatives; surfaces from its
    # "Systems/Conventional Controls.xml" (elevator +-0.14, ailerons +-0.31 with the right the
    # mirror of the left, rudder +-0.52 rad). Signs read from its aerodynamics: Pitch_elevator
    # -1.2004 * elevator-pos (positive = trailing edge down), Roll_aileron +0.3498 * left-aileron-pos
    # (positive = left trailing edge down, roll right), Yaw_rudder -0.0565 * rudder-pos (positive =
    # trailing edge left, nose left); checked on the truth by tests/jsbsim/test_jsbsim_j3cub.py.
    # 50 kt CAS: 1.6 times the model's power-off stall (about 31 kt EAS at 967 lb, CL_max 1.62 at
    # its lower Reynolds number); the sweep's slowest level, 37.5 kt, is 1.2 times the stall, as
    # on the c172x. Its pitch damping is 2.6 times the c172x's (dimensional M_q at 30 m/s), so the
    # elevator amplitude is 4 deg and the pitch-rate gain half the default; the elevator's +-8 deg
    # leaves 3-4 deg below the slow level's trim. Set from the harness's truth only (alpha, beta,
    # rates, excitation per axis; docs/jsbsim.md), never from a pipeline result.
    "j3cub": AircraftSpec(
        name="j3cub", model="J3Cub", airspeed_kts=50.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.14, 1.0 / 0.31, 1.0 / 0.52),
        amplitude_deg=(4.0, 4.5, 5.0), pulse_s=(0.7, 0.8, 1.0), gains=(1.0, 0.15, 0.01, 0.4, 0.1, 0.4),
        notes="Piper J-3 Cub (JSBSim J3Cub), engine shut down, gliding; untouched by any tuning of the method"),
    # c182: JSBSim's stock Cessna 182 (c182.xml, jberndt 2012). Surfaces from its own
    # <flight_control> (aerosurface_scale, zero-centred): elevator -28..+23 deg, left aileron
    # -20..+15 deg (the only aileron property the aerodynamics read), rudder +-16 deg; the command
    # scale is the mean of each surface's two ends (as the pa28's aileron). Signs read from its
    # aerodynamics: CmDe -0.622 * elevator-pos (positive = trailing edge down), ClDa +0.15 *
    # left-aileron-pos (positive = left trailing edge down, roll right), CnDr -0.0645 * rudder-pos
    # (positive = trailing edge left, nose left); checked on the truth by tests/jsbsim/test_jsbsim_roster.py.
    # 80 kt CAS as the c172x and pa28 (the same initial condition: 49 m/s TAS at 6000 ft); the
    # sweep's slowest level, 36.5 m/s TAS, is 1.3 times the model's power-off stall (about 49 kt EAS:
    # 2100 lb once the harness empties the pilot's off-centre point mass, CL_max 1.47 from its
    # CLo + CLalpha tables). Its pitch stiffness and elevator power are a third and a half of the
    # c172x's (Cm_alpha -0.61, CmDe -0.62 per rad), so the elevator amplitude is 5 deg (3 deg gave
    # 1.5 deg/s of pitch-rate standard deviation); its rudder gives about 1 deg of sideslip per deg
    # (Cn_beta 0.059, CnDr -0.065), so the rudder amplitude is 4 deg (6 deg gave 7.5 deg of
    # sideslip and a knock-it-off with Cl:alpha*beta = 3). Default gains. Set from the harness's
    # truth only (alpha, beta, rates, excitation per axis; docs/jsbsim.md), never from a method result.
    "c182": AircraftSpec(
        name="c182", model="c182", airspeed_kts=80.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(_DEG / 25.5, _DEG / 17.5, _DEG / 16.0),
        amplitude_deg=(5.0, 5.0, 4.0), pulse_s=(0.7, 0.8, 1.0),
        notes="Cessna 182 (JSBSim c182), engine shut down, gliding; untouched by any tuning of the method"),
    # t37: JSBSim's stock Cessna T-37 (T37.xml, Erik Hofman 2001), a twin-jet side-by-side trainer.
    # Chosen after the c310 (its inertia, Ixx + Iyy < Izz, is not a physical tensor: the airframe
    # file refuses it), the pc7 (its propwash terms read the windmilling propeller's thrust
    # coefficient, -0.30 engine off, and cancel most of its pitch stiffness), the DHC6 (Cl_beta an
    # even table in beta, Cn_beta negative below zero alpha, CmT on the windmilling thrust) and
    # the L17 (its FCS reads fcs/flaps-pos-deg, which does not exist: JSBSim 1.3.3 cannot
    # initialise it). Surfaces from its <flight_control> (aerosurface_scale, zero-centred):
    # elevator -0.35..+0.30 rad, left aileron +-0.35 rad (the only aileron property the
    # aerodynamics read), rudder +-0.35 rad; the elevator's command scale is the mean of its two
    # ends (as the c182's). Signs read from its aerodynamics: Cmde -1.12 (Mach 0) * elevator-pos
    # (positive = trailing edge down), Clda +0.181 (Mach 0) * left-aileron-pos (positive = left trailing edge
    # down, roll right), Cndr -0.0365 * rudder-pos (positive = trailing edge left, nose left);
    # checked on the truth by tests/jsbsim/test_jsbsim_roster.py (used since the eighth session's final evaluation).
    # Gear up (retractable; its gear-down terms, CDgear, DCYbdf, DClrDg and the |beta| term DCnbDg, vanish with it).
    # Engines off: the "direct" thrusters give no force. 130 kt CAS at 10000 ft: the sweep's slowest level, 97.5 kt,
    # is 1.28 times the model's power-off stall (about 76 kt EAS: 4756 lb, CL_max 1.34 at 0.26 rad
    # from its CLalpha table); the glide sinks about 12 m/s (L/D about 6), so it starts at 10000 ft
    # to end a 120-s flight well above the ground. Elevator 4.5 deg (the c172x's 3 deg gave 1.7
    # deg/s of pitch-rate standard deviation and 1.0 deg of elevator in the standard light
    # flights: Cmq -50 and Iyy 8135 kg m^2 damp it; 4.5 deg gave 2.6 deg/s), aileron 5 deg, rudder
    # 6 deg (Cndr -0.0365 against Cn_beta 0.11: a third of a degree of sideslip per degree).
    # Default gains. Set from the harness's truth only (alpha, beta, rates,
    # excitation per axis; docs/jsbsim.md), never from a method result.
    "t37": AircraftSpec(
        name="t37", model="T37", airspeed_kts=150.0, altitude_ft=12000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.325, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.5, 5.0, 6.0), pulse_s=(0.7, 0.8, 1.0), gear_up=True,
        notes="Cessna T-37 (JSBSim T37), engines shut down, gear up, gliding; untouched by any tuning of the method"),
    # t6: JSBSim's stock Raytheon T-6A Texan II (t6texan2.xml, "Aeromatic / David Culp"), a
    # single-turboprop tandem trainer. Chosen after the candidates in docs/jsbsim.md ("The t6"):
    # T38 (its aerodynamics read the normalised surfaces, its FCS has a yaw damper, no aileron yaw),
    # A4 (Ixx + Izz < Iyy: not a physical tensor), f104, dr1, fokker50 (JSBSim 1.3.3 cannot
    # initialise them), p51d and Camel (propwash / induced-velocity and gyroscopic terms of the
    # propeller), OV10 (its windmilling-propeller drag, 0.07 at idle, makes a 30-deg dive of the
    # glide at the speeds the sweep needs), f15 (Cl_beta -0.057 at alpha 0 and tables with kinks at
    # alpha 0). Its engine drives a "direct" thruster: no force once stopped, no propeller.
    # Surfaces from its <flight_control> (aerosurface_scale, gain 0.017 / 0.01745 rad per deg):
    # elevator +-30 x 0.017 = +-0.51 rad, left aileron -20..+15 x 0.017 = -0.34..+0.255 rad (the only
    # aileron property the aerodynamics read; the right the mirror), rudder +-25 x 0.01745 =
    # +-0.436 rad; the aileron's command scale is the mean of its two ends (as the c182's). Signs
    # read from its aerodynamics: CmDe -1.2 x elevator-pos (positive = trailing edge down), Clda
    # +0.29 x left-aileron-pos (positive = left trailing edge down, roll right), Cndr -0.06 x
    # rudder-pos (positive = trailing edge left, nose left); checked on the truth by
    # tests/jsbsim/test_jsbsim_roster.py. Gear up (retractable; CDgear 0.03 vanishes with it). 160 kt
    # (ic/vc-kts) at 10000 ft: about 190 kt EAS, 2.3 x the model's power-off stall (83 kt EAS: 6000
    # lb, CL_max 1.47 at 0.28 rad), as the t37's 2.35: the sweep's slowest level flies 133 kt EAS
    # (1.6 x) and alpha stays under 4 deg, so Cl:alpha*beta = 3 (which reverses the stock Cl_beta
    # -0.086 above 1.7 deg of alpha) flies without a knock-it-off. It sinks 13 m/s (L/D about 8).
    # Amplitudes: elevator 4 deg (pitch-rate standard deviation 3.1 deg/s, standard plan, light),
    # aileron 4 deg (its roll is lively: Clda 0.29, Clp -0.5, Ixx 6483 kg m^2; roll-rate standard
    # deviation 8.2 deg/s), rudder 3.5 deg (its weathercock stability is weak, Cn_beta 0.04 against
    # Cndr -0.06: 1.5 deg of sideslip per degree; 3 deg gave 1.0 deg of rudder standard deviation).
    # Default gains. Set from the harness's truth only (alpha, beta, rates, excitation per axis;
    # docs/jsbsim.md), never from a method result.
    "t6": AircraftSpec(
        name="t6", model="t6texan2", airspeed_kts=160.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.51, 1.0 / 0.2975, 1.0 / 0.43625),
        amplitude_deg=(4.0, 4.0, 3.5), pulse_s=(0.7, 0.8, 1.0), gear_up=True,
        notes="Raytheon T-6A Texan II (JSBSim t6texan2), engine shut down, gear up, gliding; untouched by any tuning "
              "of the method"),
    # b747: JSBSim's stock Boeing 747 (B747.xml, author "Unknown", 2002; an Aeromatic-style model of
    # constant derivatives and a few tables), four turbofans on "direct" thrusters (no force once
    # stopped). Chosen in the tenth session after the candidates in docs/jsbsim.md ("The b747"):
    # f22, L410, 787-8, Concorde (Ixx + Iyy < Izz or Ixx + Izz < Iyy: not a physical tensor), f16
    # (fly-by-wire: PID g and roll-rate laws between the commands and the surfaces), X15 and x24b
    # (pitch, roll and yaw stability augmentation in their FCS; the x24b's Cl_beta is zero at
    # alpha 0), f15 (flown: a lift-to-drag ratio of at most 6.5 and Mach tables with columns at 0.5
    # and 1.4 only; the glide dived to 60 deg of pitch), XB-70 (the same aerodynamics as this
    # model, with the reference point 54 ft ahead of the CG: Cm_alpha +2.6 per rad at the CG),
    # F4N, F80C, A320 (each also without aileron yaw or a second side-force term, and weaker: Cl_beta
    # -0.05, -0.1 and -0.03 per rad, Cm_alpha -0.22, -0.29 per rad at the CG, the F80C's rudder a
    # fifth of this one's, and yaw dampers as well), B17, C130,
    # Boeing314, Short_S23 (propellers that windmill once the engines stop; seaplanes), J246 (a
    # launch vehicle). Surfaces from its <flight_control> (aerosurface_scale, zero-centred):
    # elevator -0.35..+0.175 rad, left aileron +-0.35 rad (the only aileron property the
    # aerodynamics read; the right the mirror), rudder +-0.35 rad. The elevator's command scale is
    # its larger end (0.35 rad), so that the airframe file's servo ends (+-20.05 deg) cover every
    # deflection flown (the sweep reaches -18 deg, trailing edge up; the mean end, 15 deg, would
    # clip the logged PWM); a positive command then moves it half as far as a negative one. Signs
    # read from its aerodynamics: Cmde -1.3 + 0.4875 Mach x elevator-pos (positive = trailing edge
    # down), Clda +0.1 - 0.0335 Mach x left-aileron-pos (positive = left trailing edge down, roll
    # right), Cndr -0.1 x rudder-pos (positive = trailing edge left, nose left); checked on the
    # truth by tests/jsbsim/test_jsbsim_roster.py. Gear up (retractable; CDgear 0.011 vanishes with
    # it). Its FCS has a yaw damper (2 x r-aero in normalised rudder per rad/s, clipped to +-0.2,
    # i.e. 0.7 rad of rudder per rad/s up to 4 deg) that the harness cannot switch off, so the
    # harness's own yaw damper is off (k_r = 0): the model's replaces it. 260 kt (ic/vc-kts) at
    # 10000 ft: 305-325 kt EAS, Mach 0.53-0.54, 2 x the model's power-off stall (about 155 kt EAS at
    # 551098 lb, CL_max 1.2 at 0.23 rad); alpha stays within -5..7 deg in the sweep, so Cl:alpha*beta = 3
    # (which reverses the stock Cl_beta -0.1 above 1.9 deg) flies without a knock-it-off. It sinks
    # 15-17 m/s (L/D about 11). Gains: the pitch loop of a 250-t aircraft at 180 m/s (k_theta
    # 0.8, k_q 0.8: with the default 1.0 / 0.3 the sweep's first level put it into a pitch
    # oscillation of +30..-80 deg with the elevator on its stops) and a speed gain k_v of 0.004 rad per
    # m/s (the default 0.01 turns the sweep's 45-m/s speed steps into 0.45 rad of pitch); roll
    # k_phi 1.0, k_p 0.4 (its aileron rolls it far more slowly than the t6's: 1.9 deg/s of roll-rate
    # standard deviation with 8 deg of aileron, the t6 8.3 with 4; with the default roll gains the
    # sweep banked past 70 deg). Amplitudes: elevator 4 deg (+2 / -4 deg of surface: pitch-rate
    # standard deviation 0.9 deg/s, standard plan, light), aileron 8 deg (roll rate 1.9 deg/s),
    # rudder 5 deg (yaw rate 0.8 deg/s, sideslip under 4.4 deg). Set from the harness's truth only
    # (alpha, beta, rates, excitation per axis; docs/jsbsim.md), never from a method result.
    "b747": AircraftSpec(
        name="b747", model="B747", airspeed_kts=260.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.0, 8.0, 5.0), pulse_s=(0.7, 0.8, 1.0), gains=(0.8, 0.8, 0.004, 1.0, 0.4, 0.0), gear_up=True,
        notes="Boeing 747 (JSBSim B747), engines shut down, gear up, gliding; untouched by any tuning of the method"),
    # f16: JSBSim's stock F-16A (f16.xml, Erik Hofman 2001, tables from Nguyen et al., NASA TP-1538,
    # 1979), flown as a derived model, ``f16_direct`` (benchmarks/jsbsim_harness/derived.py): the
    # only aircraft whose flight control was replaced. Its fly-by-wire (roll-rate and g-command PID
    # laws, alpha limiter, yaw PID, leading-edge flaps switched on alpha, flaperons) is replaced by a
    # direct map of the commands to the surfaces the aerodynamics read: elevator +-0.436 rad
    # (``fcs/elevator-pos-rad``, the tables' horizontal-tail deflection), aileron +-0.375 rad
    # (``fcs/aileron-pos-rad``, the only aileron property the aerodynamics read), rudder +-0.524 rad;
    # leading-edge flap and flaperon-mix fixed at 0 (the log has no flap channel); aerodynamics,
    # mass, inertia and propulsion are the wheel's. Chosen in the eleventh session after the stock
    # fixed-wing list was used up (docs/jsbsim.md, "The f16"): relaxing the rule "no FCS law between
    # the commands and the surfaces" once. Signs read from its aerodynamics: CmDh decreases with
    # elevator-pos (positive = trailing edge down), Clda +0.05 x aileron-pos (positive = right roll,
    # left trailing edge down: delta_a = -aileron-pos), Cndr -0.045 x rudder-pos (positive = trailing
    # edge left, nose left). Static stability about the CG, in JSBSim (fixed surfaces, run_ic, 260 kt):
    # Cm_alpha -0.026 per rad between alpha 0 and 4 deg and -0.079 between 4 and 8 (the pilot and
    # 3000 lb of wing fuel put the CG 2.4 in ahead of the reference point): relaxed, but stable.
    # Gear up (CDgear 0.027 vanishes). Engine off ("direct" thruster: no force once stopped).
    # 212 kt (ic/vc-kts) at 15000 ft: 168 m/s TAS, Mach 0.52; the sweep flies 124-190 m/s, Mach
    # 0.38-0.57, under the Mach tables' first breakpoint (0.6, where Cma_M, Clb_M, Cnb_M, Clda_M
    # start), alpha -4..10 deg (the tables' rows every 5 deg from -10). It sinks 19-22 m/s (a
    # lift-to-drag ratio of about 7-8), so it starts at 15000 ft. Gains: k_q 0.6 (the pitch damping
    # of a relaxed-stability airframe; with 0.3 `Cm:alpha^2` = -8 pitched it down past -26 deg of
    # alpha with the elevator on its stop), k_v 0.003 (the default 0.01 turned the sweep's 60-m/s
    # speed steps into 0.5-0.8 rad of pitch reference: the first trial dived to -84 deg). Amplitudes:
    # elevator 4 deg (pitch-rate standard deviation 2.7 deg/s in the standard plan, light; 3 deg gave
    # 2.0 and 1.04 deg of elevator standard deviation; with k_q 0.3, 4 deg gave 5.1 deg/s and alpha
    # -5..10 in the sweep), aileron 5 deg (roll rate 6.5 deg/s: Clda 0.05 against Ixx 9496 slug
    # ft^2), rudder 6 deg (yaw rate 1.7 deg/s, sideslip under 3.5 deg: Cndr -0.045 against Cnb 0.21).
    # Set from the harness's truth only (alpha, beta, rates, excitation per axis), never from a
    # method result. The notes carry the derived XML's SHA-256 (16 hex digits), so that the
    # derivation is part of this aircraft's fingerprint.
    "f16": AircraftSpec(
        name="f16", model="f16_direct", airspeed_kts=212.0, altitude_ft=15000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.436, 1.0 / 0.375, 1.0 / 0.524),
        amplitude_deg=(4.0, 5.0, 6.0), pulse_s=(0.7, 0.8, 1.0), gains=(1.0, 0.6, 0.003, 0.4, 0.1, 0.4), gear_up=True,
        notes="General Dynamics F-16A (JSBSim f16) with its fly-by-wire replaced by direct surfaces, flaps fixed "
              "(derived model f16_direct, XML sha256 c58370508ab7d631), engine shut down, gear up, gliding; "
              "untouched by any tuning of the method"),
    # f4n: JSBSim's stock McDonnell F-4N Phantom II (F4N.xml, Aeromatic v0.9 / David Culp, 2007: a
    # model of constant derivatives and a few tables, as the b747's), two J79 turbojets on "direct"
    # thrusters (no force once stopped), one fuel tank of 13000 lb on the centre line, no point mass,
    # no product of inertia. Loaded as the derived model ``F4N_fcs`` (derived.py): the stock XML with an
    # empty <flight_control> added where its own is commented out, because effects.py's delay:delta_e
    # adds its channel to that element (the first pre-fly failed there); JSBSim computes the same
    # forces and moments (test). Chosen in the twelfth session (docs/jsbsim.md, "The f4n") with the rule
    # "no FCS law between the commands and the surfaces" relaxed as for the b747: its FCS
    # (systems/FCS-pitch.xml, FCS-roll.xml, FCS-yaw.xml) maps the commands straight to the surfaces
    # (aerosurface_scale, zero-centred: elevator -0.35..+0.30 rad, left aileron +-0.35 rad, the only
    # aileron property the aerodynamics read, rudder +-0.25 rad) and adds a yaw damper, 2 x r-aero in
    # normalised rudder per rad/s (above 60 kt EAS), clipped to +-0.1 (0.025 rad of rudder), that the
    # harness cannot switch off: the harness's own yaw damper is off (k_r = 0), the model's replaces
    # it, and the logged rudder (fcs/rudder-pos-rad, what Cndr and Cldr read) includes it. The
    # elevator's command scale is its larger end (0.35 rad, the b747's rule). Signs read from its
    # aerodynamics: Cmde (-0.70 + 0.25 Mach) x elevator-pos (positive = trailing edge down), Clda
    # (0.12 - 0.04 Mach) x left-aileron-pos (positive = left trailing edge down, roll right), Cndr
    # -0.08 x rudder-pos (positive = trailing edge left, nose left). Static stability about the CG
    # (JSBSim, fixed surfaces, run_ic): Cm_alpha -0.23 per rad. Gear up (CDgear 0.028 vanishes).
    # 250 kt (ic/vc-kts) at 15000 ft: 305 kt EAS, 198 m/s TAS, Mach 0.61 at the start; the sweep flies
    # 147-214 m/s, alpha -5.3..6.9 deg. It sinks 28-31 m/s (lift-to-drag about 6-7: CD0 0.021 and
    # CDi 0.14 CL^2 at CL 0.2-0.3). Trial sets on the truth (docs/jsbsim.md): at 230 kt the pair
    # (Cm:alpha^2 = -8 with Cn:delta_a) took the elevator to -19.9 deg of its -20 at the slow level,
    # hence 250 kt (-16.4 deg); at 18000 ft the speed steps took alpha to -9 deg with the pair, hence
    # 15000 ft. Gains: k_q 0.6, k_v 0.003 (the f16's: gentle push-overs of the speed steps); roll
    # k_phi 1.0, k_p 0.3 (with the default 0.4 / 0.1 the sweep with Cl:alpha*beta = 3, which reverses
    # its Cl_beta -0.05 above 1 deg of alpha, banked past 45 deg: a knock-it-off). Amplitudes:
    # elevator 4 deg, aileron 5 deg, rudder 3 deg (5 deg flew 8 deg of sideslip and 4.3 deg/s of
    # yaw-rate standard deviation in the standard plan: Cnb 0.12 against Cndr -0.08). Set from the
    # harness's truth only (alpha, beta, rates, excitation per axis), never from a method result.
    "f4n": AircraftSpec(
        name="f4n", model="F4N_fcs", airspeed_kts=250.0, altitude_ft=15000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.25),
        amplitude_deg=(4.0, 5.0, 3.0), pulse_s=(0.7, 0.8, 1.0), gains=(1.0, 0.6, 0.003, 1.0, 0.3, 0.0), gear_up=True,
        notes="McDonnell F-4N Phantom II (JSBSim F4N), its own yaw damper in the loop, flown as the derived model "
              "F4N_fcs (the stock XML with an empty flight_control added, XML sha256 546ac6c12a62200c), engines shut "
              "down, gear up, gliding; untouched by any tuning of the method"),
    # rascal: ArduPilot's SITL Rascal 110 (Tools/autotest/aircraft/Rascal/Rascal110-JSBSim.xml, based on
    # FlightGear's Rascal110; GPL-3.0 as ArduPilot), a 14.5-lb, 2.8-m-span radio-controlled trainer: the
    # first aircraft from outside the jsbsim wheel and the first of a UAV's size. Its XML is checked in
    # (data/jsbsim_models/rascal/, provenance and licence in its README.md) and flown as the derived
    # model ``Rascal110_glide`` (derived.py): the engine and its 18x8 propeller removed, so that the glide
    # has no windmilling propeller (the rule that rejected the p51d, B17 and C130); everything else is
    # the file's. Chosen in the thirteenth session (docs/jsbsim.md, "The rascal") after the 737 (the
    # wheel's last unscreened model: the b747's term set with a yaw damper in the loop) and the F80C
    # (a rudder a quarter of the F4N's). A direct FCS (aerosurface_scale, no damper or augmentation):
    # elevator -0.35..+0.30 rad, left aileron +-0.35 rad (the only aileron property the aerodynamics
    # read; the right the mirror), rudder +-0.35 rad; the elevator's command scale is its larger end
    # (0.35 rad, the b747's rule). Signs read from its aerodynamics: Cmde (-0.5 + 0.1125 Mach) x
    # elevator-pos (positive = trailing edge down), Clda (0.13 - 0.0365 Mach) x left-aileron-pos
    # (positive = left trailing edge down, roll right), Cndr -0.05 x rudder-pos (positive = trailing edge
    # left, nose left); Cnda -0.03 x left-aileron-pos (adverse yaw: Cn_delta_a +0.03 in the project's
    # sign), Cndi 0.0007 (a constant yawing moment). Fixed gear (no gear terms). 34 kt (ic/vc-kts) at
    # 6000 ft: 20.3-21.3 m/s TAS in the standard flights, 2.2 x the power-off stall (about 8.8 m/s EAS:
    # 14.5 lb, CL_max 1.4 at 0.23 rad); the sweep flies 16.5-23 m/s and alpha -1..4.5 deg. It sinks
    # 1.6-2.2 m/s (lift-to-drag about 10). Pulses 0.4 / 0.5 / 0.5 s: its modes are about twice as fast
    # as the light aircraft's (short period and Dutch roll near 6 rad/s from its Cm_alpha about -0.8,
    # Cnb 0.12 and inertia; roll mode 6.6 per s), and a doublet's best pulse is about 2.3 / omega_n.
    # Amplitudes: elevator 4 deg (3 deg gave 0.84 deg of elevator standard deviation at 40 kt, under the
    # envelope test's 1-deg floor), aileron 5 deg, rudder 6 deg (Cndr -0.05 against Cnb 0.12: 0.4 deg of
    # sideslip per degree). Trial speeds (truth only): 40 kt flew alpha -1.4..2.2 deg in the sweep
    # (too little span for alpha^2 and alpha*beta), 36 kt -1.1..3.4; 34 kt keeps the elevator at -17.1
    # deg at worst (delay:delta_e = 0.12) of its -20.05. Default gains. Set from the harness's truth only
    # (alpha, beta, rates, excitation per axis), never from a method result. The notes carry the derived
    # XML's SHA-256 (16 hex digits), so that the checked-in XML and the derivation are part of this
    # aircraft's fingerprint.
    "rascal": AircraftSpec(
        name="rascal", model="Rascal110_glide", airspeed_kts=34.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.0, 5.0, 6.0), pulse_s=(0.4, 0.5, 0.5),
        notes="ArduPilot SITL Rascal 110 (JSBSim Rascal110-JSBSim.xml, checked in under data/jsbsim_models/rascal) "
              "with its engine and propeller removed (derived model Rascal110_glide, XML sha256 7bc358774d2412a5), "
              "gliding; untouched by any tuning of the method"),
    # sgs126: JSBSim's stock Schweizer SGS 1-26 (sgs126.xml, author "Unknown"; an Aeromatic-style model of
    # constant derivatives and a few tables), a single-seat glider: 445 lb (no pilot or point mass), 40-ft
    # span, 160 ft^2 (wing loading 2.8 lb/ft^2, the lightest of the roster but the rascal's), no propulsion
    # at all (no engine, no propeller, nothing to stop). Chosen in the fourteenth session
    # (docs/jsbsim.md, "The sgs126") after the wheel's three jets no session had screened: fokker100
    # (JSBSim 1.3.3 cannot initialise it: its pushback system reads FlightGear's
    # /sim/model/pushback/position-norm; else the b747's term set with a yaw damper in the loop and its
    # rudder command clipped at 0.35), global5000 and MD11 (Ixx + Iyy < Izz in JSBSim: not a physical
    # tensor); a jet's 10-15 m/s of sink cannot glide 135 s below 4000 ft anyway, and a glider can fly
    # where JSBSim's light turbulence
    # is active: MIL-F-8785C's light curve (JSBSim's Milspec table) falls to zero at 7500 ft, so the
    # f16's light flights at 15000 ft were calm and the rascal's at 6000 ft had 0.2 m/s of vertical gust;
    # at 3000 ft the sgs126's light flights have 0.5 m/s (truth: total wind less the steady wind).
    # A direct FCS (aerosurface_scale, zero-centred, no damper): elevator -0.35..+0.30 rad, left
    # aileron +-0.35 rad (the only aileron property the aerodynamics read; the right the mirror),
    # rudder +-0.35 rad; the elevator's command scale is its larger end (0.35 rad, the b747's rule).
    # Signs read from its aerodynamics: Cmde (-0.8 + 0.3 Mach) x elevator-pos (positive = trailing edge
    # down), Clda (0.06 - 0.02 Mach) x left-aileron-pos (positive = left trailing edge down, roll
    # right), Cndr -0.03 x rudder-pos (positive = trailing edge left, nose left); Cnda -0.02 x
    # left-aileron-pos (adverse yaw: Cn_delta_a +0.02 in the project's sign, two thirds of its rudder's
    # power). Its gear is left down as the model has it (its one gear term, CDgear 0.001 x
    # gear-pos-norm, is then a constant). 45 kt (ic/vc-kts) at 3000 ft: 24.6-26.8 m/s TAS in the standard light
    # flights, 2 x the stall (about 12.5 m/s EAS: CL_max 1.4 at 0.21 rad); the sweep flies 19.3-28 m/s
    # (1.55 x the stall at its slowest) and alpha -0.7..4.7 deg. It sinks 0.8-1.5 m/s (lift-to-drag
    # about 28: CD0 0.01, CDi 0.023 CL^2), so a 135-s flight from 3000 ft ends above 700 m.
    # Pulses 0.7 / 0.8 / 1.3 s: its short period is fast and well damped (about 4 rad/s: Cmalpha
    # -0.5, Cmq -9, Cmadot -12 with a heavy lift slope per unit mass), its Dutch roll slow (about
    # 1.7 rad/s: Cnb 0.12 against Izz 2309 kg m^2), and a doublet's best pulse is about 2.3 / omega_n.
    # Amplitudes: elevator 4 deg (Cmde -0.8 against Cmalpha -0.5: a degree of elevator holds 1.6 deg
    # of alpha; 3 deg gave 1.23-1.28 deg of elevator standard deviation and alpha 0.3..2.2 deg, 1st-99th
    # percentile, in the standard light flight; 4 deg -0.1..2.4), aileron 8 deg (Clda 0.06, a weak
    # aileron: 10 deg took it to 19.5 deg of its 20 with Cl:alpha*beta = 3, which reverses its Clb -0.1
    # above 1.9 deg of alpha; 8 deg to 17.5), rudder 8 deg (Cndr -0.03 against Cnb 0.12: a quarter of a
    # degree of sideslip per degree). Default gains. Set from the harness's truth only (alpha, beta,
    # rates, excitation per axis, gusts), never from a method result.
    "sgs126": AircraftSpec(
        name="sgs126", model="sgs126", airspeed_kts=45.0, altitude_ft=3000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.0, 8.0, 8.0), pulse_s=(0.7, 0.8, 1.3),
        notes="Schweizer SGS 1-26 glider (JSBSim sgs126), flown at 3000 ft in JSBSim's light turbulence; "
              "untouched by any tuning of the method"),
    # asw20: FlightGear's ASW 20 sailplane (FGMEMBERS/asw20 Models/JSBSim/asw20-JSBSim.xml at 3ef71d9c, D-NXKT's
    # 2013 conversion of Michael Selig's UIUC ASW 20; GPL-2.0-or-later), a 15-m-class single-seat sailplane: 728.7 lb,
    # 49.2-ft span, 113 ft^2 (wing loading 6.4 lb/ft^2), no propulsion. The second aircraft from outside the wheel;
    # its XML is checked in (data/jsbsim_models/asw20/, provenance and licence in its README.md) and flown as the
    # derived model ``asw20_glide`` (derived.py): FlightGear's GenericEngine and WaterBallast systems and its Water
    # Dumping channel removed (JSBSim alone cannot initialise it with them), the tail's CmDe table reading the
    # elevator through an alias of fcs/elevator-pos-rad (so that delay:delta_e reaches it). Chosen in the
    # fifteenth session (docs/jsbsim.md, "The asw20") after the DG-101G (its XFLR5 tables jump at 2 deg of sideslip:
    # CY -0.012, -0.089, -0.015 per 1, 2, 3 deg, and Cm steps by 0.06 from beta 0 to 1 deg) and the Bocian (YASim).
    # A full lateral set: CYb, CYp, CYr, CYDa, CYDr, Clb, Clp, Clr, Clda, ClDr, Cnb, Cnp, Cnr,
    # Cnda, CnDr, plus CLq and CLadot. A direct FCS (aerosurface_scale, no damper): elevator -0.436..+0.384 rad,
    # left and right aileron both -0.436 x the command (the file's gain -1; the aerodynamics read the left
    # alone, Clda -0.214 x left: a positive left-aileron-pos-rad rolls it left, so delta_a = +left and the
    # aileron's command scale is negative), rudder 31 x 0.01745 = 0.541 rad x the command; the elevator's
    # command scale is its larger end (the b747's rule). Signs read from its aerodynamics: CmDe (a 3-D table,
    # -0.786 per rad at alpha -2 deg) x elevator (positive = trailing edge down, nose down), Clda -0.214 x left
    # (Cl_delta_a -0.214), CnDr -0.041 x rudder (positive = trailing edge left, nose left); Cnda -0.017 x left
    # (Cn_delta_a -0.017: proverse, the file's comment "different sign in UIUC??"). Gear up (its one gear term
    # CDDg 0.005 x gear-pos-norm); flaps at the file's default, -11 deg (CLDf -0.19, a constant). 65 kt (ic/vc-kts)
    # at 3000 ft (the sgs126's altitude, in JSBSim's light turbulence): 32.5-41 m/s TAS and alpha about -2 deg in
    # the standard flights, where its CL table is linear (no breakpoint between -16.7 and +2.28 deg; the lift slope
    # falls from 5.7 to 4.3 per rad above); the sweep flies 24.6-42 m/s and alpha -4.8..4.9 deg. Its Cm has a
    # break at alpha 0 (the Cmalpha table's slope +0.62 below, +0.37 above; JSBSim's static Cm_alpha -1.14 and
    # -1.38 per rad). Pulses 0.5 / 0.6 / 0.9 s: short period about 4.6 rad/s (M_alpha -13 per s^2 at 35 m/s,
    # Cmq -24), Dutch roll about 2.5 rad/s (Cnb 0.1 against Izz 1757 kg m^2), a doublet's best pulse about
    # 2.3 / omega_n. Amplitudes 3 / 5 / 6 deg: 1.5-1.6 deg of elevator standard deviation in the standard light
    # flights (the envelope test's floor is 1), surfaces at most -9.8..+9.9, 11 and 10.2 deg of their 25, 25 and
    # 31 in the trial flights. Default gains. Set from the harness's truth only (alpha, beta, rates, excitation
    # per axis, surfaces, sink), never from a method result; the first set-up tried passed (docs/jsbsim.md).
    "asw20": AircraftSpec(
        name="asw20", model="asw20_glide", airspeed_kts=65.0, altitude_ft=3000.0,
        elevator_sign=1.0, aileron_sign=1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.43633, -1.0 / 0.43633, 1.0 / (31.0 * 0.01745)),
        amplitude_deg=(3.0, 5.0, 6.0), pulse_s=(0.5, 0.6, 0.9), gear_up=True,
        notes="ASW 20 sailplane (FlightGear's JSBSim asw20-JSBSim.xml, checked in under data/jsbsim_models/asw20) "
              "without FlightGear's engine and ballast systems (derived model asw20_glide, XML sha256 "
              "f9ca126483a12dcc), gear up, gliding; untouched by any tuning of the method"),
    # iar80: FlightGear's JSBSim IAR-80 (FGMEMBERS/IAR-80-JSB IAR80-Jsb.xml at 6d011335, Aeromatic v0.95, 2015;
    # GPL-2.0-or-later), the Romanian 1939 single-seat monoplane fighter: 6170.8 lb (4850 empty, a 459.2-lb payload
    # and 861.6 lb of fuel, all at the CG), 36-ft span, 183 ft^2 (wing loading 33.7 lb/ft^2), retractable gear. The
    # third aircraft from outside the wheel and the first powered one since the rascal; its XML is checked in
    # (data/jsbsim_models/iar80/, provenance and licence in its README.md) and flown as the derived model
    # ``IAR80_glide`` (derived.py): its engine and propeller removed (their files are not in the repository but as an
    # editor's backup), its fuel tanks kept as mass. Chosen in the sixteenth session (docs/jsbsim.md, "The iar80")
    # after the Bergfalke (YASim), the ASK 21 (no licence file; a FlightGear property in its Cm_q term), the Jabiru
    # J170 (the c172p's aerodynamics; its FCS reads fcs/*-pos-output, which nothing in JSBSim writes), the DHC-2
    # (YASim), the Skywalker X8 (no rudder) and two UAV models without a licence. A direct FCS (aerosurface_scale,
    # zero-centred, no damper): elevator, left and right aileron (the right the same sign as the left; the
    # aerodynamics read the left alone) and rudder all +-0.35 rad x the command. Signs read from its aerodynamics:
    # Pitch_elevator (-1 + 0.375 Mach) x elevator-pos (positive = trailing edge down), Roll_aileron +0.18 x
    # left-aileron-pos (positive = roll right: Cl_delta_a -0.18), Yaw_rudder -0.1 x rudder-pos (positive = trailing edge
    # left, nose left); Yaw_aileron -0.003 x left (adverse: Cn_delta_a +0.003). Gear up (Drag_gear 0.03 x
    # gear-pos-norm). 150 kt (ic/vc-kts) at 10000 ft: 98-110 m/s TAS in the standard trial flights, alpha -2..4 deg
    # (1st-99th percentile); the sweep flies 69-130 m/s, 1.3 x the stall at its slowest (about 45 m/s EAS: CL_max 1.3 at
    # 0.23 rad). Its CL table has a break at alpha 0 (5.5 per rad below, 4.48 above), which the sweep crosses. It
    # sinks 9.6-11 m/s (lift-to-drag about 10), so a 135-s flight from 10000 ft ends above 1500 m; MIL-F-8785C light
    # turbulence moves the air there (vertical gust 2.1-2.2 m/s standard deviation). Pulses 0.7 / 0.8 / 0.8 s: short
    # period about 3.2 rad/s (Cm_alpha -0.5, Cmq -15, Iyy 4104 slug ft^2), Dutch roll about 2.9 rad/s (Cnb 0.12
    # against Izz 7016 slug ft^2), roll mode about 3.4 per s. Amplitudes 4 / 4 / 4 deg: 3 deg gave 0.94 / 1.01 /
    # 0.87 deg of surface standard deviation in the standard light flight (the envelope test's floor is 1); with 4
    # deg 1.1-2.5 deg in every trial flight, surfaces at most -10.7..+10.4, 7.5 and 5.5 deg of their 20. Default
    # gains. Set from the harness's truth only (alpha, beta, rates, excitation per axis, surfaces, sink), never from
    # a method result.
    "iar80": AircraftSpec(
        name="iar80", model="IAR80_glide", airspeed_kts=150.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.0, 4.0, 4.0), pulse_s=(0.7, 0.8, 0.8), gear_up=True,
        notes="IAR-80 fighter (FlightGear's JSBSim IAR80-Jsb.xml, checked in under data/jsbsim_models/iar80) with its "
              "engine and propeller removed (derived model IAR80_glide, XML sha256 2025fa83c41f3f74), gear up, "
              "gliding; untouched by any tuning of the method"),
    # c684: FlightGear's JSBSim Caudron C.684 Super Rafale (FGMEMBERS/C684 C684.xml at 05ad4b2c, Guillaume Chauvat
    # 2008, version 0.4.13; GPL-2.0-or-later), a 1930s French two-seat racing and touring monoplane: 2138.5 lb as
    # loaded (640 kg empty, pilot and passenger 85 kg each on the centre line, 80 kg of fuel in each of two tanks
    # 0.2 m either side of it), 7.70-m span, 9.00 m^2 (wing loading 22 lb/ft^2, aspect ratio 6.6), fixed tailwheel
    # gear. The fourth aircraft from outside the wheel; its XML is checked in (data/jsbsim_models/c684/, provenance
    # and licence in its README.md) and flown as the derived model ``C684_glide`` (derived.py): its engine, propeller
    # and engine system removed, the gear's 2008 ``FIXED`` flags written 0 for JSBSim 1.3.3. Chosen in the
    # seventeenth session (docs/jsbsim.md, "The c684") as the one screened model whose aerodynamics are not an
    # Aeromatic template: a hand-made CL table on aero/alpha-wing-rad (0.043-rad incidence), Cl_beta, Cl_p and
    # Cl_delta_a tables in alpha, an adverse yaw proportional to the lift (Cnda = -0.008 x CL x left aileron), a
    # constant Cl0 (-0.0011); its file's Cmalpha -2.3 (on alpha-wing) is -0.87 about the loaded CG, 0.287 m aft of
    # the aerodynamic reference point (Cmde -1.3, Cmq -15, Cmadot -8). Its FCS
    # is direct but unequal: elevator -0.35 (trailing edge up) / +0.30 rad, aileron 20 / 15 deg (the right the
    # mirror of the left; the aerodynamics read the left alone), rudder +-20 deg; ``cmd_per_rad`` takes the larger
    # side of each (so the airframe's ends cover every deflection; the autopilot flies either side, the log carries
    # JSBSim's surface positions). Signs read from its aerodynamics: Cmde -1.3 x elevator-pos (positive = trailing
    # edge down), Clda +0.12 x left-aileron-pos (positive = roll right: Cl_delta_a -0.12), Cndr -0.065 x
    # rudder-pos (positive = trailing edge left, nose left). Set from the harness's truth only (alpha, beta, rates,
    # excitation per axis, surfaces, sink), never from a method result.
    "c684": AircraftSpec(
        name="c684", model="C684_glide", airspeed_kts=125.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / (20.0 * 0.01745), 1.0 / (20.0 * 0.01745)),
        amplitude_deg=(3.0, 4.0, 4.0), pulse_s=(0.5, 0.8, 0.8),
        notes="Caudron C.684 racer (FlightGear's JSBSim C684.xml, checked in under data/jsbsim_models/c684) with its "
              "engine, propeller and engine system removed (derived model C684_glide, XML sha256 4d332e34ee7966d7), "
              "fixed gear, gliding; untouched by any tuning of the method"),
    # ultrastick: the University of Minnesota UAS Lab's JSBSim Ultra Stick 120 (UASLab/OpenFlightSim
    # Simulation/aircraft/UltraStick120 at 1650a6e3; MIT), a 7.4-kg radio-controlled research UAV: 1.92-m span,
    # 0.786 m^2 (wing loading 9.4 kg/m^2), measured inertia with a product (Ixz 0.19 kg m^2), fixed gear. The fifth
    # model from outside the wheel and the first not from FlightGear or ArduPilot; its files are checked in
    # (data/jsbsim_models/ultrastick120/, provenance and licence in its README.md) and flown as the derived model
    # ``UltraStick120_glide`` (derived.py): its Metrics, Mass, Gear and Aero files assembled into one, no
    # propulsion, the lab's control laws, actuators and sensors replaced by direct surfaces (+-30 deg, the lab's
    # actuator limits). Chosen in the eighteenth session (docs/jsbsim.md, "The ultrastick"): its aerodynamics
    # are vortex-lattice (AVL) tables in alpha of every derivative of all six coefficients, each aileron with
    # its own tables (CL, CD, CY, Cl, Cm, Cn of each side). Signs read from its aerodynamics: dCMm/dElev -1.2
    # (positive = trailing edge down), dCMl/dAilL +0.11 and dCMl/dAilR -0.11 (each positive = trailing edge
    # down; the right is driven as the mirror of the left, so delta_a = -left: Cl_delta_a -0.22),
    # dCMn/dRud -0.04 (positive = trailing edge left, nose left). 45 kt (ic/vc-kts) at 10000 ft: 23-34 m/s TAS,
    # alpha about 0..6 deg in the standard flights (p1-p99), -2..8 in the sweeps; its drag (CD__zero 0.106) makes
    # the glide steep (lift-to-drag about 2, sink 13-16 m/s), hence the height. Pulses 0.3 / 0.4 / 0.5 s: short
    # period about 10 rad/s, roll mode about 9 per s, Dutch roll about 4 rad/s. Amplitudes 5 / 4 / 5 deg and gains
    # (0.25, 0.05, 0.01, 0.2, 0.05, 0.2): its control power per unit of qbar is about ten times the c684's, so the
    # default rate gains fought the maneuvers (surface standard deviation 0.6-0.7 deg); with k_theta 0.5 and k_q
    # 0.15 an injected 0.12-s elevator delay rolled it out of the envelope (seeds 1 and 2). Set from the harness's
    # truth only (alpha, beta, rates, excitation per axis, surfaces, sink), never from a method result.
    "ultrastick": AircraftSpec(
        name="ultrastick", model="UltraStick120_glide", airspeed_kts=45.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/posAilL_rad", "fcs/posAilR_rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.5235987755982988, 1.0 / 0.5235987755982988, 1.0 / 0.5235987755982988),
        amplitude_deg=(5.0, 4.0, 5.0), pulse_s=(0.3, 0.4, 0.5), gains=(0.25, 0.05, 0.01, 0.2, 0.05, 0.2),
        notes="Ultra Stick 120 UAV (UASLab OpenFlightSim JSBSim model, checked in under "
              "data/jsbsim_models/ultrastick120) without propulsion, direct surfaces (derived model "
              "UltraStick120_glide, XML sha256 df846fb42f873137), fixed gear, gliding; untouched by any tuning of the "
              "method"),
    # b737: JSBSim's stock Boeing 737 (737.xml, Dave Culp and Aeromatic, GPL in its header; the wheel's, flown
    # as it is), the nineteenth session's untouched aircraft. Chosen with one screening rule relaxed (docs/
    # jsbsim.md, "The b737"): its aerodynamics are the b747's term set function for function (the thirteenth
    # session set it aside as a near-copy), with other numbers (Cnb 0.26, Cnr -0.35, Cndr -0.20, Clb -0.09,
    # Clr 0.09, Cmalpha -0.6, Cmq -27, Cmadot -16, Clda and Cmde in Mach). Its own yaw damper (1.0 x r-aero
    # above Mach 0.11, in the rudder channel, not clipped short of the rudder's +-0.35 rad) stays in the loop,
    # as the b747's did: k_r 0. Both CFM56 on "direct" thrusters (no force once stopped), gear up.
    "b737": AircraftSpec(
        name="b737", model="737", airspeed_kts=250.0, altitude_ft=12000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.3, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(3.5, 6.0, 5.0), pulse_s=(0.7, 0.8, 1.0), gains=(0.8, 0.8, 0.004, 1.0, 0.4, 0.0), gear_up=True,
        notes="Boeing 737 (JSBSim 737), engines shut down, gear up, gliding, its own yaw damper in the loop; "
              "untouched by any tuning of the method"),
    # c172p: JSBSim's stock Cessna 172P (the wheel's c172p.xml, FlightGear's C172P model; flown as it is), the
    # twentieth session's untouched aircraft. Chosen with one screening rule relaxed (docs/jsbsim.md, "The c172p"):
    # its term set is the c172x's (tuning), with its own numbers where they differ: CYdr 0.187 (0.098), CYda 0
    # (-0.05), CYp and CYr tables in alpha (-0.075..-0.145, 0.214..0.267), Cnda -0.0053 (+0.0053), Cmadot -7.27
    # (-5.2), Cmde -1.122 (-1.28), CLDe 0.43 (0.347), CYb -0.39 per rad (-0.31); and its elevator and rudder moments
    # read a propeller-wash dynamic pressure (0.5 rho (u + 2 v_induced)^2: with the engine stopped, 0.5 rho u^2 on
    # the body-axis airspeed, not the total). Its FCS is direct but unequal: elevator -28 / +23 deg, aileron -20 /
    # +15 deg (the right the left's mirror), rudder +-16 deg; ``cmd_per_rad`` takes the larger side of each. Its
    # pilot (180 lb at y = -14 in) is emptied by the harness. 80 kt at 4000 ft, where MIL-F-8785C light turbulence
    # moves the air (the c172x's 6000 ft is nearly calm). Set from the harness's truth only (alpha, beta, rates,
    # excitation per axis, surfaces, sink), never from a method result.
    "c172p": AircraftSpec(
        name="c172p", model="c172p", airspeed_kts=80.0, altitude_ft=4000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / (28.0 * 0.01745), 1.0 / (20.0 * 0.01745), 1.0 / (16.0 * 0.01745)),
        amplitude_deg=(3.0, 5.0, 6.0), pulse_s=(0.7, 0.8, 1.0),
        notes="Cessna 172P (JSBSim c172p), engine shut down, gliding; lateral point masses emptied; untouched by "
              "any tuning of the method"),
    # eternity: ENAC's Eternity UAV in Paparazzi's JSBSim simulator (paparazzi/paparazzi conf/simulator/jsbsim/
    # aircraft/Eternity.xml at 5399bd98, Murat Bronz 2015, GPL-2.0-or-later): 0.90 kg, 1.0-m span, 0.145 m^2
    # (wing loading 61 N/m^2, aspect ratio 6.9), its coefficients "according to wind-tunnel measurements and AVL
    # results" (its header), inertia 0.080 / 0.033 / 0.107 kg m^2 (the easystar file's it was made from), no
    # product. The sixth model from outside the wheel and the first from Paparazzi; checked in
    # (data/jsbsim_models/eternity/, provenance and licence in its README.md) and flown as the derived model
    # ``Eternity_glide`` (derived.py): motor, propeller and throttle channel removed, its elevator moment reading
    # an alias. Chosen in the twenty-first session (docs/jsbsim.md, "The eternity"). A direct FCS
    # (aerosurface_scale, zero-centred): elevator -20 / +15 deg, both ailerons +-20 deg the same sign (the
    # aerodynamics read the left alone), rudder +-27 deg with a gain of -0.01745 (a positive command moves the
    # rudder to negative positions). Signs read from its aerodynamics: Pitch_elevator -0.0119 per deg of
    # elevator-pos (positive = trailing edge down), Roll_aileron +0.2966 x left-aileron-pos (positive = roll
    # right: Cl_delta_a -0.2966), Yaw_rudder +0.043 x rudder-pos (positive = nose right, trailing edge right:
    # delta_r = -rudder-pos, Cn_delta_r -0.043), Yaw_aileron -0.021 x left (adverse: Cn_delta_a +0.021).
    # ``cmd_per_rad`` takes the larger end of each surface, the rudder's negative for its gain's sign. Its lift
    # acts 2 in behind the CG (AERORP x 4, CG x 2), so it trims at a negative alpha with the elevator trailing
    # edge up. Set from the harness's truth only (alpha, beta, rates, excitation per axis, surfaces, sink), never
    # from a method result.
    "eternity": AircraftSpec(
        name="eternity", model="Eternity_glide", airspeed_kts=34.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=-1.0,
        cmd_per_rad=(1.0 / (20.0 * 0.01745), 1.0 / (20.0 * 0.01745), -1.0 / (27.0 * 0.01745)),
        amplitude_deg=(5.0, 4.0, 5.0), pulse_s=(0.2, 0.3, 0.5), gains=(0.5, 0.1, 0.01, 0.2, 0.05, 0.2),
        notes="Eternity UAV (Paparazzi's JSBSim Eternity.xml, checked in under data/jsbsim_models/eternity) without "
              "its motor and propeller (derived model Eternity_glide, XML sha256 ada8d7c7cccebe1a), gliding; "
              "untouched by any tuning of the method"),
    # us25e: the University of Minnesota UAS Lab's Ultra Stick 25e with its OpenFlight aerodynamics (UASLab/
    # OpenFlightSim Simulation/aircraft/UltraStick25e, MIT; the main file at 06a2b255, its parts at 1650a6e3): 1.96
    # kg, 1.27-m span, 0.3097 m^2 (wing loading 62 N/m^2), one constant per derivative on all six axes (the lab's
    # linear model: CY_p, CY_r, Cn_p and a product of inertia Ixz included), inertia 0.0715 / 0.0864 / 0.1536 kg m^2.
    # The seventh model from outside the wheel; checked in (data/jsbsim_models/ultrastick25e/, provenance and
    # licence in its README.md) and flown as the derived model ``UltraStick25e_glide`` (derived.py), assembled and
    # flown as the ultrastick's: no propulsion, direct surfaces +-30 deg (the lab's actuator travel). Chosen in the
    # twenty-second session (docs/jsbsim.md, "The us25e"). Signs read from its aerodynamics: dCMm/dElev -0.8488
    # (positive = trailing edge down), dCMl/dAilL +0.0823 and dCMl/dAilR -0.0823 (the right driven as the mirror of
    # the left, so delta_a = -left: Cl_delta_a -0.1646), dCMn/dRud -0.1811 (positive = nose left). 34 kt at 10000 ft:
    # 17-28 m/s TAS, alpha about -1..6 deg (p1-p99). Pulses 0.2 / 0.3 / 0.5 s (short period about 12 rad/s, Dutch
    # roll about 7 rad/s, roll mode about 16 per s), amplitudes 5 / 5 / 4.5 deg, the ultrastick's gains but a yaw
    # damper of 0.4: its rudder is 2.5 times its Cn_beta (a degree of rudder holds 2.5 deg of sideslip), so the rudder
    # is small (sideslip under 10 deg clean, no knock-it-off with Cl:alpha*beta = 3) and its standard deviation under
    # 1 deg (docs/jsbsim.md, "The us25e"). Set from the harness's truth only (alpha, beta, rates, excitation per axis,
    # surfaces, sink), never from a method result.
    "us25e": AircraftSpec(
        name="us25e", model="UltraStick25e_glide", airspeed_kts=34.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/posAilL_rad", "fcs/posAilR_rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.5235987755982988, 1.0 / 0.5235987755982988, 1.0 / 0.5235987755982988),
        amplitude_deg=(5.0, 5.0, 4.5), pulse_s=(0.2, 0.3, 0.5), gains=(0.25, 0.05, 0.01, 0.2, 0.05, 0.4),
        notes="Ultra Stick 25e UAV (UASLab OpenFlightSim JSBSim model with its OpenFlight aerodynamics, checked in "
              "under data/jsbsim_models/ultrastick25e) without propulsion, direct surfaces (derived model "
              "UltraStick25e_glide, XML sha256 8ea2d4e4a54bfe4f), fixed gear, gliding; untouched by any tuning of the "
              "method"),
    # ka350: a JSBSim Beechcraft King Air 350 (B300) twin turboprop, the flight model of a FlightGear package
    # rebuilt in 2026 (itaalh/FlightGear-Beechcraft-350ER Aero/KingAir-350.xml at 0298d965, GPL-2.0-or-later):
    # 13509 lb as the harness flies it (9650 lb empty, 2888 lb of fuel in two symmetric pairs of tanks, 780 lb of
    # centre-line point masses; its 190-lb pilot at y = -14.7 in is emptied by the harness), a 57.92-ft (17.65 m)
    # span, 310 ft^2 (28.8 m^2), T-tail; inertia 30290 / 19681 / 47471 slug ft^2 with the fuel, Ixz 834. Its
    # aerodynamics are tables in alpha and flaps (CL, CD, Cm_alpha, Cl_beta, Cl_delta_a and Cm_delta_e scheduled in
    # alpha) and rate and aileron cross terms linear in the basic lift coefficient (Cl_r = 0.06 + 0.22 CL, Cn_p =
    # 0.01 - 0.08 CL, Cn_delta_a = -0.004 - 0.012 CL), CY_r, an alpha-dot lift and moment. The eighth model from
    # outside the wheel; checked in (data/jsbsim_models/kingair350/, provenance and licence in its README.md) and
    # flown as the derived model ``KingAir350_glide`` (derived.py): engines, propellers and systems removed, the
    # autopilot inputs, rudder boost and feathered-propeller drag that read them removed, its yaw damper off.
    # Chosen in the twenty-third session (docs/jsbsim.md, "The ka350"). Its FCS: elevator -20 / +14 deg, ailerons
    # 25 deg up / 15 deg down (differential; the aerodynamics read the mean 0.5 (left - right), 0.349 rad per unit
    # command, linear), rudder +-25 deg. Signs read from its aerodynamics: Pitch_elevator -1.40 x elevator-pos
    # (positive = trailing edge down), Roll_aileron +0.100 x 0.5 (left - right) (positive = roll right: delta_a =
    # -0.5 (left - right), Cl_delta_a -0.100), Yaw_rudder -0.095 x rudder-pos (positive = nose left, Cn_delta_r
    # -0.095), Yaw_aileron (-0.004 - 0.012 CL) x 0.5 (left - right) (adverse). Set from the harness's truth only
    # (alpha, beta, rates, excitation per axis, surfaces, sink), never from a method result.
    "ka350": AircraftSpec(
        name="ka350", model="KingAir350_glide", airspeed_kts=160.0, altitude_ft=8000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.3491, 1.0 / 0.34905, 1.0 / 0.4363),
        amplitude_deg=(4.0, 5.0, 5.0), pulse_s=(0.7, 0.8, 1.0), gear_up=True,
        notes="Beechcraft King Air 350 twin turboprop (JSBSim flight model of the FlightGear package "
              "itaalh/FlightGear-Beechcraft-350ER, checked in under data/jsbsim_models/kingair350) without engines, "
              "propellers, systems, rudder boost or yaw damper (derived model KingAir350_glide, XML sha256 "
              "1d8b5080db88889e), gear up, gliding; untouched by any tuning of the method"),
    # s23: JSBSim's Short S.23 "Empire" four-engine flying boat of 1936 (Anders Gidenstam 2008-2023,
    # GPL-2.0-or-later; the jsbsim 1.3.3 wheel's aircraft/Short_S23, checked in under data/jsbsim_models/shorts23
    # with its DATCOM+ aerodynamics file): 33686 lb as the harness flies it (27528 lb empty, 4704 lb of fuel in
    # the two inner wing tanks, 1454 lb of centre-line point masses and the four engines' oil in symmetric
    # pairs, which the harness empties with the crew's off-centre seats), a 114-ft (34.75 m) span, 1510 ft^2
    # (140.3 m^2), a 16.46-ft (5.02 m) chord; inertia 299666 / 212782 / 501090 slug ft^2 (estimated by Aeromatic,
    # its documentation says), Ixz -1920 (JSBSim's sign). Its aerodynamics are USAF DATCOM (Datcom+) tables in
    # alpha from -16 deg: lift, drag, CL_q, CL_alphadot; CY_beta and CY_p; Cl_beta, Cl_p, Cl_r and the aileron's
    # roll (a table in the left aileron); Cm, Cm_q, Cm_alphadot, Cm_delta_e (a table); Cn_beta, Cn_p, Cn_r, the
    # aileron's yaw (a table in alpha and aileron) and Cn_delta_r -0.06; no rudder side force or roll, no CY_r
    # (their DATCOM values are 0). The ninth model from outside the wheel's stock list; flown as the derived
    # ``ShortS23_glide`` (derived.py): engines, propellers, the hull's water forces and the nine systems removed,
    # the aerodynamics inlined with an elevator alias. Chosen in the twenty-fourth session (docs/jsbsim.md, "The
    # s23"). Its FCS: elevator +-18 deg, ailerons +-19.5 deg (both written with the command's sign; the
    # aerodynamics read the left one), rudder +-22.5 deg. Signs read from its aerodynamics: CmDe -1.07 per rad of
    # elevator-pos-rad (positive = trailing edge down), ClDs4 +0.122 per rad of left-aileron-pos-rad (positive =
    # roll right: delta_a = -left, Cl_delta_a -0.122), CnDr -0.06 (positive rudder = nose left, Cn_delta_r
    # -0.06), CnDa -0.0098 per rad of left aileron at alpha 0 (Cn_delta_a +0.0098, adverse). Set from the
    # harness's truth only (alpha, beta, rates, excitation per axis, surfaces, sink), never from a method result.
    "s23": AircraftSpec(
        name="s23", model="ShortS23_glide", airspeed_kts=130.0, altitude_ft=6000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.3142, 1.0 / 0.3403, 1.0 / 0.3927),
        amplitude_deg=(4.0, 5.0, 5.0), pulse_s=(0.7, 0.8, 1.0),
        notes="Short S.23 Empire four-engine flying boat (JSBSim's model by Anders Gidenstam with DATCOM+ "
              "aerodynamics, checked in under data/jsbsim_models/shorts23) without engines, propellers, hull forces "
              "or systems (derived model ShortS23_glide, XML sha256 c1ce083b70c3d424), gliding; untouched by any "
              "tuning of the method"),
    # dr1: JSBSim's Fokker Dr.I triplane fighter of 1917 (Ron Jensen and Erik Hofman 2008, from an Aeromatic 0.9
    # start; LGPL-2.1 with JSBSim; the jsbsim 1.3.3 wheel's aircraft/dr1, checked in under
    # data/jsbsim_models/fokkerdr1): 945 lb as the harness flies it (895 lb empty, 50 lb of fuel on the centre
    # line; no pilot mass in the file), a 23.62-ft (7.20 m) span, 201.31 ft^2 (18.70 m^2: the three wings), an
    # 8.52-ft (2.60 m) chord; inertia 368.6 / 522.6 / 731.7 slug ft^2 with the tank, Ixz +0.115 kg m^2 (the
    # tank's). Its aerodynamics are its own: lift a table over +-180 deg of alpha (3.56 per rad, CL 0.25 at alpha
    # 0), the pitch moment a table in alpha plus a table in alpha and elevator (Cmde: the elevator's moment and part
    # of the static one), constant CLq, CLadot, Cmq -1.84, Cmadot -1.12; five SIDE terms (CYbeta -0.3855, CYdr
    # 0.094, CYp -0.01, CYr 0.1047, CYda 0); Clbeta -0.02, Clp -0.193, Clr -0.0458 (negative), Clda 0.087, Cldr
    # -0.005; Cnbeta 0.096, Cnp -0.0109, Cnr -0.082, Cndr -0.0502 and Cnda +0.0552 per rad of the left aileron
    # (proverse). A stock wheel model the ninth session could not initialise (its pushback system reads FlightGear
    # properties); flown as the derived ``Dr1_glide`` (derived.py): the rotary engine and propeller, the pushback
    # force and system removed, the Cmde table reading the elevator through the identity alias. Chosen in the
    # twenty-fifth session (docs/jsbsim.md, "The dr1"). Its FCS: elevator +-0.35 rad (20.1 deg), both ailerons +-0.30
    # rad (17.2 deg) with the command's sign (the aerodynamics read the left one), rudder: the command clipped at +-0.35
    # of its normalised range before the +-0.44-rad scale, so +-0.154 rad (8.8 deg) of travel. Signs read from its
    # aerodynamics: CLde +0.2 and Cmde falling with elevator-pos-rad (positive = trailing edge down), Clda +0.087 per
    # rad of left-aileron-pos-rad (positive = roll right: delta_a = -left, Cl_delta_a -0.087), Cndr -0.0502 (positive
    # rudder = nose left), Cnda +0.0552 per rad of the left aileron (Cn_delta_a -0.0552: proverse). Set from the
    # harness's truth only (alpha, beta, rates, excitation per axis, surfaces, sink), never from a method result:
    # at 80 kt the pair (Cm:alpha^2 -8 with Cn:delta_a -0.06) tucked under past the elevator's authority (alpha
    # -8.5 deg, seed 3) and the lowest flight reached 344 m from 6000 ft; at 65 kt Cl:alpha*beta 3 banked 34 deg;
    # 70 kt at 8000 ft flies every trial flight inside the envelope. A tuning aircraft since the twenty-sixth session
    # (its notes, part of its fingerprint, unchanged).
    "dr1": AircraftSpec(
        name="dr1", model="Dr1_glide", airspeed_kts=70.0, altitude_ft=8000.0,
        elevator_sign=1.0, aileron_sign=-1.0, aileron_props=("fcs/left-aileron-pos-rad", None), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.30, 1.0 / 0.44),
        amplitude_deg=(3.5, 5.0, 4.0), pulse_s=(0.7, 0.8, 1.0),
        notes="Fokker Dr.I triplane (JSBSim's model by Ron Jensen and Erik Hofman, checked in under "
              "data/jsbsim_models/fokkerdr1) without its rotary engine, propeller or pushback (derived model "
              "Dr1_glide, XML sha256 6ba46d3a95d9619e), gliding; untouched by any tuning of the method"),
    # navion: JSBSim's Ryan Navion, the four-seat light aircraft of 1946 (the Army's L-17; the jsbsim 1.3.3 wheel's
    # aircraft/L17, "Originally from Bruce Jackson (LaRCSim)?", LGPL-2.1 with JSBSim; checked in under
    # data/jsbsim_models/navion): 2770 lb as the harness flies it (2750 empty, 2 x 10 lb of fuel on the centre line;
    # no point masses), a 33.42-ft (10.19 m) span, 184 ft^2 (17.09 m^2), a 5.7-ft (1.74 m) chord; inertia 1048 /
    # 3000 / 3530 slug ft^2, no product of inertia: the Navion's textbook numbers (Teper, NASA CR-96008, 1969;
    # Nelson, Flight Stability and Automatic Control, 2nd ed., 1998, appendix B), as are its constant derivatives:
    # Cm_alpha -0.683, Cm_q -9.96, Cm_alphadot -4.36, CL_delta_e 0.355, Cm_delta_e (-0.923 + 0.324 Mach), CY_beta
    # -0.564 (its only side-force term), Cl_beta -0.074, Cl_p -0.41, Cl_r 0.107, Cl_delta_a (0.134 - 0.0385 Mach),
    # Cl_delta_r 0.0107, Cn_beta 0.071, Cn_p -0.0575, Cn_r -0.125, Cn_delta_r -0.072, Cn_delta_a -0.0035 per rad of
    # the left aileron (adverse, small); lift a table in alpha with a kink at 0 (5.0 per rad below, 3.35 above, CL
    # 0.25 at 0), drag CD0 a table in alpha plus 0.04 CL^2. A stock wheel model the ninth session could not
    # initialise (its flap normaliser reads fcs/flaps-pos-deg, which nothing writes); flown as the derived
    # ``Navion_glide`` (derived.py): the engine and propeller removed, the normaliser reading the flap kinematic's
    # fcs/flap-pos-deg. Chosen in the twenty-sixth session (docs/jsbsim.md, "The navion"). Its FCS: elevator -0.35 /
    # +0.30 rad (the harness's command scale is the larger, trailing-edge-up side, as the ka350's), ailerons +-0.35
    # rad (left with the command's sign, right its mirror), rudder +-0.35 rad. Signs read from its aerodynamics: Cmde
    # negative per rad of elevator-pos-rad (positive = trailing edge down), Clda +0.124 per rad of the left aileron
    # (positive = roll right: delta_a = -0.5 (left - right), Cl_delta_a -0.124), Cndr -0.072 (positive rudder = nose
    # left). Gear up (retractable; CDgear 0.03 vanishes with it). Set from the harness's truth only (alpha, beta,
    # rates, excitation per axis, surfaces, sink), never from a method result: at 90 and 95 kt (6000 ft) the sweep
    # reached alpha 12-14 deg (CL_max at 13.2) and Cl:alpha*beta 3 knocked off at 45 deg of bank; at 110 kt it banked
    # 26 deg; 120 kt at 10000 ft flies all eleven trial flights inside the envelope, alpha -4.9..5.3 deg. A tuning
    # aircraft since the twenty-seventh session (its notes, part of its fingerprint, unchanged).
    "navion": AircraftSpec(
        name="navion", model="Navion_glide", airspeed_kts=120.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.5, 5.0, 5.0), pulse_s=(0.7, 0.8, 1.0), gear_up=True,
        notes="Ryan Navion (JSBSim's L17 with LaRCSim's textbook Navion derivatives, checked in under "
              "data/jsbsim_models/navion) without its engine or propeller (derived model Navion_glide, XML sha256 "
              "2e075b387ce9a6e4), gear up, gliding; untouched by any tuning of the method"),
    # fokker50: JSBSim's Fokker 50, the twin-turboprop regional airliner of 1985 (the jsbsim 1.3.3 wheel's
    # aircraft/fokker50, Erik Hofman 2002, LGPL-2.1 with JSBSim; checked in under data/jsbsim_models/fokker50): 31900 lb
    # as the harness flies it (29700 empty, 2 x 1100 lb of fuel 3 in either side of the centre line; no point masses),
    # a 95.15-ft (29.0 m) span, 753.55 ft^2 (70.0 m^2), a 7.92-ft (2.41 m) chord; inertia 474936 / 430723 / 896344
    # slug ft^2, no product of inertia in the file. Its own derivatives (not Aeromatic's set): Cm_alpha -1.876, Cm_q
    # -20.13, Cm_alphadot -5.75, Cm_delta_e (-1.628 + 0.6105 Mach), CL_q 5.22, CL_alphadot 1.49, CL_delta_e 0.273; four
    # side-force terms (CY_beta -0.416, CY_p a table in Reynolds number, CY_r 0.362, CY_delta_r 0.253); Cl_beta and
    # Cl_r tables in alpha and Reynolds number, Cl_p -0.514, Cl_delta_a (0.15 - 0.05625 Mach) per rad of the left
    # aileron, Cl_delta_r 0.01; Cn_beta 0.181, Cn_p a table in Reynolds number (on the inertial p), Cn_r -0.174,
    # Cn_delta_r -0.110, Cn_delta_a -0.008 per rad of the left aileron (adverse); lift a table in alpha (CL 0.468 at
    # 0), drag CD0 a table in alpha plus 0.03 CL^2. Below a Reynolds number of 10.6 million its Cl_beta, Cl_r, CY_p
    # and Cn_p tables jump (a stall initiator): the harness flies fast enough to stay above it. A stock wheel model the
    # ninth session could not initialise (its engine control reads FlightGear's throttle) and set aside for its
    # propwash terms; flown as the derived ``Fokker50_glide`` (derived.py): the engines, propellers, the EEC and
    # Thruster channels and the three propwash terms (products with the propellers' thrust coefficients, 0 without
    # propellers) removed, and its yaw damper. Chosen in the twenty-seventh session (docs/jsbsim.md, "The
    # fokker50"). Its FCS: elevator -0.35 / +0.30 rad (the harness's command scale is the larger, trailing-edge-up
    # side, as the navion's), ailerons +-0.35 rad (left with the command's sign, right its mirror), rudder +-0.35
    # rad. Signs read from its aerodynamics: Cmde negative per rad of elevator-pos-rad (positive = trailing edge
    # down), Clda +0.129 per rad of the left aileron at the glide's Mach (positive = roll right: delta_a = -0.5 (left
    # - right), Cl_delta_a -0.129), Cndr -0.110 (positive rudder = nose left). Gear up (retractable; CDgear 0.046
    # vanishes with it). Set from the harness's truth only (alpha, beta, rates, excitation per axis, surfaces, sink,
    # Reynolds number), never from a method result: at 170 kt (10000 ft) the sweeps' slowest point fell to a
    # Reynolds number of 10.4 million, below the tables' jump; 200 kt at 8000 ft left the envelope (speed); 180 kt
    # at 10000 ft flies all eleven trial flights inside the envelope, alpha -8.8..2.7 deg, Reynolds number 11.0-22.6
    # million, the elevator at most 15.7 deg trailing edge down of its 17.2 (amplitude 4 deg; 4.5 reached 16.3).
    "fokker50": AircraftSpec(
        name="fokker50", model="Fokker50_glide", airspeed_kts=180.0, altitude_ft=10000.0,
        elevator_sign=1.0, aileron_sign=-1.0,
        aileron_props=("fcs/left-aileron-pos-rad", "fcs/right-aileron-pos-rad"), rudder_sign=1.0,
        cmd_per_rad=(1.0 / 0.35, 1.0 / 0.35, 1.0 / 0.35),
        amplitude_deg=(4.0, 5.0, 5.0), pulse_s=(0.7, 0.8, 1.0), gear_up=True,
        notes="Fokker 50 twin-turboprop airliner (JSBSim's fokker50 by Erik Hofman, checked in under "
              "data/jsbsim_models/fokker50) without its engines, propellers, propwash terms or yaw damper (derived "
              "model Fokker50_glide, XML sha256 6b10cd57d0647df4), gear up, gliding; untouched by any tuning of the "
              "method"),
}
TUNING_AIRCRAFT = ("c172x", "sgs", "pa28", "j3cub", "c182", "t37", "t6", "b747", "f16", "f4n", "rascal", "sgs126",
                   "asw20", "iar80", "c684", "ultrastick", "b737", "c172p", "eternity", "us25e", "ka350", "s23", "dr1",
                   "navion", "fokker50")
HELD_OUT_AIRCRAFT: tuple[str, ...] = ()
UNTOUCHED_AIRCRAFT: tuple[str, ...] = ()


def aircraft(name: str) -> AircraftSpec:
    """The spec called ``name``.

    Raises:
        KeyError: unknown name (the message lists the known ones).
    """
    try:
        return AIRCRAFT[name]
    except KeyError:
        raise KeyError(f"unknown aircraft '{name}' (known: {', '.join(AIRCRAFT)})") from None


def canonical_name(name: str) -> str:
    """The harness name of ``name``: a harness name (``j3cub``) or a JSBSim model name (``J3Cub``),
    either in any case.

    Raises:
        KeyError: unknown name (the message lists the known ones).
    """
    key = str(name).strip().lower()
    for spec in AIRCRAFT.values():
        if key in (spec.name.lower(), spec.model.lower()):
            return spec.name
    raise KeyError(f"unknown aircraft '{name}' (known: {', '.join(AIRCRAFT)})")


def aircraft_argument(name: str) -> str:
    """``type=`` of the evaluation scripts' ``--aircraft``: :func:`canonical_name`, an unknown name
    being argparse's one-line usage error (exit 2)."""
    try:
        return canonical_name(name)
    except KeyError as e:
        raise argparse.ArgumentTypeError(e.args[0]) from None


def summary_label(name: str) -> str:
    """``name`` as the evaluation summaries print it: ``"t6 (untouched)"`` for the
    :data:`UNTOUCHED_AIRCRAFT`, ``"<name> (held out)"`` for the other :data:`HELD_OUT_AIRCRAFT`, the
    name alone for the aircraft used in tuning."""
    return name + (" (untouched)" if name in UNTOUCHED_AIRCRAFT else " (held out)" if name in HELD_OUT_AIRCRAFT else "")
