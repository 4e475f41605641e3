"""The harness's checks shared by the aircraft set up from their XML and JSBSim's truth alone (c182,
t37, t6, b747, f16, f4n, rascal, sgs126, asw20, iar80, c684, ultrastick, b737, c172p, eternity, us25e, ka350, s23,
dr1, navion and the untouched fokker50;
docs/jsbsim.md, one section each),
parametrised over the roster.

Only the harness is checked, on JSBSim's exact truth and its own properties: the names and roles,
the rigid-body consistency of the truth with the checked-in airframe file (mass, product of inertia),
the sign map against each model's XML, the gear retracted by the harness, the .tlog as the pipeline
decodes it, every hidden effect as JSBSim computes it, the airspeed bias in the log, the evaluation's
flights in each aircraft's envelope, and the eval scripts' ``--fly-only``. No pipeline fit, GP,
diagnosis or scoring runs here. One 30-s flight per aircraft (light, seed 1) serves its tests.

Used aircraft's checks are slow tests but their names' (the c182 keeps its flight checks in the
default suite, as before the fold); the untouched fokker50's are slow too but its names', and its own
default checks (its model, surfaces, static stability, the summaries' label) are in
``test_jsbsim_fokker50.py`` (the navion's in ``test_jsbsim_navion.py``, the dr1's in ``test_jsbsim_dr1.py``, the s23's
in ``test_jsbsim_s23.py``, the ka350's in ``test_jsbsim_ka350.py``, the us25e's in ``test_jsbsim_us25e.py``, the
eternity's in ``test_jsbsim_eternity.py``, the c172p's in ``test_jsbsim_c172p.py``, the b737's in
``test_jsbsim_b737.py``, the ultrastick's in ``test_jsbsim_ultrastick.py``, the c684's in ``test_jsbsim_c684.py``, the
iar80's in ``test_jsbsim_iar80.py``, the asw20's in ``test_jsbsim_asw20.py``, the sgs126's in ``test_jsbsim_sgs126.py``,
the rascal's in ``test_jsbsim_rascal.py``, the f4n's in ``test_jsbsim_f4n.py``, the f16's in ``test_jsbsim_f16.py``;
tuning aircraft since the eleventh to twenty-seventh sessions). Folded in the eleventh session from
``test_jsbsim_{c182,t37,t6,b747}.py`` (same checks, same numbers; the Ixz checks now pin each model's value); the f4n
added in the twelfth, the rascal in the thirteenth, the sgs126 in the fourteenth, the asw20 in the fifteenth, the iar80
in the sixteenth, the c684 in the seventeenth, the ultrastick in the eighteenth, the b737 in the nineteenth, the c172p
in the twentieth, the eternity in the twenty-first, the us25e in the twenty-second, the ka350 in the twenty-third, the
s23 in the twenty-fourth, the dr1 in the twenty-fifth, the navion in the twenty-sixth, the fokker50 in the
twenty-seventh.
"""

from dataclasses import dataclass

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, aircraft, make_flight
from model_checks import assert_names_resolve
from static_checks import assert_hidden_effects_in_jsbsim
from truth_fits import (ENVELOPE_FLIGHTS, assert_airspeed_bias_in_log, assert_in_envelope, assert_rigid_body_glide,
                        assert_servos_map_back, closure_slopes, derivative_slopes, evaluation_envelope)
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log

SLUG_FT2 = 1.3558179483314004     # kg m^2 per slug ft^2


@dataclass(frozen=True)
class Case:
    """What one aircraft's harness is checked against (each number from its XML or JSBSim; sources in
    its docs/jsbsim.md section).

    Attributes:
        name, model, typo: harness name, JSBSim model name, an unknown name close to it.
        mass_lb: JSBSim's mass in the glide (empty + fuel + kept point masses), lb.
        ixz: the project's Ixz, kg m^2 (JSBSim's with the sign flipped; 0: no product of inertia).
        slopes: sign-map checks on ``derivative_slopes`` (cm: alpha, q_hat, delta_e; cl, cn: beta,
            p_hat, r_hat, delta_a, delta_r): (coefficient, index, target, tolerance), the tolerance
            ``("rel", x)``, ``("abs", x)`` or ``("in", lo, hi)`` (target unused).
        gear_zero: the gear-down aerodynamic functions that must read 0 after the settling phase
            (empty: fixed gear, not retracted): a name under ``aero/coefficient/`` or a full property path.
        elevator_end: the elevator's trailing-edge-down end, rad; n_side: its SIDE functions;
            n_elevator_reads: its aerodynamics' ``<property>`` reads of ``fcs/elevator-pos-rad``.
        envelope: ``assert_in_envelope`` limits of the evaluation's flights.
        default: the flight checks run in the default suite (else slow).
        untouched: the untouched aircraft of the next final evaluation.
        min_lbf: the hidden effects' least force or moment at the check's state, lbf (ft)
            (``assert_hidden_effects_in_jsbsim``; small for a small aircraft).
        closure: the sign map's slopes from ``closure_slopes`` (JSBSim's own regressors: the rates relative
            to the air, Cm with JSBSim's alpha-dot) instead of ``derivative_slopes``' (inertial rates, no
            alpha-dot): for an aircraft flown in turbulence strong enough to turn the short fit's Cm_alpha
            (the sgs126).
        cross_inertia_abs: the largest abs(Ixy) and abs(Iyz) JSBSim may report, kg m^2: 0 (exactly) for every
            aircraft but the ka350, whose two symmetric pairs of fuel tanks leave JSBSim's floating-point sum of
            m x y at 6e-15 and -1.4e-14 kg m^2 (its Ixx is 41053; twenty-third session).
    """

    name: str
    model: str
    typo: str
    mass_lb: float
    ixz: float
    slopes: tuple
    gear_zero: tuple
    elevator_end: float
    n_side: int
    envelope: dict
    n_elevator_reads: int = 2
    default: bool = False
    untouched: bool = False
    min_lbf: float = 10.0
    closure: bool = False
    cross_inertia_abs: float = 0.0


