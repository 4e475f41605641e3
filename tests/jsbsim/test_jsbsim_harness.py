"""The JSBSim harness itself: exact truth consistent with rigid-body dynamics, sign conventions,
generated airframe files, the .tlog as the pipeline decodes it."""

import dataclasses

import numpy as np
import pytest

from benchmarks.jsbsim_harness import AIRCRAFT, FlightConfig, aircraft, fly
from benchmarks.jsbsim_harness.airframes import airframe_doc
from truth_fits import derivative_slopes, rigid_body_residual, servo_against_truth
from gcs_sysid.airframe import load_airframe
from gcs_sysid.telemetry import read_log


def test_truth_moments_are_about_the_cg_with_the_airframe_inertia(fast_flight):
    """JSBSim's aero moments equal J w_dot + w x J w with the airframe file's J (so the Ixz sign,
    the point masses and the moment reference point are right), and the specific force times the
    mass equals the aero force (a glide: no other non-gravity force)."""
    tr, af = fast_flight.recording.truth, load_airframe(fast_flight.airframe)
    rel = rigid_body_residual(tr, af.inertia)
    assert (rel < 2e-3).all(), rel          # airframe values are rounded to 6 digits
    for a in "xyz":
        np.testing.assert_allclose(tr[f"F{a}_aero"], tr[f"F{a}_total"], atol=1e-9)
    assert af.mass == pytest.approx(fast_flight.recording.constants["mass"], rel=1e-5)


def test_truth_signs_follow_the_project_conventions(fast_flight):
    """Least squares on the exact truth: Cm_delta_e, Cl_delta_a, Cn_delta_r, Cm_alpha, Cl_p < 0 and
    Cn_beta > 0 in the project's conventions (docs/conventions.md)."""
    cm, cl, cn = derivative_slopes(fast_flight.recording)
    assert cm[0] < 0 and cm[2] < 0
    assert cl[1] < 0 and cl[3] < 0
    assert cn[0] > 0 and cn[4] < 0


@pytest.mark.parametrize("name", list(AIRCRAFT))
def test_airframe_files_match_jsbsim(name):
    """The checked-in airframe files are what the generator makes from the JSBSim model now."""
    spec = AIRCRAFT[name]
    doc, af = airframe_doc(spec), load_airframe(spec.airframe_path)
    assert af.mass == pytest.approx(doc["mass"], rel=1e-6)
    np.testing.assert_allclose(np.diag(af.inertia), [doc["inertia"][k] for k in ("Ixx", "Iyy", "Izz")], rtol=1e-6)
    assert -af.inertia[0, 2] == pytest.approx(doc["inertia"]["Ixz"], rel=1e-6, abs=1e-9)
    assert (af.S, af.b, af.c) == pytest.approx(tuple(doc["geometry"][k] for k in "Sbc"), rel=1e-6)


def test_tlog_carries_the_ardupilot_streams_and_the_surfaces(fast_flight):
    """The pipeline decodes the harness's .tlog: 50 Hz IMU/attitude/servo/AOA_SSA, GPS, pressure,
    wind; the servo PWM maps back to JSBSim's deflections within PWM quantisation."""
    flight = read_log(fast_flight.tlog)
    for name, rate in (("imu", 50), ("attitude", 50), ("servo", 50), ("aoa_ssa", 50), ("gps", 25),
                       ("airspeed", 25), ("wind", 2)):
        s = flight.streams[name]
        assert np.median(np.diff(s.t)) == pytest.approx(1.0 / rate, rel=0.05), name
    for k, (from_pwm, ref) in servo_against_truth(flight, fast_flight).items():
        assert np.max(np.abs(from_pwm - ref)) < np.radians(0.1), k


def test_flights_are_reproducible_per_seed(tmp_path, monkeypatch):
    """JSBSim's turbulence is seeded: the same seed flies the same flight, another seed another;
    JSBSim writes nothing into the working directory (the c172x model has an <output> element)."""
    monkeypatch.chdir(tmp_path)
    fly(FlightConfig("c172x", duration_s=1.0))
    assert not list(tmp_path.iterdir())
    a, b, c = (fly(FlightConfig("sgs", duration_s=5.0, seed=s)) for s in (3, 3, 4))
    np.testing.assert_array_equal(a.truth["wn"], b.truth["wn"])
    assert np.abs(a.truth["wn"] - c.truth["wn"]).max() > 0.01


