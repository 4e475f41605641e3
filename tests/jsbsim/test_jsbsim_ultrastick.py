"""The ultrastick in the JSBSim harness: the eighteenth session's untouched aircraft, a tuning aircraft since the
nineteenth (docs/jsbsim.md, "The ultrastick").

The model is the University of Minnesota UAS Laboratories' JSBSim Ultra Stick 120 (UASLab/OpenFlightSim
``Simulation/aircraft/UltraStick120`` at commit 1650a6e3, MIT), a 7.4-kg research UAV whose aerodynamics are
vortex-lattice tables in alpha of every derivative of the six coefficients. Its files are checked in under
``data/jsbsim_models/ultrastick120/`` and flown as the derived model ``UltraStick120_glide`` (``derived.py``):
the Metrics, Mass, Gear and Aero files in one, no propulsion, direct surfaces (+-30 deg) for the lab's control
laws, actuators and sensors. It is flown at 45 kt (``ic/vc-kts``) and 10000 ft.

The checks here use the files and JSBSim's own properties (the harness's initial condition, ``run_ic``, no
turbulence: a mechanism check); none of them flies the harness:

- the checked-in files are the README's, and the derivation changes no number;
- the FCS maps the commands straight to the surfaces (+-30 deg, the right aileron the left's mirror), flaps 0;
  no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its tables say.

The summaries' label test moved to ``test_jsbsim_b737.py`` in the nineteenth session (the b737 is untouched now).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign
map, .tlog, hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``.
All of them but the names are slow.

No pipeline fit, GP, diagnosis or scoring ran on the ultrastick before the eighteenth session's final evaluation.
"""

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_openflightsim_assembly, assert_openflightsim_direct_surfaces
from static_checks import assert_lateral_derivatives, assert_pitch_derivatives

DIR = "data/jsbsim_models/ultrastick120"
#: file -> (bytes, SHA-256), as the README lists them.
FILES = {
    "UltraStick120.xml": (554, "f3126cd0de1ca74d9372d967e4c90cf57452e15572f13990c6fc67447932ba12"),
    "Aero.xml": (64633, "51cc33123dfd437a398a4f9f720a1ffa8613da5a482fdcf831bf82759acf0751"),
    "Mass.xml": (430, "16d06b38088ffe963d9916d4bcca67b083f939b1e9b9dbc94d87b7a841c7a4c3"),
    "Metrics.xml": (561, "a1fcb576eb571091fe01c46f73a9d53d651bdc9636005ed8a9db818ecc318e42"),
    "Gear.xml": (1702, "fbfa16e648947d212bbcbd28e1ebb94a3d8bab3d4fc9b88d52455bf134b02c7b"),
}
SURFACE = 0.5235987755982988      # every surface's end, rad (the lab's actuator clip, 30 deg)


def test_the_derivation_assembles_the_files_and_changes_no_number():
    """The checked-in files are the README's (bytes and SHA-256). ``UltraStick120_glide`` holds ``Metrics.xml``,
    ``Mass.xml`` and ``Gear.xml`` as they are, an empty ``<propulsion>``, a direct ``<flight_control>`` and
    ``Aero.xml`` with its reads of ``fcs/posElev_rad`` and ``fcs/posRud_rad`` renamed ``fcs/elevator-pos-rad``
    and ``fcs/rudder-pos-rad`` (nothing else: the same functions, tables and numbers); no system. The spec's notes
    carry the derived XML's hash."""
    assert aircraft("ultrastick").model == "UltraStick120_glide"
    assert_openflightsim_assembly("ultrastick", DIR, FILES, (("metrics", "Metrics.xml"), ("mass_balance", "Mass.xml"),
                                  ("ground_reactions", "Gear.xml"), ("aerodynamics", "Aero.xml")),
                                  {"fcs/posElev_rad": 6, "fcs/posRud_rad": 6})


def test_the_ultrastick_flies_direct_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface, +-30 deg (``aerosurface_scale``, no actuator dynamics,
    no damper): elevator -> ``fcs/elevator-pos-rad``, rudder -> ``fcs/rudder-pos-rad``, aileron ->
    ``fcs/posAilL_rad`` and ``fcs/posAilR_rad`` = -left (each positive trailing edge down: the harness reads both,
    delta_a = -0.5 (left - right) = -left); the flaps stay 0. No engine; after 50 frames every non-gravity
    force and moment is aerodynamic. A yaw rate does not move the rudder."""
    assert_openflightsim_direct_surfaces("ultrastick", SURFACE, 5.0)      # it weighs 16.3 lb


def test_the_ultrastick_is_statically_stable_and_its_controls_act_as_its_tables_say():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition). The
    aerodynamic reference point is 7 mm ahead of the CG and 0.072 m below it; the model has no alpha-dot term.

    - **Pitch:** Cm falls with alpha: -0.93 per rad between -4 and 0 deg, -0.70 between 0 and 4 deg
      (``dCMm__alpha_rad`` -0.81..-1.15 per rad in its table, with the ``CMm__zero`` table); per rad of
      elevator -1.196 at alpha 2 deg (``dCMm__dElev_rad`` -1.206 there, less the lift and drag of the
      elevator through the arm).
    - **Roll and yaw:** per rad of left aileron (the right its mirror) Cl +0.2172 at alpha 2 deg (the two
      tables: 0.1089 + 0.1089; the project's Cl_delta_a -0.217) and Cn -0.0038 (-0.0019 - 0.0019: an
      alpha-dependent cross term, Cn_delta_a +0.0038 in the project's sign), the same either side; per rad of
      rudder Cn -0.0392 (``dCMn__dRud_rad`` -0.0395) and Cl -0.0037 (-0.0006 and the rudder's side force
      acting below the CG); Cl_beta changes sign with alpha (+0.021 at -2 deg, -0.016 at 2, -0.037 at 6:
      its ``dCMl__beta_rad`` table), Cn_beta 0.068-0.075.
    """
    spec = aircraft("ultrastick")
    assert_pitch_derivatives(spec, ((-4.0, 0.0, approx(-0.930, abs=0.01)), (0.0, 4.0, approx(-0.695, abs=0.01))),
                             ((-0.3, approx(-1.196, abs=0.005)), (0.3, approx(-1.196, abs=0.005))), alpha_e=2.0,
                             travel=(SURFACE, SURFACE), term=None)
    assert_lateral_derivatives(spec, (approx(0.2172, abs=1e-3), approx(-0.0038, abs=3e-4)),
                               (approx(-0.0392, abs=5e-4), approx(-0.0037, abs=5e-4)),
                               {-2.0: (approx(0.0213, abs=5e-4), approx(0.0680, abs=5e-4)),
                                2.0: (approx(-0.0164, abs=5e-4), approx(0.0683, abs=5e-4)),
                                6.0: (approx(-0.0374, abs=5e-4), approx(0.0745, abs=5e-4))},
                               alpha_deg=2.0, rest=1e-5, rudder_cmds=(0.3,), aileron_prop="fcs/posAilL_rad")