# Envelope limits re-derived in the fifteenth session (turb15) from the truth of the evaluation flights in
# MIL-F-8785C light / moderate turbulence (severity 3 / 4; docs/jsbsim.md, each aircraft's section): c182
# alpha under 11 (seed-100 sweep 10.0 deg; stall near 16) and clean sideslip under 10 (moderate seed 2: 8.5
# deg; knock-it-off 15); t37 alpha above -6 (the pair's sweep -5.2); t6 alpha above -7 (the pair's sweep
# -6.1); f16 clean sideslip under 7.5 and bank under 25 (the pair's sweep 6.3 deg and 21.3 deg). The sink
# is checked through the air (truth_fits.assert_in_envelope).
CASES = (
    # c182: 1700 lb empty + 400 lb fuel; its 180-lb pilot at y = -14 in emptied by the harness.
    # ClDa +0.15 x left-aileron-pos (Cl_delta_a = -0.15); CnDr -0.0645 at alpha 0 to -0.0805 at 5.4 deg.
    Case("c182", "c182", "c18", 2100, 32.5499,
         (("cl", 3, -0.15, ("rel", 0.03)), ("cn", 4, None, ("in", -0.0805, -0.0645))), (), np.radians(23.0), 5,
         dict(alpha=(-4.0, 11.0), beta=(10.0, 13.0), bank=(15.0, 25.0), speed=(1.15 * 27.8, 70.0), rate_std=1.8,
              rate_std_held=1.5), default=True),
    # t37: 4056 lb empty + 2 x 350 lb on the centre line, no product of inertia. Clda (0.181 - 0.0705
    # Mach) x left-aileron-pos: -0.157 at Mach 0.34; Cnda -0.0254 x left (+0.0254); Cndr -0.0365.
    Case("t37", "T37", "t3", 4756, 0.0,
         (("cl", 3, -0.157, ("rel", 0.03)), ("cn", 3, 0.0254, ("rel", 0.1)), ("cn", 4, -0.0365, ("rel", 0.05))),
         ("CDgear", "DCYbdf", "DClrDg", "DCnbDg"), 0.30, 5,
         dict(alpha=(-6.0, 7.0), beta=(6.0, 9.0), bank=(18.0, 30.0), speed=(1.3 * 46.9, 150.0), alt_min=500.0,
              rate_std=1.8, rate_std_held=1.8)),
    # t6: 5000 lb empty + 2 x 500 lb in wing tanks at y = +-50 in; <ixz> -1000 (997.41 slug ft^2 with the
    # tanks). CmDe -1.2, Clda 0.29 x left (Cl_delta_a -0.29), Cldr 0.012, Cndr -0.06, no aileron yaw.
    Case("t6", "t6texan2", "t66", 6000, 997.41 * SLUG_FT2,
         (("cm", 2, -1.2, ("rel", 0.02)), ("cl", 3, -0.29, ("rel", 0.02)), ("cl", 4, 0.012, ("rel", 0.05)),
          ("cn", 4, -0.06, ("rel", 0.02)), ("cn", 3, 0.0, ("abs", 1e-3))), ("CDgear",), 0.51, 1,
         dict(alpha=(-7.0, 7.0), beta=(6.0, 8.0), bank=(20.0, 25.0), speed=(1.3 * 50.0, 140.0), alt_min=500.0,
              rate_std=1.5, rate_std_held=1.5)),
    # b747: 523816 lb empty + 5 x 5456.4 lb on the centre line; <ixz> -970000. Cmde (-1.3 + 0.4875 Mach)
    # with CLde's arm: -1.068 at the CG; Clda (0.1 - 0.0335 Mach): -0.082; Clb -0.1, Clp -0.4, Cldr 0.01;
    # Cnb 0.12 + the side force's arm: 0.140; Cnr -0.15, Cndr -0.1; no Cnda.
    Case("b747", "B747", "b74", 551098, 970000 * SLUG_FT2,
         (("cm", 2, -1.068, ("rel", 0.02)), ("cl", 3, -0.082, ("rel", 0.02)), ("cl", 0, -0.1, ("rel", 0.02)),
          ("cl", 1, -0.4, ("rel", 0.02)), ("cl", 4, 0.01, ("rel", 0.05)), ("cn", 4, -0.1, ("rel", 0.02)),
          ("cn", 0, 0.140, ("rel", 0.02)), ("cn", 2, -0.15, ("rel", 0.02)), ("cn", 3, 0.0, ("abs", 1e-3))),
         ("CDgear",), 0.175, 1,
         dict(alpha=(-7.0, 8.0), beta=(6.0, 6.0), bank=(15.0, 15.0), speed=(1.3 * 95.0, 230.0), alt_min=500.0,
              rate_std=0.5, rate_std_held=0.4)),
    # f16 (derived f16_direct): 17400 lb empty + the 230-lb pilot on the centre line + 2 x 1500 lb in
    # wing tanks at y = +-65 in; <ixz> -982 (1059.9 slug ft^2 with the tanks). Clda 0.051-0.052 x
    # aileron-pos at these alphas (-0.052); Cnda +0.009..0.011 (-0.010); Cndr -0.045; CmDh about -0.53
    # per rad of elevator near 0. Six SIDE functions; the elevator read once, through the alias.
    Case("f16", "f16_direct", "f15x", 20630, 1436.98,
         (("cl", 3, -0.052, ("rel", 0.1)), ("cn", 4, -0.045, ("rel", 0.1)), ("cn", 3, -0.010, ("abs", 0.004)),
          ("cm", 2, -0.53, ("rel", 0.1))), ("CDgear",), 0.436, 6,
         dict(alpha=(-6.0, 11.0), beta=(7.5, 6.0), bank=(25.0, 25.0), speed=(110.0, 200.0), alt_min=1000.0,
              rate_std=1.0, rate_std_held=1.0), n_elevator_reads=1),
    # f4n (stock F4N as F4N_fcs, its own yaw damper in the loop): 28000 lb empty + 13000 lb of fuel on the centre
    # line, no product of inertia. Cmde (-0.70 + 0.25 Mach) x elevator-pos; Clda (0.12 - 0.04 Mach) x
    # left-aileron-pos: -0.547 and -0.0956 at the standard flight's Mach 0.61 (the reference point 4 in
    # above the CG adds no pitch arm); Cmalpha -0.3 with the lift 4 in above the CG: -0.228 (JSBSim, as
    # run_ic gives -0.229); Cmq -18 + Cmadot -9: -27; Clb -0.05 plus the side force (CYb -1) acting 4 in
    # above the CG: -0.05 + 4 / (12 x 38.4) = -0.041; Clp -0.4, Cldr 0.005; Cnb 0.12 (no side-force arm
    # fore or aft), Cnr -0.15, Cndr -0.08; Cnda 0 (a function of value 0). One SIDE function (CYb); the
    # elevator read by CLde and Cmde.
    Case("f4n", "F4N_fcs", "f4", 41000, 0.0,
         (("cm", 0, -0.228, ("rel", 0.03)), ("cm", 1, -27.0, ("rel", 0.02)), ("cm", 2, -0.547, ("rel", 0.03)),
          ("cl", 3, -0.0956, ("rel", 0.03)), ("cl", 0, -0.041, ("rel", 0.02)),
          ("cl", 1, -0.4, ("rel", 0.02)), ("cl", 4, 0.005, ("rel", 0.1)), ("cn", 4, -0.08, ("rel", 0.02)),
          ("cn", 0, 0.12, ("rel", 0.02)), ("cn", 2, -0.15, ("rel", 0.02)), ("cn", 3, 0.0, ("abs", 1e-3))),
         ("CDgear",), 0.30, 1,
         dict(alpha=(-7.0, 9.0), beta=(6.0, 6.0), bank=(10.0, 15.0), speed=(130.0, 230.0), alt_min=200.0,
              rate_std=1.0, rate_std_held=1.0)),
    # rascal (ArduPilot's SITL Rascal 110, flown as Rascal110_glide: its engine and propeller removed):
    # 13 lb empty + 1.5 lb of fuel on the centre line, 0.37 in ahead of and 5.9 in below the empty CG, whence
    # JSBSim's tiny Ixz (-6.84e-5 slug ft^2, the project's +9.28e-5 kg m^2). On the 30-s flight's truth
    # (least squares, seed 1): Clda (0.13 - 0.0365 Mach) x left at Mach 0.06: Cl_delta_a -0.124 (-0.128
    # in JSBSim); Cnda -0.03 x left: Cn_delta_a +0.030; Cndr -0.05; Cnb 0.12 plus the side force (CYb -1)
    # acting 1.0 in aft of the CG: 0.129; Cnr -0.15; Clb -0.1 plus the side force 3.4 in below the CG:
    # -0.074; Clp -0.4 (-0.386 on the inertial rates); Cm_alpha -0.67 (the fit on a 30-s flight; JSBSim's
    # static -0.8, test_jsbsim_rascal.py). One SIDE function; the elevator read by CLde and Cmde (CDde
    # reads fcs/elevator-pos-norm, not delayed). Fixed gear. Envelope limits from the trial flights
    # (docs/jsbsim.md, "The rascal"): alpha -1.2..4.5 deg, sideslip 4.7, bank 15, TAS 16.5-23.8 m/s,
    # sink 1.6-2.2 m/s.
    Case("rascal", "Rascal110_glide", "rascl", 14.5, 6.843056e-05 * SLUG_FT2,
         (("cm", 0, None, ("in", -0.9, -0.5)), ("cl", 3, -0.1244, ("rel", 0.05)), ("cl", 0, -0.0744, ("rel", 0.05)),
          ("cl", 1, -0.39, ("rel", 0.05)), ("cn", 4, -0.05, ("rel", 0.02)), ("cn", 0, 0.129, ("rel", 0.02)),
          ("cn", 2, -0.15, ("rel", 0.03)), ("cn", 3, 0.030, ("rel", 0.05))),
         (), 0.30, 1,
         dict(alpha=(-4.0, 8.0), beta=(7.0, 8.0), bank=(20.0, 25.0), speed=(13.0, 30.0), alt_min=1000.0,
              rate_std=1.5, rate_std_held=1.5, sink_min=1.0), min_lbf=0.5),
    # sgs126 (the wheel's Schweizer SGS 1-26 glider, flown as it is at 3000 ft): 445 lb, no fuel, no point
    # mass, no product of inertia. Clda (0.06 - 0.02 Mach) x left at Mach 0.075: Cl_delta_a -0.0585; Cnda
    # -0.02 x left: Cn_delta_a +0.02; Cndr -0.03; Cnb 0.12 (no side-force arm fore or aft); Cnr -0.15;
    # Clb -0.1 plus the side force (CYb -1) acting 6.4 in above the CG: -0.1137; Clp -0.4; Cm_alpha about
    # the CG -0.56..-0.65 (JSBSim, test_jsbsim_sgs126.py). The 30-s light flight's Cm on alpha, q_hat and
    # delta_e gives Cm_alpha +0.065 and Cl_beta -0.051 (its Cmadot -12 and the gusts' rotation left out at
    # 3000 ft), so it is checked on JSBSim's own regressors (closure_slopes): Cm_alpha -0.515, Cm_q -9.37
    # (Cmq -9), Cm_delta_e -0.788 (-0.8 + 0.3 Mach), Cm_alpha_dot -12.18 (Cmadot -12); Cl and Cn exactly
    # the values above. One SIDE function; the elevator read by CLde and
    # Cmde (CDde reads fcs/mag-elevator-pos-rad). Gear left down (CDgear 0.001 a constant). Envelope limits
    # from the trial flights (docs/jsbsim.md, "The sgs126"): alpha -1.8..4.7 deg, sideslip 6.7 (moderate)
    # and 4.2 (Cl:alpha*beta = 3), bank 25 (moderate) and 18, TAS 19.3-29.3 m/s, sink 0.3-2.1 m/s (one
    # moderate flight in rising air), lowest 706 m, yaw-rate standard deviation 1.0 on the held-out 20 %.
    Case("sgs126", "sgs126", "sgs12", 445, 0.0,
         (("cm", 0, None, ("in", -0.7, -0.4)), ("cm", 1, -9.0, ("rel", 0.1)), ("cm", 2, -0.78, ("rel", 0.03)),
          ("cm", 3, -12.0, ("rel", 0.05)), ("cl", 3, -0.0585, ("rel", 0.01)), ("cl", 0, -0.1137, ("rel", 0.01)),
          ("cl", 1, -0.4, ("rel", 0.01)), ("cl", 2, 0.15, ("rel", 0.01)), ("cl", 4, 0.01, ("rel", 0.01)),
          ("cn", 4, -0.03, ("rel", 1e-6)), ("cn", 0, 0.12, ("rel", 1e-6)), ("cn", 2, -0.15, ("rel", 1e-6)),
          ("cn", 3, 0.02, ("rel", 1e-6)), ("cn", 1, 0.0, ("abs", 1e-9))),
         (), 0.30, 1,
         dict(alpha=(-4.0, 8.0), beta=(9.0, 8.0), bank=(30.0, 25.0), speed=(15.0, 35.0), alt_min=500.0,
              rate_std=1.0, rate_std_held=0.8, sink_min=0.2), closure=True),
    # asw20 (FlightGear's ASW 20 sailplane, flown as asw20_glide at 3000 ft: FlightGear's engine and ballast
    # systems removed, its tail table reading the elevator through an alias): 728.7 lb, no point mass, no
    # product of inertia. On JSBSim's own regressors (closure_slopes; the 30-s light flight's inertial-rate
    # fit gives Cl_p -0.11 for its -0.68, the gusts' rotation over a 15-m span): Cl and Cn exactly its XML:
    # Clb -0.0693, Clp -0.6843, Clr 0.1551, Clda -0.214 x left (delta_a = +left: Cl_delta_a -0.214), Cldr
    # 0.0065; Cnb 0.1007, Cnp -0.0859, Cnr -0.0539, Cnda -0.017 x left (Cn_delta_a -0.017: proverse), Cndr
    # -0.041; Cm_alpha -1.13 (its Cmalpha table, +0.37..+0.62 per rad, and the tail's CmDe table, -1.76),
    # Cm_q -24.1 (Cmq -24.098), Cm_delta_e -0.79 (CmDe -0.79 per rad of elevator at alpha -2 deg),
    # Cm_alpha_dot -1.86 (Cmadot -1.928). Five SIDE functions (CYb, CYp, CYr, CYDa, CYDr); the elevator read
    # by CLDe and the alias the CmDe table looks up (CDDe reads fcs/mag-elevator-pos-rad). Gear up (CDDg).
    # Envelope limits from the trial flights (docs/jsbsim.md, "The asw20").
    Case("asw20", "asw20_glide", "asw2", 728.736, 0.0,
         (("cm", 0, None, ("in", -1.3, -0.95)), ("cm", 1, -24.1, ("rel", 0.03)), ("cm", 2, -0.787, ("rel", 0.03)),
          ("cm", 3, -1.9, ("rel", 0.1)), ("cl", 3, -0.214, ("rel", 1e-3)), ("cl", 0, -0.0693, ("rel", 1e-3)),
          ("cl", 1, -0.6843, ("rel", 1e-3)), ("cl", 2, 0.1551, ("rel", 1e-3)), ("cl", 4, 0.0065, ("rel", 1e-3)),
          ("cn", 4, -0.041, ("rel", 1e-3)), ("cn", 0, 0.1007, ("rel", 1e-3)), ("cn", 2, -0.0539, ("rel", 1e-3)),
          ("cn", 3, -0.017, ("rel", 1e-3)), ("cn", 1, -0.0859, ("rel", 1e-3))),
         ("CDDg",), 0.38397, 5,
         dict(alpha=(-7.0, 7.0), beta=(8.0, 9.0), bank=(25.0, 25.0), speed=(20.0, 50.0), alt_min=400.0,
              rate_std=1.5, rate_std_held=1.2, sink_min=0.0), closure=True),
    # iar80 (FlightGear's JSBSim IAR-80, Aeromatic 0.95, flown as IAR80_glide at 10000 ft: its engine and propeller
    # removed): 4850 lb empty + a 459.2-lb payload + 861.6 lb of fuel, all at the CG; no product of inertia. The
    # aerodynamic reference point is 8.7 in above the CG (same x). On JSBSim's own regressors (closure_slopes, the
    # 30-s calm flight): Cl and Cn its XML: Clb -0.1 plus the side force (Side_beta -1) acting 8.7 in above the CG:
    # -0.1208; Clp -0.4, Clr 0.15, Roll_aileron +0.18 x left (Cl_delta_a -0.18), Roll_rudder 0.01; Cnb 0.12 (no
    # fore-aft arm), Cnp 0, Cnr -0.15, Yaw_aileron -0.003 x left (Cn_delta_a +0.003: adverse), Yaw_rudder -0.1;
    # Cm_alpha about the CG -0.54 (Pitch_alpha -0.5 and the arm: JSBSim's static -0.48 below alpha 0 and -0.55
    # above, test_jsbsim_iar80.py), Cm_q -14.7 (Pitch_damp -15), Cm_delta_e -0.88 ((-1 + 0.375 Mach) at Mach
    # 0.3), Cm_alpha_dot -7.4 (Pitch_alphadot -7). One SIDE function; the elevator read by Lift_elevator and
    # Pitch_elevator (Drag_elevator reads fcs/elevator-pos-norm, not delayed). Gear up (Drag_gear). Envelope
    # limits from the trial flights (docs/jsbsim.md, "The iar80"): alpha -6.2..6.4 deg, sideslip 5.5, bank 11.8,
    # TAS 69-130 m/s, sink through the air 9.6-10.6 m/s, lowest 1562 m, yaw-rate standard deviation 2.2 deg/s
    # on the held-out 20 %.
    Case("iar80", "IAR80_glide", "iar8", 6170.8, 0.0,
         (("cm", 0, None, ("in", -0.65, -0.42)), ("cm", 1, -15.0, ("rel", 0.05)), ("cm", 2, -0.885, ("rel", 0.03)),
          ("cm", 3, -7.0, ("rel", 0.12)), ("cl", 3, -0.18, ("rel", 1e-3)), ("cl", 0, -0.1208, ("rel", 0.01)),
          ("cl", 1, -0.4, ("rel", 1e-3)), ("cl", 2, 0.15, ("rel", 1e-3)), ("cl", 4, 0.01, ("rel", 0.01)),
          ("cn", 4, -0.1, ("rel", 1e-3)), ("cn", 0, 0.12, ("rel", 1e-3)), ("cn", 2, -0.15, ("rel", 1e-3)),
          ("cn", 3, 0.003, ("rel", 0.01)), ("cn", 1, 0.0, ("abs", 1e-6))),
         ("aero/force/Drag_gear",), 0.35, 1,
         dict(alpha=(-9.0, 9.0), beta=(8.0, 9.0), bank=(20.0, 25.0), speed=(60.0, 145.0), alt_min=1000.0,
              rate_std=1.5, rate_std_held=1.5, sink_min=5.0), closure=True),
    # c684 (FlightGear's JSBSim Caudron C.684, Guillaume Chauvat 2008, hand-made tables; flown as C684_glide at 6000
    # ft: its engine, propeller and engine system removed): 640 kg empty + pilot and passenger 85 kg each on the
    # centre line (x 3.5 and 4.0 m, 0.2 m above the CG's z: the product of inertia, project Ixz 37.86 kg m^2) + 2 x
    # 80 kg of fuel 0.2 m either side of the centre line. The aerodynamic reference point is 0.287 m ahead of the
    # loaded CG and 0.15 m below it. On JSBSim's own regressors (closure_slopes, the 30-s calm flight): Cm_alpha
    # -0.869 (Cmalpha -2.3 less the lift ahead of the CG), Cm_q -14.6 (Cmq -15), Cm_delta_e -1.250 (Cmde -1.3 and
    # CLde through the arm), Cm_alpha_dot -8.3 (Cmadot -8); Cl_beta -0.056 (the Clb table in alpha, -0.08 at 0, and
    # the side force below the CG), Cl_p -0.448 (the Clp table in alpha and p, -0.45 at alpha 0), Cl_r 0.200, Cl_delta_a
    # -0.1197 (the Clda table, 0.12 at alpha 0), Cl_delta_r 0; Cn_beta 0.141 (Cnb 0.18 less the side force ahead of
    # the CG), Cn_p 0, Cn_r -0.120, Cn_delta_a +0.0028 (Cnda -0.008 x CL x left: adverse, with the lift), Cn_delta_r
    # -0.065. One SIDE function; the elevator read by CLde and Cmde (CDde reads fcs/elevator-pos-norm, not delayed).
    # Fixed gear, no gear drag. Envelope limits from the trial flights (docs/jsbsim.md, "The c684"): alpha -3.7..5.4
    # deg, sideslip 3.7, bank 12, TAS 51-92 m/s, sink 7.2-8.0 m/s, rate standard deviations at least 2.2 deg/s.
    Case("c684", "C684_glide", "c68", 2138.484, 37.8557,
         (("cm", 0, None, ("in", -0.95, -0.78)), ("cm", 1, -15.0, ("rel", 0.05)), ("cm", 2, -1.25, ("rel", 0.03)),
          ("cm", 3, -8.0, ("rel", 0.12)), ("cl", 3, None, ("in", -0.1205, -0.114)),
          ("cl", 0, None, ("in", -0.07, -0.05)),
          ("cl", 1, None, ("in", -0.46, -0.43)), ("cl", 2, 0.2, ("rel", 0.01)), ("cl", 4, 0.0, ("abs", 1e-4)),
          ("cn", 4, -0.065, ("rel", 1e-3)), ("cn", 0, 0.141, ("abs", 3e-3)), ("cn", 2, -0.12, ("rel", 0.01)),
          ("cn", 3, None, ("in", 0.001, 0.006)), ("cn", 1, 0.0, ("abs", 1e-4))),
         (), 0.30, 1,
         dict(alpha=(-9.0, 9.0), beta=(8.0, 9.0), bank=(20.0, 25.0), speed=(45.0, 105.0), alt_min=300.0,
              rate_std=1.5, rate_std_held=1.5, sink_min=3.0), closure=True),
    # ultrastick (the University of Minnesota UAS Lab's JSBSim Ultra Stick 120, vortex-lattice tables in alpha of
    # every derivative; flown as UltraStick120_glide at 10000 ft: its files in one, no propulsion, direct surfaces
    # +-30 deg): 7.411 kg (16.34 lb), the lab's measured inertia with its product (file ixz 0.1898 kg m^2: the
    # project's Ixz -0.1898). The aerodynamic reference point is 7 mm ahead of the CG and 0.072 m below it. On the
    # 30-s calm flight (derivative_slopes: the model has no alpha-dot term): Cm_alpha -0.80 (dCMm__alpha_rad
    # -0.84..-1.15 and the CMm__zero table), Cm_q -9.0 (dCMm__dqHat_rps -9.4..-10.3), Cm_delta_e -1.15
    # (dCMm__dElev_rad -1.21 less the arm); Cl_beta -0.022 (dCMl__beta_rad changes sign with alpha: +0.012 at -2
    # deg, -0.025 at 2), Cl_p -0.445, Cl_r +0.026 (its table in alpha, -0.020 at -2 deg, +0.021 at 2), Cl_delta_a
    # -0.218 (each aileron's table, 0.109 + 0.109 with the right the mirror), Cl_delta_r -0.004 (the rudder's side
    # force below the CG); Cn_beta 0.070, Cn_p +0.086 (its table: -0.087 at alpha -2 deg, +0.093 at 2), Cn_r
    # -0.082, Cn_delta_a +0.005 (the two ailerons' tables, alpha-dependent), Cn_delta_r -0.038. One SIDE function
    # (CY summed from its tables: CY:scale scales every CY term); the elevator read by six tables (CL, CD, CY, Cl,
    # Cm, Cn). Fixed gear, no gear drag. Its side force is small (0.35 lbf at beta 4 deg): min_lbf 0.3. Envelope
    # limits from the trial and evaluation flights (docs/jsbsim.md, "The ultrastick").
    Case("ultrastick", "UltraStick120_glide", "ultrastik", 16.33846, -0.189797,
         (("cm", 0, None, ("in", -0.95, -0.6)), ("cm", 1, None, ("in", -11.0, -8.5)), ("cm", 2, -1.15, ("rel", 0.03)),
          ("cl", 3, -0.218, ("rel", 0.01)), ("cl", 0, None, ("in", -0.04, -0.005)), ("cl", 1, -0.445, ("rel", 0.02)),
          ("cl", 2, None, ("in", 0.0, 0.06)), ("cl", 4, None, ("in", -0.006, -0.002)),
          ("cn", 4, -0.038, ("rel", 0.03)), ("cn", 0, 0.070, ("rel", 0.05)), ("cn", 2, -0.082, ("rel", 0.03)),
          ("cn", 3, None, ("in", 0.002, 0.008)), ("cn", 1, None, ("in", 0.05, 0.12))),
         (), 0.5235987755982988, 1,
         dict(alpha=(-9.0, 15.0), beta=(9.0, 11.0), bank=(25.0, 30.0), speed=(15.0, 45.0), alt_min=500.0,
              rate_std=1.5, rate_std_held=1.5, sink_min=5.0), n_elevator_reads=6, min_lbf=0.3),
    # b737 (JSBSim's stock Boeing 737, the wheel's 737.xml, Dave Culp and Aeromatic; flown as it is at 250 kt and 12000
    # ft, engines shut down, gear up, its own yaw damper in the loop): 83000 lb empty + 24000 lb of fuel in three
    # tanks on and either side of the centre line (project Ixz -25908.5 kg m^2: <ixz> 8000 slug ft^2 with
    # negated_crossproduct_inertia and the tanks 22 in above the CG). The aerodynamic reference point is 14 in aft of
    # the empty CG, 15 in aft of the loaded one, and 64 in above it. On the 30-s calm flight (derivative_slopes, as the
    # b747's): Cm_alpha -0.99 (Cmalpha -0.6 and the lift aft of the CG), Cm_q -43.4 (Cmq -27 with Cmadot -16: the
    # fit has no alpha-dot), Cm_delta_e -0.987 (Cmde (-1.2 + 0.45 Mach) at Mach 0.55 and CLde through the arm);
    # Cl_beta -0.1439 (Clb -0.09 and the side force, CYb -1, acting 64 in below the reference point), Cl_p -0.400,
    # Cl_r 0.090, Cl_delta_a -0.0815 (Clda (0.1 - 0.0335 Mach) x left), Cl_delta_r 0.010; Cn_beta 0.2729 (Cnb 0.26
    # and the side force aft of the CG), Cn_p 0, Cn_r -0.350, Cn_delta_a 0 (no Cnda function), Cn_delta_r -0.200.
    # One SIDE function; the elevator read by CLde and Cmde (CDde reads fcs/mag-elevator-pos-rad, not delayed). Gear
    # up (CDgear). Envelope limits from the trial flights (docs/jsbsim.md, "The b737"): alpha -7.5..7.6 deg,
    # sideslip 5.8, bank 9.8 (Cl:alpha*beta = 3), TAS 127-217 m/s, sink through the air 15.9-20.3 m/s, lowest 902 m,
    # rate standard deviations at least 1.07 deg/s (the pitch rate, moderate, held-out 20 %).
    Case("b737", "737", "b73", 107000, -25908.5,
         (("cm", 0, None, ("in", -1.2, -0.85)), ("cm", 2, -0.987, ("rel", 0.02)), ("cl", 3, -0.0815, ("rel", 0.02)),
          ("cl", 0, -0.1439, ("rel", 0.02)), ("cl", 1, -0.4, ("rel", 0.02)), ("cl", 2, 0.0901, ("rel", 0.03)),
          ("cl", 4, 0.01, ("rel", 0.05)), ("cn", 4, -0.2, ("rel", 0.02)), ("cn", 0, 0.2729, ("rel", 0.02)),
          ("cn", 2, -0.35, ("rel", 0.02)), ("cn", 3, 0.0, ("abs", 1e-3)), ("cn", 1, 0.0, ("abs", 1e-3))),
         ("CDgear",), 0.3, 1,
         dict(alpha=(-9.0, 9.0), beta=(8.0, 9.0), bank=(15.0, 20.0), speed=(110.0, 240.0), alt_min=500.0,
              rate_std=0.8, rate_std_held=0.7, sink_min=5.0)),
    # c172p (JSBSim's stock Cessna 172P, the wheel's c172p.xml, FlightGear's C172P model; flown as it is at 80 kt and
    # 4000 ft, engine shut down, fixed gear): 1500 lb empty + 200 lb of fuel in two wing tanks; its 180-lb pilot at
    # y = -14 in emptied by the harness (project Ixz 17.74 kg m^2: JSBSim's -13.08 slug ft^2 with the tanks). The
    # c172x's term set with its own numbers. On the 30-s calm flight (derivative_slopes, as the c182's): Cm_alpha
    # -1.64 (Cmalpha -1.8 and the arms; the fit has no alpha-dot: Cm_q -16.5 holds Cmq -12.4 and part of Cmadot
    # -7.27), Cm_delta_e -1.025 (Cmde -1.122 on the wash dynamic pressure, CLDe 0.43 through the arm); Cl_beta -0.0964
    # (the Clb table and the side force: -0.113 at the IC, -0.1138 with closure_slopes on the light flight), Cl_p
    # -0.450, Cl_r 0.165 (the Clr table in alpha), Cl_delta_a -0.218 (ClDa 0.229 x left), Cl_delta_r 0.0235; Cn_beta
    # 0.0577, Cn_r -0.094, Cn_delta_a +0.0058 (Cnda -0.0053 x left: adverse), Cn_delta_r -0.0432. Five SIDE functions
    # (CYb, CYda of value 0, CYdr, CYp, CYr); the elevator read by CLDe and Cmde (CDDe reads its magnitude). Envelope
    # limits from the 50 pre-flown final-evaluation flights (docs/jsbsim.md, "The c172p"): alpha -2.0..8.4 deg,
    # sideslip 8.0 clean and 9.9 with Cl:alpha*beta, bank 15.4 and 16.9, TAS 31.3-55.8 m/s, lowest 385 m, sink
    # through the air 4.9-5.6 m/s, rate standard deviations at least 2.0 deg/s (held-out 20 %).
    Case("c172p", "c172p", "c172q", 1700, 17.739127,
         (("cm", 0, None, ("in", -1.9, -1.4)), ("cm", 2, -1.0247, ("rel", 0.02)), ("cl", 3, -0.2182, ("rel", 0.02)),
          ("cl", 0, -0.0964, ("rel", 0.03)), ("cl", 1, -0.4501, ("rel", 0.02)), ("cl", 2, 0.1649, ("rel", 0.03)),
          ("cl", 4, 0.0235, ("rel", 0.05)), ("cn", 4, -0.0432, ("rel", 0.02)), ("cn", 0, 0.0577, ("rel", 0.03)),
          ("cn", 2, -0.0943, ("rel", 0.03)), ("cn", 3, 0.0058, ("rel", 0.1))),
         (), 23.0 * 0.01745, 5,
         dict(alpha=(-4.0, 11.0), beta=(10.0, 12.0), bank=(20.0, 25.0), speed=(28.0, 60.0), alt_min=300.0,
              rate_std=1.5, rate_std_held=1.5)),
    # eternity (ENAC's Eternity UAV in Paparazzi's JSBSim simulator, Eternity.xml at 5399bd98, GPL-2.0-or-later; the
    # derived Eternity_glide: motor, propeller and throttle channel removed, its elevator moment reading an alias):
    # 0.90 kg (1.98 lb), no product of inertia, one SIDE function (Side_beta), the elevator read by Lift_elevator and
    # the alias (Drag_elevator reads the normalised command, not counted). On the 30-s calm flight
    # (derivative_slopes): Cm_alpha -1.76 (Pitch_alpha -0.3215 and the lift's 2-in arm; no alpha-dot in the fit: Cm_q
    # -12.8 holds Pitch_damp -8.8 and part of Pitch_alphadot -7), Cm_delta_e -0.698 (-0.761 at the IC: the fit's
    # alpha and delta_e share the short period); Cl_beta -0.094, Cl_p -0.4659, Cl_r 0.1345, Cl_delta_a -0.2966,
    # Cl_delta_r -0.00166 (Roll_rudder 0.00166 x the position, delta_r = -position); Cn_beta 0.0653, Cn_r -0.0914,
    # Cn_delta_a +0.021 (adverse), Cn_delta_r -0.043, Cn_p 0 (none in the file). Envelope limits from the pre-flown
    # final-evaluation flights (docs/jsbsim.md, "The eternity"). A tuning aircraft since the twenty-second session.
    Case("eternity", "Eternity_glide", "eternty", 1.98416, 0.0,
         (("cm", 0, None, ("in", -2.0, -1.5)), ("cm", 2, -0.698, ("rel", 0.03)), ("cl", 3, -0.2966, ("rel", 0.01)),
          ("cl", 0, -0.094, ("rel", 0.01)), ("cl", 1, -0.4659, ("rel", 0.01)), ("cl", 2, 0.1345, ("rel", 0.01)),
          ("cl", 4, -0.00166, ("abs", 2e-4)), ("cn", 4, -0.043, ("rel", 0.01)), ("cn", 0, 0.0653, ("rel", 0.03)),
          ("cn", 2, -0.0914, ("rel", 0.02)), ("cn", 3, 0.021, ("rel", 0.03)), ("cn", 1, 0.0, ("abs", 2e-3))),
         (), 15.0 * 0.01745, 1,
         dict(alpha=(-12.0, 8.0), beta=(10.0, 12.0), bank=(25.0, 30.0), speed=(14.0, 32.0), alt_min=1500.0,
              rate_std=4.0, rate_std_held=4.0), min_lbf=0.05),
    # us25e (the University of Minnesota UAS Lab's Ultra Stick 25e with its OpenFlight aerodynamics, UASLab/
    # OpenFlightSim Simulation/aircraft/UltraStick25e, MIT; the derived UltraStick25e_glide: its files in one, no
    # propulsion, direct surfaces +-30 deg): 1.959 kg (4.3189 lb), project Ixz 0.0140 kg m^2 (JSBSim's -0.014), one
    # SIDE function (the sum SIDE__CY of CY__beta, CY__dpHat, CY__drHat, CY__dRud), the elevator read by CL, CD and
    # CMm. On the 30-s calm flight (derivative_slopes) every slope is the file's constant, the arm of the reference
    # point (4.5 mm ahead of the CG) aside: Cm_alpha -0.641 (dCMm__alpha -0.723 and the lift through the arm),
    # Cm_q -13.42 (dCMm__dqHat -13.57; no alpha-dot moment), Cm_delta_e -0.847; Cl_beta -0.0545, Cl_p -0.4496, Cl_r
    # 0.1086, Cl_delta_a -0.1646 (0.0823 x left - 0.0823 x right, right = -left), Cl_delta_r 0.0115; Cn_beta 0.0704,
    # Cn_p 0.1179, Cn_r -0.1828, Cn_delta_a +0.0574 (adverse), Cn_delta_r -0.1804. Envelope limits from the pre-flown
    # final-evaluation flights (docs/jsbsim.md, "The us25e"): alpha -4.4..9.3 deg, sideslip 9.7 clean and 12.2 with
    # Cl:alpha*beta, bank 21.6 and 31.1, TAS 17.2-27.2 m/s, lowest 2379 m, sink through the air 3.7-4.3 m/s, rate
    # standard deviations at least 4.2 deg/s (4.3 held out), surfaces' at least 1.45 / 1.21 / 0.57 deg; its rudder
    # floor is 0.4 deg (its Cn_delta_r is 2.5 times its Cn_beta: truth_fits.assert_in_envelope). A tuning aircraft
    # since the twenty-third session.
    Case("us25e", "UltraStick25e_glide", "us25f", 4.318856, 0.0139987,
         (("cm", 0, None, ("in", -0.70, -0.58)), ("cm", 2, -0.8471, ("rel", 0.01)), ("cl", 3, -0.1646, ("rel", 0.01)),
          ("cl", 0, -0.0545, ("rel", 0.01)), ("cl", 1, -0.4496, ("rel", 0.01)), ("cl", 2, 0.1086, ("rel", 0.01)),
          ("cl", 4, 0.0115, ("rel", 0.02)), ("cn", 4, -0.1804, ("rel", 0.01)), ("cn", 0, 0.0704, ("rel", 0.01)),
          ("cn", 2, -0.1828, ("rel", 0.01)), ("cn", 3, 0.0574, ("rel", 0.01)), ("cn", 1, 0.1179, ("rel", 0.02))),
         (), 0.5235987755982988, 1,
         dict(alpha=(-6.0, 11.0), beta=(11.0, 13.5), bank=(25.0, 35.0), speed=(15.0, 30.0), alt_min=2000.0,
              rate_std=3.0, rate_std_held=3.0, surface_std_min=(1.0, 1.0, 0.4)),
         n_elevator_reads=3, min_lbf=0.05),
    # ka350 (a JSBSim Beechcraft King Air 350 twin turboprop, itaalh/FlightGear-Beechcraft-350ER
    # Aero/KingAir-350.xml at 0298d965, GPL-2.0-or-later; the derived KingAir350_glide: engines, propellers,
    # systems, autopilot inputs, rudder boost and feathered-propeller drag removed, yaw damper off): 13319 lb
    # (9650 empty, 2889 of fuel, 780 of centre-line point masses; the 190-lb pilot at y = -14.7 in emptied), the
    # project's Ixz -1107.36 kg m^2 (JSBSim's +834 slug ft^2 less the pilot's share), three SIDE functions
    # (Side_beta, Side_rudder, Side_yawrate), the elevator read by Lift_elevator, Drag_elevator and
    # Pitch_elevator, the gear's drag (Drag_gear) 0 once retracted. On the 30-s calm flight (derivative_slopes;
    # alpha 0.2 deg mean, -2.1..3.6) the slopes are the file's at that alpha and CL, through the reference point
    # 11 in below and 2.5 in behind the CG: Cm_alpha -0.70 (Pitch_alpha about -0.52 and the lift's arm),
    # Cm_delta_e -1.395 (Pitch_elevator -1.40); Cl_beta -0.0777 (Roll_beta -0.085 at alpha 0 and the side force
    # -0.60 beta through the 11-in arm), Cl_p -0.4998 (-0.50), Cl_r 0.140 (0.06 + 0.22 CL), Cl_delta_a -0.1002
    # (0.100 x 0.5 (left - right), delta_a = -0.5 (left - right)), Cl_delta_r 0.0159 (Roll_rudder 0.018 and
    # Side_rudder 0.16 through the arm); Cn_beta 0.0946 (0.095), Cn_p -0.019 (0.01 - 0.08 CL), Cn_r -0.160
    # (-0.16), Cn_delta_a +0.0085 (adverse: 0.004 + 0.012 CL), Cn_delta_r -0.0949 (-0.095). Envelope limits from
    # the six envelope flights flown in the twenty-third session (docs/jsbsim.md, "The ka350"): alpha -6.4..6.4
    # deg, sideslip 7.4 clean and 6.3 with Cl:alpha*beta, bank 13.8 and 16.2, TAS 69-130 m/s, lowest 1032 m, sink
    # through the air 9.0-9.7 m/s, rate standard deviations at least 2.8 deg/s (2.3 held out), surfaces' at least
    # 1.37 / 2.31 / 1.83 deg. A tuning aircraft since the twenty-fourth session.
    Case("ka350", "KingAir350_glide", "ka305", 13319.0, -1107.3615,
         (("cm", 0, None, ("in", -0.85, -0.55)), ("cm", 2, -1.3946, ("rel", 0.02)), ("cl", 3, -0.1002, ("rel", 0.01)),
          ("cl", 0, -0.0777, ("rel", 0.05)), ("cl", 1, -0.4998, ("rel", 0.01)), ("cl", 2, 0.1399, ("rel", 0.05)),
          ("cl", 4, 0.0159, ("rel", 0.05)), ("cn", 4, -0.0949, ("rel", 0.01)), ("cn", 0, 0.0946, ("rel", 0.01)),
          ("cn", 2, -0.1601, ("rel", 0.02)), ("cn", 3, 0.0085, ("rel", 0.15)), ("cn", 1, -0.019, ("rel", 0.15))),
         ("aero/force/Drag_gear",), 0.2443, 3,
         dict(alpha=(-9.0, 9.0), beta=(10.0, 12.0), bank=(20.0, 25.0), speed=(60.0, 135.0), alt_min=800.0,
              rate_std=2.0, rate_std_held=2.0, sink_min=5.0),
         n_elevator_reads=3, cross_inertia_abs=1e-9),
    # s23 (JSBSim's Short S.23 "Empire" flying boat, Anders Gidenstam's model with DATCOM+ aerodynamics, the jsbsim
    # 1.3.3 wheel's aircraft/Short_S23 checked in under data/jsbsim_models/shorts23, GPL-2.0-or-later; the derived
    # ShortS23_glide: engines, propellers, the hull's water forces and nine systems removed, the aerodynamics
    # inlined, their elevator lookups through an identity alias): 33686 lb (27528 empty, 4704 of fuel in the two
    # inner wing tanks, 1454 of centre-line point masses; the pilot, co-pilot and W/T operator seats at y = +-0.5 m
    # and the four engines' oil at y = +-4 and +-8 m emptied), the project's Ixz +2602.95 kg m^2 (JSBSim's -1920
    # slug ft^2), five SIDE functions (Cyb, Cyp and the zero-valued Cyr, CyDr, CyDa), the elevator read by the
    # alias and the elevator hinge moment (two <property> reads), no gear. On the 30-s calm flight
    # (derivative_slopes; inertial rates, no alpha-dot) the slopes are the DATCOM tables' at the flight's alpha
    # (-2.0 deg mean, -4.4..0.8): Cm_alpha -0.13 (the file's static slope is -0.53 per rad near alpha 0; its
    # Cm_alphadot of about -5 goes into the short fit's Cm_alpha and Cm_q), Cm_delta_e -1.045 (CmDe -1.08); Cl_beta
    # -0.118 (Clb -0.128 at alpha 0), Cl_p -0.323, Cl_r 0.112, Cl_delta_a -0.121 (ClDs4 0.122 per rad of the left
    # aileron, delta_a = -left), Cl_delta_r 0 (ClDr 0); Cn_beta 0.066 (Cnb 0.069), Cn_p -0.045, Cn_r -0.153,
    # Cn_delta_a +0.0068 (adverse: CnDa), Cn_delta_r -0.060 (CnDr -0.06). Envelope limits from the six envelope
    # flights flown in the twenty-fourth session (docs/jsbsim.md, "The s23"): alpha -6.9..3.8 deg, sideslip 7.1
    # clean and 5.4 with Cl:alpha*beta, bank 11.8 and 15.6, TAS 52.6-99.0 m/s, lowest 919 m, sink through the air
    # 6.0-6.3 m/s, rate standard deviations at least 1.46 deg/s (1.12 held out: the yaw rate of a 501090-slug-ft^2
    # Izz), surfaces' at least 1.78 / 2.30 / 2.07 deg. A tuning aircraft since the twenty-fifth session.
    Case("s23", "ShortS23_glide", "s32", 33685.7, 2602.95,
         (("cm", 0, None, ("in", -0.30, -0.05)), ("cm", 2, -1.0449, ("rel", 0.02)), ("cl", 3, -0.1207, ("rel", 0.02)),
          ("cl", 0, -0.1184, ("rel", 0.05)), ("cl", 1, -0.3228, ("rel", 0.05)), ("cl", 2, 0.1121, ("rel", 0.10)),
          ("cl", 4, 0.0, ("abs", 0.005)), ("cn", 4, -0.0602, ("rel", 0.02)), ("cn", 0, 0.066, ("rel", 0.05)),
          ("cn", 2, -0.153, ("rel", 0.05)), ("cn", 3, 0.0068, ("rel", 0.25)), ("cn", 1, -0.0445, ("rel", 0.20))),
         (), 0.3142, 5,
         dict(alpha=(-10.0, 7.0), beta=(10.0, 12.0), bank=(20.0, 25.0), speed=(45.0, 110.0), alt_min=700.0,
              rate_std=1.0, rate_std_held=0.8, sink_min=4.0)),
    # dr1 (JSBSim's Fokker Dr.I triplane, Ron Jensen and Erik Hofman 2008, the jsbsim 1.3.3 wheel's aircraft/dr1
    # checked in under data/jsbsim_models/fokkerdr1, LGPL-2.1 with JSBSim; the derived Dr1_glide: rotary engine,
    # propeller, pushback force and system removed, the Cmde table reading the elevator through an identity alias):
    # 945 lb (895 empty, 50 of fuel on the centre line, no pilot mass), the project's Ixz +0.115 kg m^2 (the tank's:
    # JSBSim's -0.085 slug ft^2), five SIDE functions (CYbeta, CYda = 0, CYdr, CYp, CYr), the elevator read by the
    # alias and CLde (two <property> reads), a fixed gear whose drag is in CDo. On the 30-s calm flight
    # (derivative_slopes; inertial rates, no alpha-dot) Cm_alpha -0.080 (the static slope is -0.18 to -0.20 per rad
    # near alpha 0; closure_slopes reads -0.16 with Cm_alphadot -1.00), Cm_delta_e -0.260 (Cmde's table: -0.275 to
    # -0.283); Cl_beta -0.0287 (Clbeta -0.02 and CYbeta 5.75 in above the CG), Cl_p -0.193, Cl_r -0.043 (Clr
    # -0.0458), Cl_delta_a -0.087 (Clda 0.087 per rad of the left aileron, delta_a = -left), Cl_delta_r -0.0031;
    # Cn_beta 0.0964, Cn_p -0.0109, Cn_r -0.082, Cn_delta_a -0.0552 (proverse: Cnda +0.0552 x left), Cn_delta_r
    # -0.0503. Envelope limits from the six envelope flights flown in the twenty-fifth session (docs/jsbsim.md, "The
    # dr1"): alpha -4.3..4.7 deg, sideslip 8.6 with the pair and 6.5 with Cl:alpha*beta, bank 15.6 and 16.3, TAS
    # 32-54 m/s, lowest 1283 m, sink through the air 6.7-8.0 m/s, rate standard deviations at least 3.0 deg/s (3.8
    # held out), surfaces' at least 1.29 / 1.84 / 1.93 deg. A tuning aircraft since the twenty-sixth session.
    Case("dr1", "Dr1_glide", "dr2", 945.0, 0.115478,
         (("cm", 0, None, ("in", -0.16, -0.02)), ("cm", 2, -0.2601, ("rel", 0.03)), ("cl", 3, -0.087, ("rel", 0.01)),
          ("cl", 0, -0.0287, ("rel", 0.05)), ("cl", 1, -0.1933, ("rel", 0.02)), ("cl", 2, -0.0434, ("rel", 0.10)),
          ("cl", 4, -0.0031, ("abs", 0.001)), ("cn", 4, -0.0503, ("rel", 0.02)), ("cn", 0, 0.0964, ("rel", 0.03)),
          ("cn", 2, -0.0823, ("rel", 0.05)), ("cn", 3, -0.0552, ("rel", 0.05)), ("cn", 1, -0.0109, ("rel", 0.25))),
         (), 0.35, 5,
         dict(alpha=(-8.0, 8.0), beta=(11.0, 12.0), bank=(20.0, 25.0), speed=(28.0, 62.0), alt_min=1000.0,
              rate_std=2.0, rate_std_held=2.0, sink_min=4.0)),
    # navion (JSBSim's Ryan Navion, the jsbsim 1.3.3 wheel's aircraft/L17 checked in under data/jsbsim_models/navion,
    # LGPL-2.1 with JSBSim; the derived Navion_glide: engine and propeller removed, the flap normaliser reading
    # fcs/flap-pos-deg): 2770 lb (2750 empty, 2 x 10 lb of fuel on the centre line), no product of inertia (JSBSim's
    # Ixz reads 0 to 1e-33), one SIDE function (CYb), the elevator read by CLde and Cmde (two <property> reads), a
    # retractable gear whose CDgear vanishes once up. On the 30-s calm flight (derivative_slopes; inertial rates, no
    # alpha-dot) Cm_alpha -0.611 (the static slope is -0.68 to -0.72 per rad near alpha 0; closure_slopes reads
    # -0.716 with Cm_alphadot -4.76), Cm_delta_e -0.828 (Cmde -0.923 + 0.324 Mach); Cl_beta -0.0864 (Clb -0.074 and
    # CYb 8.3 in below the reference point), Cl_p -0.410, Cl_r 0.107, Cl_delta_a -0.1243 (Clda 0.134 - 0.0385 Mach per
    # rad of the left aileron, delta_a = -0.5 (left - right)), Cl_delta_r 0.0107; Cn_beta 0.071, Cn_p -0.0575, Cn_r
    # -0.125, Cn_delta_a +0.0035 (adverse: Cnda -0.0035 x left), Cn_delta_r -0.072: the file's constants. Envelope
    # limits from the six envelope flights flown in the twenty-sixth session (docs/jsbsim.md, "The navion"): alpha
    # -4.9..5.3 deg, sideslip 6.8 clean and 6.0 with Cl:alpha*beta, bank 14.5 and 12.8, TAS 56.9-101.8 m/s, lowest
    # 1288 m, sink through the air 11.3-12.6 m/s (lift-to-drag about 7-8 at the sweep's speeds), rate standard
    # deviations at least 3.35 deg/s (3.34 held out), surfaces' at least 1.43 / 1.68 / 1.66 deg. A tuning aircraft
    # since the twenty-seventh session.
    Case("navion", "Navion_glide", "navio", 2770.0, 0.0,
         (("cm", 0, None, ("in", -0.75, -0.45)), ("cm", 2, -0.8283, ("rel", 0.03)), ("cl", 3, -0.1243, ("rel", 0.01)),
          ("cl", 0, -0.0864, ("rel", 0.03)), ("cl", 1, -0.41, ("rel", 0.02)), ("cl", 2, 0.107, ("rel", 0.05)),
          ("cl", 4, 0.0107, ("abs", 0.001)), ("cn", 4, -0.072, ("rel", 0.02)), ("cn", 0, 0.071, ("rel", 0.03)),
          ("cn", 2, -0.125, ("rel", 0.05)), ("cn", 3, 0.0035, ("rel", 0.25)), ("cn", 1, -0.0575, ("rel", 0.10))),
         ("CDgear",), 0.30, 1,
         dict(alpha=(-8.0, 8.0), beta=(10.0, 11.0), bank=(20.0, 25.0), speed=(48.0, 115.0), alt_min=900.0,
              rate_std=2.5, rate_std_held=2.5, sink_min=6.0)),
    # fokker50 (JSBSim's Fokker 50, the jsbsim 1.3.3 wheel's aircraft/fokker50 checked in under
    # data/jsbsim_models/fokker50, LGPL-2.1 with JSBSim; the derived Fokker50_glide: engines, propellers, the EEC and
    # Thruster channels, the three propwash terms and the yaw damper removed): 31900 lb (29700 empty, 2 x 1100 lb of
    # fuel 3 in either side of the centre line), JSBSim's Ixz 5.7e-4 slug ft^2 (the tanks' x and z offsets from the
    # CG; the file has no <ixz>), four SIDE functions (CYb, the Reynolds-number table Side_roll_rate, Side_yaw_rate,
    # Side_rudder), the elevator read by CLde and Cmde (two <property> reads), a retractable gear whose CDgear
    # vanishes once up. On the 30-s calm flight (derivative_slopes; inertial rates, no alpha-dot) Cm_alpha -1.847
    # (Cmalpha -1.876 and the lift and drag 24.9 in below the reference point; closure_slopes -1.976 with Cm_alphadot
    # -8.14), Cm_delta_e -1.377 (Cmde -1.628 + 0.6105 Mach, and CLde); Cl_beta -0.0377 (Clb a table in alpha and
    # Reynolds number, and CYb's arm), Cl_p -0.514, Cl_r 0.079 (Clr a table in alpha and Reynolds number), Cl_delta_a
    # -0.1288 (Clda 0.15 - 0.05625 Mach per rad of the left aileron, delta_a = -0.5 (left - right)), Cl_delta_r
    # 0.0155; Cn_beta 0.1809, Cn_p -0.0806 (Yaw_rol_rate, a table in Reynolds number on the inertial p), Cn_r -0.174,
    # Cn_delta_a +0.008 (adverse: Cnda -0.008 x left), Cn_delta_r -0.110. Envelope limits from the six envelope
    # flights flown in the twenty-seventh session (docs/jsbsim.md, "The fokker50"): alpha -8.8..2.6 deg, sideslip 6.6
    # clean and with Cl:alpha*beta, bank 13.8 and 16.9, TAS 83-156 m/s, lowest 396 m (the moderate flight; it sinks
    # 19.4 m/s through the air), sink through the air 17.0-19.4 m/s, rate standard deviations at least 2.09 deg/s
    # (1.71 held out), surfaces' at least 2.23 / 2.24 / 2.11 deg. Untouched: the twenty-seventh session's final
    # evaluation aircraft.
    Case("fokker50", "Fokker50_glide", "fokker5", 31900.0, -0.000778749,
         (("cm", 0, None, ("in", -2.3, -1.5)), ("cm", 2, -1.3766, ("rel", 0.03)), ("cl", 3, -0.1288, ("rel", 0.02)),
          ("cl", 0, -0.0377, ("rel", 0.08)), ("cl", 1, -0.5138, ("rel", 0.02)), ("cl", 2, None, ("in", 0.05, 0.12)),
          ("cl", 4, 0.0155, ("abs", 0.002)), ("cn", 4, -0.1102, ("rel", 0.02)), ("cn", 0, 0.1809, ("rel", 0.03)),
          ("cn", 2, -0.1739, ("rel", 0.05)), ("cn", 3, 0.008, ("rel", 0.25)), ("cn", 1, None, ("in", -0.11, -0.06))),
         ("CDgear",), 0.30, 4,
         dict(alpha=(-11.0, 5.0), beta=(10.0, 11.0), bank=(20.0, 25.0), speed=(70.0, 175.0), alt_min=250.0,
              rate_std=1.5, rate_std_held=1.2, sink_min=12.0)),
)
BY_NAME = {c.name: c for c in CASES}