def test_speed_schedule_levels_and_rate():
    """The sweep's airspeed reference steps through its levels with cosine ramps; its rate is the
    derivative of the factor; the standard plan holds 1 and adds no sideslip."""
    from benchmarks.jsbsim_harness.flight import SWEEP_LEVELS, SWEEP_RAMP_S, sideslip_holds, speed_schedule

    t = np.arange(0, 120, 0.02)
    f, df = speed_schedule(t, 120.0, "sweep")
    for (frac, lev), nxt in zip(SWEEP_LEVELS, [x[0] for x in SWEEP_LEVELS[1:]] + [1.0]):
        if nxt * 120 - (frac * 120 + SWEEP_RAMP_S) > 0.5:          # levels that are held reach their value
            k = np.searchsorted(t, frac * 120 + SWEEP_RAMP_S + 0.2)
            assert f[k] == pytest.approx(lev, abs=1e-9)
    np.testing.assert_allclose(np.gradient(f, t), df, atol=2e-3)
    assert 0.7 <= f.min() and f.max() <= 1.15
    spec = aircraft("c172x")
    holds = sideslip_holds(spec, 120.0, "sweep")
    assert len(holds) >= 5 and {np.sign(a) for _, a in holds} == {-1.0, 1.0}
    f0, df0 = speed_schedule(t, 120.0, "standard")
    assert np.all(f0 == 1.0) and not np.any(df0) and sideslip_holds(spec, 120.0, "standard") == []
    with pytest.raises(ValueError, match="plan"):
        FlightConfig("c172x", plan="loops")


@pytest.mark.slow
def test_sweep_plan_spans_alpha_and_sideslips_at_several_speeds():
    """The sweep flies several trim speeds (a wider alpha range than the standard plan) and holds
    sideslips at different alpha, inside the envelope (no stall, no departure)."""
    std = fly(FlightConfig("c172x", duration_s=120.0, seed=1))
    swp = fly(FlightConfig("c172x", duration_s=120.0, seed=1, plan="sweep"))

    def spread(rec):          # alpha's standard deviation, all of it and its 2-s averages (trim alpha), deg
        a = np.degrees(rec.truth["alpha"])
        return a.std(), np.convolve(a, np.ones(100) / 100, "valid").std()

    (s0, s0_trim), (s1, s1_trim) = spread(std), spread(swp)
    assert s1 > 1.5 * s0 and s1_trim > 2.5 * s0_trim, (spread(std), spread(swp))
    V = swp.truth["V"]
    assert np.ptp(np.percentile(V, [1, 99])) > 0.3 * np.median(V)
    a = np.degrees(swp.truth["alpha"])
    assert a.max() < 12.0                                          # far below the c172x's stall
    from benchmarks.jsbsim_harness.flight import sideslip_holds

    b = np.degrees(swp.truth["beta"])
    alphas, betas = [], []
    for start, amp in sideslip_holds(aircraft("c172x"), 120.0, "sweep"):
        m = (swp.t > start + 1.0) & (swp.t < start + 3.0)
        betas.append(np.sign(amp) * b[m].mean())
        alphas.append(a[m].mean())
    # the c172x's holds (3 deg of rudder, on top of the other maneuvers) give about 1 deg of sideslip
    assert np.median(betas) > 0.5, betas
    assert np.ptp(alphas) > 1.0                                       # at different alpha


def test_sideslips_are_smaller_at_the_slow_levels():
    """A test pilot limits sideslip near the stall: the rudder of a hold scales with the level's
    speed, full at the initial speed and above, half at 0.75."""
    from benchmarks.jsbsim_harness.flight import SWEEP_LEVELS, SWEEP_SLIP_RUDDER, sideslip_holds, slip_scale

    assert slip_scale(0.75) == pytest.approx(0.5) and slip_scale(1.0) == 1.0 and slip_scale(1.12) == 1.0
    assert slip_scale(0.82) == pytest.approx(0.64)
    spec = aircraft("sgs")
    full = SWEEP_SLIP_RUDDER * np.radians(spec.amplitude_deg[2])
    holds = sideslip_holds(spec, 120.0, "sweep")
    starts = [f * 120.0 for f, _ in SWEEP_LEVELS] + [120.0]
    for t0, amp in holds:
        k = max(i for i in range(len(SWEEP_LEVELS)) if starts[i] <= t0)
        assert abs(amp) == pytest.approx(full * slip_scale(SWEEP_LEVELS[k][1]))
    assert min(abs(a) for _, a in holds) < 0.6 * full < max(abs(a) for _, a in holds)


