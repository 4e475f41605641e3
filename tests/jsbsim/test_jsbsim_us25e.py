"""The us25e in the JSBSim harness: the twenty-second session's untouched aircraft, a tuning aircraft since the
twenty-third session (docs/jsbsim.md, "The us25e").

The model is the University of Minnesota UAS Laboratories' JSBSim Ultra Stick 25e with its OpenFlight aerodynamics
(UASLab/OpenFlightSim ``Simulation/aircraft/UltraStick25e``, the main file at 06a2b255, its parts at 1650a6e3, MIT),
a 1.96-kg, 1.27-m-span research UAV whose aerodynamics are one constant per derivative on all six axes. Its files
are checked in under ``data/jsbsim_models/ultrastick25e/`` and flown as the derived model ``UltraStick25e_glide``
(``derived.py``): the MetricsOpenFlight, MassOpenFlight, Gear and AeroOpenFlight files in one, no propulsion, direct
surfaces (+-30 deg) for the lab's control laws, actuators and sensors.

The checks here use the files and JSBSim's own properties (the harness's initial condition, ``run_ic``, no
turbulence: a mechanism check); none of them flies the harness:

- the checked-in files are the README's, and the derivation changes no number;
- the FCS maps the commands straight to the surfaces (+-30 deg, the right aileron the left's mirror), flaps 0;
  no engine, no external force;
- it is statically stable about the CG, and its elevator, ailerons and rudder act as its constants say.

The summaries' label test moves on with the untouched aircraft (twenty-third session: ``test_jsbsim_ka350.py``).

The checks it shares with the other aircraft are in ``test_jsbsim_roster.py``: names, rigid body, sign map, .tlog,
hidden effects, airspeed bias, the evaluation's flights in the envelope and ``--fly-only``. All of them but the names
are slow.

No pipeline fit, GP, diagnosis or scoring ran on the us25e before its final evaluation (twenty-second session); it
is a tuning aircraft since.
"""

import pytest

from benchmarks.jsbsim_harness import aircraft
from pytest import approx
from model_checks import assert_openflightsim_assembly, assert_openflightsim_direct_surfaces
from static_checks import assert_lateral_derivatives, assert_pitch_derivatives, ic_state

DIR = "data/jsbsim_models/ultrastick25e"
#: file -> (bytes, SHA-256), as the README lists them.
FILES = {
    "UltraStick25e.xml": (550, "8d3e72ec043cd4d968e2d90f24f8f5d8839aefc39db9185891f01e1317a42b8e"),
    "AeroOpenFlight.xml": (26790, "43ff5c1ea59acfebf1ea049b603d2d2451c203f0bbb40bb167955d543a80d7e5"),
    "MassOpenFlight.xml": (426, "cddd379a722134ef3a1aa7d68c28360053ab0cc7ac58aede39174604c4e31c37"),
    "MetricsOpenFlight.xml": (521, "ce119e72d565d7a7c2db14aa3cb8f13400b06d37d6db1afb24117ec413df1497"),
    "Gear.xml": (1677, "7330a6bf1a1fca3f33c260eeb334cd094700c2c65fd4c8caf928526c61cefc9d"),
}
SURFACE = 0.5235987755982988      # every surface's end, rad (the lab's actuator clip, 30 deg)


def test_the_derivation_assembles_the_files_and_changes_no_number():
    """The checked-in files are the README's (bytes and SHA-256). ``UltraStick25e_glide`` holds
    ``MetricsOpenFlight.xml``, ``MassOpenFlight.xml`` and ``Gear.xml`` as they are, an empty ``<propulsion>``, a
    direct ``<flight_control>`` and ``AeroOpenFlight.xml`` with its reads of ``fcs/posElev_rad`` (3) and
    ``fcs/posRud_rad`` (4) renamed ``fcs/elevator-pos-rad`` and ``fcs/rudder-pos-rad`` (nothing else: the same
    functions and numbers); no system. The spec's notes carry the derived XML's hash."""
    assert aircraft("us25e").model == "UltraStick25e_glide"
    assert_openflightsim_assembly("us25e", DIR, FILES, (("metrics", "MetricsOpenFlight.xml"),
                                  ("mass_balance", "MassOpenFlight.xml"), ("ground_reactions", "Gear.xml"),
                                  ("aerodynamics", "AeroOpenFlight.xml")), {"fcs/posElev_rad": 3, "fcs/posRud_rad": 4})