def _params(cases=CASES, flight=True):
    """``cases`` as pytest params: slow unless the case's flight checks are default (or ``flight``
    is False: the names' check, always default)."""
    return [pytest.param(c, id=c.name, marks=() if (c.default or not flight) else pytest.mark.slow) for c in cases]


_FLIGHTS: dict = {}


@pytest.fixture(scope="module")
def short_flight(tmp_path_factory):
    """``short_flight(name)``: the aircraft's 30-s flight ("calm", the harness's light until the fifteenth
    session; seed 1, AHRS AOA_SSA), flown once per module: the harness ``FlightFiles``. The sign-map
    checks fit derivatives to the truth, which gusts of MIL-F-8785C light turbulence blur."""
    def get(name):
        if name not in _FLIGHTS:
            cfg = FlightConfig(name, duration_s=30.0, turbulence="calm", seed=1)
            _FLIGHTS[name] = make_flight(cfg, tmp_path_factory.mktemp(name))
        return _FLIGHTS[name]
    return get


@pytest.mark.parametrize("case", _params(flight=False))
def test_names_resolve_and_roles(case):
    """The harness name and the JSBSim model name resolve in any case, a near miss is refused; the
    untouched aircraft alone is untouched (and held out), every other aircraft is a tuning aircraft with a bare
    label."""
    from benchmarks.jsbsim_harness.aircraft import HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, UNTOUCHED_AIRCRAFT, summary_label

    assert_names_resolve(case.name, case.model, case.typo)
    if case.untouched:
        assert UNTOUCHED_AIRCRAFT == HELD_OUT_AIRCRAFT == (case.name,) and case.name not in TUNING_AIRCRAFT
        assert summary_label(case.name) == f"{case.name} (untouched)"
    else:
        assert case.name in TUNING_AIRCRAFT and case.name not in HELD_OUT_AIRCRAFT
        assert summary_label(case.name) == case.name
    used = {"pa28", "j3cub", "c182", "t37", "t6", "b747", "f16", "f4n", "rascal", "sgs126", "asw20", "iar80", "c684",
            "ultrastick", "b737", "c172p", "eternity", "us25e", "ka350", "s23", "dr1", "navion", "fokker50"}
    assert used <= set(TUNING_AIRCRAFT)