def test_turn_plan_carries_the_heading_round_at_a_limited_bank():
    """``"sweep_turn"`` flies the sweep in a steady turn: the c172x turns through most of
    TURN_HEADING_DEG at a modest bank, inside the envelope; a fast aircraft's rate is set by the bank
    limit; the other plans do not turn (turn_rate 0, so their flights are the same as before)."""
    from benchmarks.jsbsim_harness.flight import TURN_HEADING_DEG, TURN_MAX_BANK_DEG, turn_rate

    assert turn_rate("sweep", 40.0, 120.0) == 0.0 and turn_rate("standard", 40.0, 120.0) == 0.0
    assert turn_rate("sweep_turn", 20.0, 120.0) == pytest.approx(np.radians(TURN_HEADING_DEG) / 120.0)
    assert turn_rate("sweep_turn", 134.0, 120.0) == pytest.approx(9.80665 * np.tan(np.radians(TURN_MAX_BANK_DEG))
                                                                  / 134.0)
    rec = fly(FlightConfig("c172x", duration_s=120.0, seed=1, plan="sweep_turn"))
    psi = np.unwrap(rec.truth["psi"])
    assert 250.0 < np.degrees(psi[-1] - psi[0]) < TURN_HEADING_DEG + 10.0
    phi = np.degrees(rec.truth["phi"])
    assert 5.0 < np.median(np.abs(phi)) < TURN_MAX_BANK_DEG and np.abs(phi).max() < 40.0
    assert rec.meta["aborts"] == []
    with pytest.raises(ValueError, match="plan must be one of"):
        FlightConfig("c172x", plan="cloverleaf")


def test_sensor_draw_per_aircraft_gives_each_aircraft_its_own_noise():
    """``sensor_draw="shared"`` seeds the sensor noise from the seed alone (every aircraft of a seed
    shares the autopilot wind's wander); ``"per_aircraft"`` mixes the aircraft's name in, so that the
    same flight under two names draws different noise, and the same name the same noise."""
    from benchmarks.jsbsim_harness.sensors import make_sensors

    rec = fly(FlightConfig("c172x", duration_s=20.0, seed=1, turbulence="none"))

    def wind(name, draw):
        cfg = dataclasses.replace(rec.config, aircraft=name, sensor_draw=draw)
        return make_sensors(dataclasses.replace(rec, config=cfg))["wind"]["wn"]

    np.testing.assert_array_equal(wind("c172x", "shared"), wind("sgs", "shared"))
    np.testing.assert_array_equal(wind("c172x", "shared"), make_sensors(rec)["wind"]["wn"])
    np.testing.assert_array_equal(wind("c172x", "per_aircraft"), wind("c172x", "per_aircraft"))
    assert np.abs(wind("c172x", "per_aircraft") - wind("sgs", "per_aircraft")).max() > 0.01
    with pytest.raises(ValueError, match="sensor_draw must be one of"):
        FlightConfig("c172x", sensor_draw="independent")


def test_turbulence_draw_per_aircraft_gives_each_aircraft_its_own_gusts():
    """``turbulence_draw="shared"`` sets JSBSim's random seed to the flight's seed (the older flights);
    ``"per_aircraft"`` mixes the aircraft's name in: another gust sequence for the same seed, the same
    one each time it is flown, and a seed JSBSim's C int holds."""
    from benchmarks.jsbsim_harness.flight import turbulence_seed

    shared = FlightConfig("c172x", duration_s=8.0, seed=1)
    own = dataclasses.replace(shared, turbulence_draw="per_aircraft")
    assert turbulence_seed(shared) == 1
    assert turbulence_seed(own) != turbulence_seed(dataclasses.replace(own, aircraft="sgs"))
    assert turbulence_seed(own) != turbulence_seed(dataclasses.replace(own, seed=2))
    assert all(0 <= turbulence_seed(dataclasses.replace(own, seed=s)) < 2**31 for s in range(50))
    a, b, c = fly(shared), fly(own), fly(own)
    np.testing.assert_array_equal(b.truth["wn"], c.truth["wn"])
    gust = a.truth["wn"] - np.mean(a.truth["wn"])
    assert np.abs(a.truth["wn"] - b.truth["wn"]).max() > 0.2 * np.abs(gust).max() > 0.0
    with pytest.raises(ValueError, match="turbulence_draw must be one of"):
        FlightConfig("c172x", turbulence_draw="independent")