def test_the_us25e_flies_direct_surfaces_without_engine_or_external_force():
    """The FCS maps each command straight to its surface, +-30 deg (``aerosurface_scale``, no actuator dynamics,
    no damper): elevator -> ``fcs/elevator-pos-rad``, rudder -> ``fcs/rudder-pos-rad``, aileron ->
    ``fcs/posAilL_rad`` and ``fcs/posAilR_rad`` = -left (the harness reads both, delta_a = -0.5 (left - right) =
    -left); the flaps stay 0. No engine; after 50 frames every non-gravity force and moment is aerodynamic (1.959
    kg: 4.32 lb). A yaw rate does not move the rudder."""
    assert_openflightsim_direct_surfaces("us25e", SURFACE, 1.0)
    assert ic_state(aircraft("us25e"), 2.0)["inertia/weight-lbs"] == pytest.approx(1.959 / 0.45359237, rel=1e-6)


def test_the_us25e_is_statically_stable_and_its_controls_act_as_its_constants_say():
    """JSBSim's moments about the CG at fixed surfaces (``run_ic`` at the harness's initial condition, Mach 0.072).
    The aerodynamic reference point is 4.5 mm ahead of the CG at its height; ``dCMm__alphaDot`` is 0.

    - **Pitch:** Cm falls with alpha at -0.641 per rad over -4..8 deg (``dCMm__alpha`` -0.723 and the lift
      ``dCL__alpha`` 4.58 through the 4.5-mm arm, 0.018 chords); the file's ``CMm`` coefficient is ``CMm__zero``
      -0.0278 at alpha 0 (its sum reads all nine terms, the stray ``>`` of the stored file aside); per rad of
      elevator -0.847 (``dCMm__dElev`` -0.8488 and ``dCL__dElev`` 0.0983 through the arm).
    - **Roll and yaw:** per rad of left aileron (the right its mirror) Cl +0.1646 (0.0823 + 0.0823: the project's
      Cl_delta_a -0.1646) and Cn -0.0574 (adverse: Cn_delta_a +0.0574); per rad of rudder Cn -0.1804 (``dCMn__dRud``
      -0.1811 and the rudder's side force through the arm) and Cl +0.0115; Cl_beta -0.0545 and Cn_beta 0.0704
      (``dCMn__beta`` 0.0723 less the side force's arm), the same at every alpha (constants).
    """
    spec = aircraft("us25e")
    per_rad = approx(-0.641, abs=0.003)
    assert_pitch_derivatives(spec, ((-4.0, 0.0, per_rad), (0.0, 4.0, per_rad), (4.0, 8.0, per_rad)),
                             ((-0.3, approx(-0.847, abs=0.002)), (0.3, approx(-0.847, abs=0.002))), alpha_e=2.0,
                             travel=(SURFACE, SURFACE), term=None)
    assert ic_state(spec, 0.0)["aero/coefficient/CMm"] == pytest.approx(-0.0278, abs=1e-9)
    beta = (approx(-0.0545, abs=1e-4), approx(0.0704, abs=3e-4))
    assert_lateral_derivatives(spec, (approx(0.1646, abs=1e-4), approx(-0.0574, abs=1e-4)),
                               (approx(-0.1804, abs=2e-4), approx(0.0115, abs=1e-4)),
                               {-2.0: beta, 2.0: beta, 6.0: beta},
                               alpha_deg=2.0, aileron_prop="fcs/posAilL_rad")