@pytest.mark.parametrize("case", _params())
def test_truth_is_rigid_body_consistent_with_the_airframe_file(case, short_flight):
    """JSBSim's aero moments equal J w_dot + w x J w with the checked-in airframe's J, its Ixz
    included; in the glide every non-gravity force and moment is aerodynamic (engines stopped: no
    propeller windmills; "direct" thrusters give no force once stopped); the mass is the model's
    (off-centre point masses emptied by the harness); the product of inertia is Ixz alone, the
    model's (``negated_crossproduct_inertia``: the project's Ixz is JSBSim's with the sign flipped)."""
    files = short_flight(case.name)
    assert_rigid_body_glide(files, mass_lb=case.mass_lb)
    const, af = files.recording.constants, load_airframe(files.airframe)
    assert abs(const["Ixy"]) <= case.cross_inertia_abs and abs(const["Iyz"]) <= case.cross_inertia_abs
    assert const["Ixz"] == pytest.approx(case.ixz, rel=1e-4, abs=1e-9)
    assert -af.inertia[0, 2] == pytest.approx(const["Ixz"], rel=1e-5, abs=1e-9)


@pytest.mark.parametrize("case", _params())
def test_sign_map_gives_the_project_conventions(case, short_flight):
    """Least squares on the exact truth: Cm_delta_e, Cl_delta_a, Cn_delta_r, Cm_alpha, Cl_p < 0,
    Cn_beta > 0, and the derivatives the case lists at its model's numbers (Cm on JSBSim's own pitch
    regressors where the case says ``closure``)."""
    rec = short_flight(case.name).recording
    cm, cl, cn = closure_slopes(rec) if case.closure else derivative_slopes(rec)
    assert cm[0] < 0 and cm[2] < 0 and cl[1] < 0 and cl[3] < 0 and cn[0] > 0 and cn[4] < 0, (cm, cl, cn)
    got = {"cm": cm, "cl": cl, "cn": cn}
    for coef, i, target, tol in case.slopes:
        v = got[coef][i]
        if tol[0] == "in":
            assert tol[1] < v < tol[2], (coef, i, v)
        else:
            assert v == pytest.approx(target, **{tol[0]: tol[1]}), (coef, i, v)