@pytest.mark.slow
def test_a_departing_maneuver_is_knocked_off_and_the_flight_survives(tmp_path):
    """With Cl:alpha*beta = 3 the SGS's dihedral reverses at the slow level and a sideslip departs
    (before the knock-it-off: beyond 20 deg, the flight ended). The pilot's abort stops the
    maneuvers, recovers (rudder against the sideslip, unload) and resumes; the clean reference
    flight never needs it. Both fly "calm" (the harness's light until the fifteenth session, the flights
    this was written on): in MIL-F-8785C light turbulence the clean reference (seed 100) itself reaches
    15.0 deg of sideslip at 32 s and is knocked off (turb15)."""
    from benchmarks.jsbsim_harness.effects import Effect, _write_model
    from benchmarks.jsbsim_harness.flight import ABORT_BETA_DEG, MAX_BETA_DEG

    spec = aircraft("sgs")
    cfg = FlightConfig("sgs", duration_s=120.0, seed=1, plan="sweep", turbulence="calm")
    rec = fly(cfg, _write_model(spec, [Effect("Cl:alpha*beta", 3.0)], tmp_path))
    aborts = rec.meta["aborts"]
    assert aborts and all(abs(a["beta_deg"]) >= ABORT_BETA_DEG for a in aborts), aborts
    assert np.degrees(np.abs(rec.truth["beta"])).max() < MAX_BETA_DEG
    assert rec.t[-1] == pytest.approx(120.0 - 0.02)
    ref = fly(FlightConfig("sgs", duration_s=120.0, seed=100, plan="sweep", turbulence="calm"))
    assert ref.meta["aborts"] == []


def test_fingerprint_is_per_aircraft():
    """The flight fingerprint of an aircraft holds its own spec and the harness's code, not the
    other aircraft or the roles: adding an aircraft or moving one between tuning and untouched
    keeps it; a change of its spec, of another fingerprinted source's code or of its airframe file
    changes it; comments and docstrings do not."""
    import dataclasses

    from benchmarks.jsbsim_harness.logfile import _REPO, FINGERPRINT_SOURCES, fingerprint, harness_fingerprint

    rel_ac = "benchmarks/jsbsim_harness/aircraft.py"
    src = {rel: (_REPO / rel).read_text() for rel in FINGERPRINT_SOURCES}
    spec = aircraft("c172x")
    fp = lambda s=spec, texts=src, af=b"airframe": fingerprint(s, texts, af, "1.3.3")   # noqa: E731
    assert harness_fingerprint("c172x") == fingerprint(spec, src, spec.airframe_path.read_bytes(),
                                                       __import__("jsbsim").__version__)
    text = src[rel_ac]
    assert '"f16": AircraftSpec(' in text and 'UNTOUCHED_AIRCRAFT: tuple[str, ...] = ()' in text
    roster = (text.replace('"f16": AircraftSpec(', '"t6b": AircraftSpec(name="t6b", model="x", airspeed_kts=1.0, '
                           'altitude_ft=1.0, elevator_sign=1.0, aileron_sign=1.0, aileron_props=("a", None), '
                           'rudder_sign=1.0, cmd_per_rad=(1, 1, 1), amplitude_deg=(1, 1, 1), pulse_s=(1, 1, 1)),\n'
                           '    "f16": AircraftSpec(')
              .replace('UNTOUCHED_AIRCRAFT: tuple[str, ...] = ()', 'UNTOUCHED_AIRCRAFT = ("t6b",)') + "\n# a comment\n")
    assert fp(texts=src | {rel_ac: roster}) == fp()
    assert fp(s=dataclasses.replace(spec, amplitude_deg=(3.0, 5.0, 6.5))) != fp()
    assert fp(texts=src | {rel_ac: text + "\n_DEG = 1.0\n"}) != fp()
    rel_fl = "benchmarks/jsbsim_harness/flight.py"
    assert fp(texts=src | {rel_fl: src[rel_fl] + "\nX = 1\n"}) != fp() and fp(af=b"other") != fp()