@pytest.mark.parametrize("case", [p for p in _params() if p.values[0].gear_zero])
def test_the_harness_flies_it_with_its_gear_up(case):
    """``gear_up``: the retractable gear (5 s from down to up) is up before the log starts (the 15-s
    settling phase), so its drag and any gear-down stability term read 0 (the c182's gear is fixed)."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft(case.name)
    assert spec.gear_up and not aircraft("c182").gear_up
    fdm = load_model(spec, 1 / 200)
    _set_ic(fdm, spec, FlightConfig(case.name, turbulence="none"))
    for _ in range(int(FlightConfig(case.name).settle_s * 200)):
        fdm.run()
    assert fdm["gear/gear-pos-norm"] == 0.0
    assert all(fdm[n if "/" in n else f"aero/coefficient/{n}"] == 0.0 for n in case.gear_zero)


@pytest.mark.slow
def test_the_b747_keeps_its_own_yaw_damper():
    """The B747's FCS adds 2 x ``velocities/r-aero-rad_sec`` to the normalised rudder (clipped to
    +-0.2), which the harness cannot switch off: the harness's own yaw damper is off (k_r = 0) and the
    model's moves the rudder the aerodynamics read against a yaw rate."""
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    spec = aircraft("b747")
    assert spec.gains[5] == 0.0
    fdm = load_model(spec, 1 / 200)
    _set_ic(fdm, spec, FlightConfig("b747", turbulence="none"))
    for _ in range(int(FlightConfig("b747").settle_s * 200)):
        fdm.run()
    fdm["ic/r-rad_sec"] = 0.05
    fdm.run_ic()
    fdm.run()
    assert fdm["fcs/yaw-damper-final"] == pytest.approx(2 * fdm["velocities/r-aero-rad_sec"], rel=0.02)
    assert fdm["fcs/rudder-pos-rad"] == pytest.approx(0.35 * fdm["fcs/yaw-damper-final"], rel=1e-9)
    assert fdm["fcs/rudder-pos-rad"] > 0.03


@pytest.mark.parametrize("case", _params())
def test_tlog_decodes_and_the_servos_map_back_to_the_surfaces(case, short_flight):
    """The pipeline's decoder reads the aircraft's .tlog; its SERVO_OUTPUT_RAW, through the checked-in
    airframe file, gives JSBSim's deflections within PWM quantisation (0.1 deg), every surface moving."""
    assert_servos_map_back(short_flight(case.name))


@pytest.mark.parametrize("case", _params())
def test_every_hidden_effect_shows_in_jsbsims_own_forces_and_moments(case):
    """On the aircraft's XML every effect does what ``effects.py`` specifies, in JSBSim's own
    properties at one initial condition (alpha 4 deg, sideslip 4 deg, fixed surfaces): each injected
    moment is k alpha^2, k alpha beta or k delta_a times qbar S c|b and exactly the change of JSBSim's
    total aerodynamic moment; CY:scale multiplies the sum of its SIDE functions (and the wind-axis
    side force) by k; the delay holds the elevator the aerodynamics read 24 frames (0.12 s at 200 Hz)
    behind the surface (``static_checks.assert_hidden_effects_in_jsbsim``)."""
    assert_hidden_effects_in_jsbsim(aircraft(case.name), case.elevator_end, n_side=case.n_side,
                                    n_elevator_reads=case.n_elevator_reads, min_lbf=case.min_lbf)


@pytest.mark.slow
@pytest.mark.parametrize("case", _params())
def test_airspeed_bias_reaches_the_logged_airspeed(case, short_flight, tmp_path):
    """``bias:airspeed`` = 2 m/s of TAS in a second log of the aircraft's flight: 2 sqrt(rho / rho0)
    m/s more decoded airspeed, sample by sample."""
    assert_airspeed_bias_in_log(short_flight(case.name), tmp_path)


#: Evaluation flights that leave the envelope since the turbulence relabel (measured by turb15, fifteenth
#: session; docs/benchmarks.md "Fifteenth session, turb15"): (aircraft, seed, turbulence, plan, effects) ->
#: why. The knock-it-off limits are not widened for them.
ENVELOPE_EXITS = {
    ("sgs126", 1, "light", "sweep", (("Cl:alpha*beta", 3.0),)):
        "knocked off at bank 45.0 deg at 17.4 s: the reversed dihedral effect in light turbulence",
    ("f4n", 2, "moderate", "standard", ()):
        "the 120-s test flight sinks to 189 m (33 m/s); eval_jsbsim's 90-s flight stays above 1334 m",
}


@pytest.mark.slow
@pytest.mark.parametrize("case", _params())
@pytest.mark.parametrize("seed,turbulence,plan,effects", ENVELOPE_FLIGHTS)    # with the evaluation's pair
def test_evaluation_flights_stay_in_the_envelope_with_every_axis_excited(request, tmp_path, case, seed, turbulence,
                                                                         plan, effects):
    """Each flight the final evaluation flies (120 s) keeps inside the aircraft's envelope, read from
    ``flight_envelope`` of the truth file: no knock-it-off, alpha, sideslip, bank and TAS within the
    case's limits (sideslip and bank wider with Cl:alpha*beta = 3, whose reversed dihedral rolls it),
    every rate and surface moving (also in the held-out 20 %), the glide still above the case's
    lowest altitude. The limits' sources are in each aircraft's docs/jsbsim.md section. Two flights
    leave the envelope in MIL-F-8785C light/moderate turbulence (fifteenth session's relabel) and are
    strict expected failures, reported rather than hidden by wider limits (:data:`ENVELOPE_EXITS`)."""
    reason = ENVELOPE_EXITS.get((case.name, seed, turbulence, plan, tuple(map(tuple, effects))))
    if reason:
        request.applymarker(pytest.mark.xfail(strict=True, reason=reason))
    assert_in_envelope(evaluation_envelope(case.name, seed, turbulence, plan, effects, tmp_path), **case.envelope)


@pytest.mark.slow
@pytest.mark.parametrize("case", [p for p in _params()
                                  if p.values[0].name in ("rascal", "sgs126", "asw20", "iar80", "c684", "ultrastick",
                                                          "b737", "c172p", "eternity", "us25e", "ka350",
                                                          "s23", "dr1", "navion", "fokker50")])
def test_eval_scripts_fly_it_without_scoring_it(case, tmp_path, capsys, monkeypatch):
    """The JSBSim model name in capitals resolves to the harness name in both scripts; with
    ``--fly-only`` they fly into ``--work`` / ``--out``, say so for the untouched aircraft alone, reuse
    the flights on a second run and score nothing."""
    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose

    monkeypatch.setattr(eval_jsbsim_diagnose, "DURATION_S", 2.0)
    runs = ((eval_jsbsim.main, ["--turbulence", "light", "--duration", "2", "--work", str(tmp_path / "f")], 1, 1),
            (eval_jsbsim_diagnose.main, ["--clean-seeds", "--pairs", "--effects", "delay:delta_e",
                                         "--out", str(tmp_path / "d")], -3, 3))      # reference + 2 sizes
    for main, extra, column, n in runs:
        argv = ["--aircraft", case.model.upper(), "--seeds", "1", *extra, "--fly-only"]
        assert main(argv) == 0 and main(argv) == 0
        cap = capsys.readouterr()
        # the flights' lines alone: JSBSim's loader prints its own warnings there too (the c684's one-argument
        # <product> ground-effect functions)
        lines = [ln for ln in cap.out.splitlines() if " flown " in ln or " reused " in ln]
        assert [ln.split()[column] for ln in lines] == ["flown"] * n + ["reused"] * n, cap.out
        assert (f"{case.name} is the untouched aircraft" in cap.err) == case.untouched
    assert read_log(tmp_path / "f" / f"{case.name}-light-s1-ahrs.tlog").streams["servo"].t.size > 50
    assert not (tmp_path / "d" / "results.jsonl").exists() or not (tmp_path / "d" / "results.jsonl").read_text()
