"""Checks of a JSBSim flight's exact truth shared by the harness tests: least-squares derivatives,
the rigid body, the decoded log, the hidden effects in JSBSim's own properties, the evaluation's flights.

The per-aircraft tests (``test_jsbsim_<name>.py``) share the checks of JSBSim's own properties at the harness's
initial condition (:func:`ic_state`, no turbulence, nothing flown): the FCS (:func:`surface_state`,
:func:`check_direct_fcs`, :func:`assert_aileron_maps_back`, :func:`assert_deflections_map_back`), static stability
and control (:func:`assert_pitch_derivatives`, :func:`assert_lateral_derivatives`: each test passes its own numbers
and tolerances as ``pytest.approx``), the derivation (:func:`assert_kept_but_engines`, against the stock model
:func:`assert_same_aero_as_stock`) and the summaries' labels (:func:`assert_summaries_label_bare`); twenty-eighth
session, folded from sixteen files' copies with every assertion and tolerance kept.
"""

import numpy as np

from benchmarks.jsbsim_harness.truth import truth_coefficients, truth_regressors

LB = 0.45359237          # kg per lb


def assert_names_resolve(name: str, model: str, typo: str) -> None:
    """The harness name ``name`` and the JSBSim model name ``model`` resolve to ``name`` in any case
    and with spaces (``canonical_name``); the unknown ``typo`` raises a KeyError listing ``name``.

    Raises:
        AssertionError: one of these fails.
    """
    import re

    import pytest

    from benchmarks.jsbsim_harness import canonical_name

    assert canonical_name(model) == canonical_name(f" {name.upper()} ") == canonical_name(name) == name
    with pytest.raises(KeyError, match=f"unknown aircraft '{re.escape(typo)}' .*{re.escape(name)}"):
        canonical_name(typo)


def assert_rigid_body_glide(files, mass_lb: float) -> None:
    """A harness flight's truth is a rigid body with the checked-in airframe file, gliding.

    JSBSim's aerodynamic moments equal ``J w_dot + w x J w`` with the airframe file's J to 2e-3 of
    their RMS (:func:`rigid_body_residual`), every non-gravity force and moment is aerodynamic
    (:func:`non_aero_residual` under 1e-9: engines stopped), and the airframe file's mass is
    JSBSim's, ``mass_lb`` lb.

    Raises:
        AssertionError: one of these fails.
    """
    import pytest

    from gcs_sysid.airframe import load_airframe

    tr, af, const = files.recording.truth, load_airframe(files.airframe), files.recording.constants
    rel = rigid_body_residual(tr, af.inertia)
    assert (rel < 2e-3).all(), rel
    assert non_aero_residual(tr) < 1e-9
    assert af.mass == pytest.approx(const["mass"], rel=1e-5) and const["mass"] == pytest.approx(mass_lb * LB, rel=1e-6)


def assert_servos_map_back(files) -> None:
    """The pipeline decodes every stream of a harness flight's .tlog, and its SERVO_OUTPUT_RAW maps
    back through the airframe file to JSBSim's deflections within 0.1 deg, each surface moving
    (standard deviation over 0.5 deg; :func:`decoded_servo_errors`).

    Raises:
        AssertionError: a stream is missing or a surface does not map back.
    """
    empty, errors = decoded_servo_errors(files)
    assert empty == [], empty
    for k, (err, std) in errors.items():
        assert err < np.radians(0.1) and std > np.radians(0.5), k      # maps back; every surface moves


def derivative_slopes(rec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Slopes of the exact Cm, Cl, Cn on their leading regressors (intercept fitted, not returned).

    Args:
        rec: a harness ``Recording``.

    Returns:
        ``(cm, cl, cn)``: Cm on (alpha, q_hat, delta_e); Cl and Cn each on (beta, p_hat, r_hat,
        delta_a, delta_r); 1/rad.
    """
    X, Y = truth_regressors(rec), truth_coefficients(rec)

    def slopes(y, cols):
        A = np.c_[np.ones(len(y)), X[:, cols]]
        return np.linalg.lstsq(A, y, rcond=None)[0][1:]

    return (slopes(Y[:, 4], [0, 3, 5]), slopes(Y[:, 3], [1, 2, 4, 6, 7]), slopes(Y[:, 5], [1, 2, 4, 6, 7]))


def closure_slopes(rec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Slopes of the exact Cm, Cl, Cn on the regressors JSBSim's terms read (intercept fitted, not returned):
    the body rates relative to the turbulent air (``p_aero q_aero r_aero``, what ``Clp Cmq Cnr`` read) made
    dimensionless, and JSBSim's ``aero/alphadot-rad_sec`` rebuilt from the truth as JSBSim's
    ``FGAuxiliary`` computes it: ``(u_a w_dot - w_a u_dot) / (u_a^2 + w_a^2)`` with the air-relative
    ``u_a w_a`` and the time derivatives of the body velocity over the ground (so without the gusts' own
    rate). :func:`derivative_slopes` uses the inertial rates and no alpha-dot; in light turbulence at
    3000 ft the sgs126's alpha-dot term (Cmadot -12, larger than its Cmq -9) and the gusts' rotation turn
    the sign of its Cm_alpha and halve its Cl_beta on a 30-s flight, while this fit closes on JSBSim's
    numbers (Cl and Cn to 1e-6).

    Args:
        rec: a harness ``Recording``.

    Returns:
        ``(cm, cl, cn)``: Cm on (alpha, q_aero_hat, delta_e, alpha_dot_hat); Cl and Cn each on (beta,
        p_aero_hat, r_aero_hat, delta_a, delta_r); 1/rad.
    """
    tr, c, b = rec.truth, rec.constants["c"], rec.constants["b"]
    V, al, be = tr["V"], tr["alpha"], tr["beta"]
    ua, wa = V * np.cos(al) * np.cos(be), V * np.sin(al) * np.cos(be)
    adot = (ua * np.gradient(tr["w"], rec.t) - wa * np.gradient(tr["u"], rec.t)) / (ua**2 + wa**2)
    Y = truth_coefficients(rec)

    def slopes(y, *cols):
        return np.linalg.lstsq(np.column_stack((np.ones(len(y)),) + cols), y, rcond=None)[0][1:]

    lat = (be, tr["p_aero"] * b / (2 * V), tr["r_aero"] * b / (2 * V), tr["delta_a"], tr["delta_r"])
    return (slopes(Y[:, 4], al, tr["q_aero"] * c / (2 * V), tr["delta_e"], adot * c / (2 * V)),
            slopes(Y[:, 3], *lat), slopes(Y[:, 5], *lat))


def servo_against_truth(flight, files) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The logged servo PWM mapped back to deflections, next to the truth's, per surface.

    Args:
        flight: the decoded log (``read_log``); files: the harness ``FlightFiles`` (airframe, truth).

    Returns:
        ``{"delta_e" | "delta_a" | "delta_r": (from_pwm, truth)}``, each (T,) rad on the servo times.
    """
    from gcs_sysid.airframe import load_airframe
    from benchmarks.jsbsim_harness import load_truth

    af = load_airframe(files.airframe)
    servo = flight.streams["servo"]
    ctl = af.controls_from_pwm({c: servo.fields[f"pwm{c}"] for c in af.channels})
    truth = load_truth(files.truth)
    return {k: (ctl[k], np.interp(servo.t, truth.t, truth.X[:, i]))
            for k, i in (("delta_e", 5), ("delta_a", 6), ("delta_r", 7))}


def rigid_body_residual(truth: dict, inertia: np.ndarray) -> np.ndarray:
    """How far JSBSim's aerodynamic moments are from the rigid body with the airframe file's inertia.

    Args:
        truth: a recording's truth arrays (``p q r`` rad/s, ``p_dot q_dot r_dot`` rad/s^2,
            ``L_aero M_aero N_aero`` N m; each (T,)).
        inertia: (3, 3) inertia tensor of the airframe file, kg m^2 (project convention).

    Returns:
        (3,) RMS of ``J w_dot + w x J w - M`` over the RMS of ``M``, per body axis (Euler's
        equations about the CG, e.g. Stevens, Lewis and Johnson, *Aircraft Control and
        Simulation*, 3rd ed., 2016, eq. 1.7-2).
    """
    w = np.stack([truth["p"], truth["q"], truth["r"]], 1)
    wd = np.stack([truth["p_dot"], truth["q_dot"], truth["r_dot"]], 1)
    M = np.stack([truth["L_aero"], truth["M_aero"], truth["N_aero"]], 1)
    rhs = wd @ inertia.T + np.cross(w, w @ inertia.T)
    return np.sqrt(np.mean((rhs - M) ** 2, 0)) / np.sqrt(np.mean(M ** 2, 0))


def ic_state(spec, alpha_deg=4.0, beta_deg=0.0, cmds=(0.0, 0.0, 0.0), r_rad_s=0.0, props=()):
    """JSBSim (``FGFDMExec``) at the harness's initial condition for ``spec`` with the given alpha and
    sideslip (deg), yaw rate (rad/s) and fixed normalised commands ``cmds`` (elevator, aileron,
    rudder), after ``run_ic``: the FCS evaluated once, nothing integrated (the per-aircraft tests'
    checks of their FCS and static stability). ``props``: properties created at 0 before the initial
    condition (the FlightGear properties a stock wheel model reads and nothing writes, without which
    ``run_ic`` fails: the navion's, dr1's and fokker50's stock models)."""
    from benchmarks.jsbsim_harness import FlightConfig
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    fdm = load_model(spec, 1 / 200)
    for k in props:
        fdm[k] = 0.0
    _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
    fdm["ic/alpha-deg"], fdm["ic/beta-deg"], fdm["ic/r-rad_sec"] = alpha_deg, beta_deg, r_rad_s
    fdm["fcs/elevator-cmd-norm"], fdm["fcs/aileron-cmd-norm"], fdm["fcs/rudder-cmd-norm"] = cmds
    fdm.run_ic()
    return fdm


def lateral_coefficients(fdm, aileron: str = "fcs/left-aileron-pos-rad",
                         rudder: str = "fcs/rudder-pos-rad") -> tuple[float, float, float, float]:
    """JSBSim's rolling and yawing moment coefficients and the surfaces that made them, from one state.

    Args:
        fdm: a JSBSim FGFDMExec after ``run_ic`` (the aircraft's reference area, span and dynamic pressure set).
        aileron, rudder: the properties holding the surface deflections, rad (a model's own names).

    Returns:
        ``(Cl, Cn, delta_a, delta_r)``: ``L / (qbar S b)``, ``N / (qbar S b)`` from JSBSim's aerodynamic moments
        about the CG (lbs ft over psf ft^2 ft: dimensionless), and the two deflections, rad.
    """
    qsb = fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm["metrics/bw-ft"]
    return fdm["moments/l-aero-lbsft"] / qsb, fdm["moments/n-aero-lbsft"] / qsb, fdm[aileron], fdm[rudder]


def cm_without_alpha_dot(spec, alpha_deg: float, elevator_cmd: float = 0.0,
                         term: str | None = "aero/coefficient/Cmadot") -> float:
    """JSBSim's pitching-moment coefficient about the CG at :func:`ic_state` (``alpha_deg`` of alpha, the
    normalised elevator command ``elevator_cmd``) less its alpha-dot term ``term`` (``run_ic`` gives an alpha-dot
    the term reads; ``aero/moment/Pitch_alphadot`` in Aeromatic's models, None where the model has none): the
    static Cm the stability checks (:func:`assert_pitch_derivatives`) difference over alpha and elevator."""
    fdm = ic_state(spec, alpha_deg=alpha_deg, cmds=(elevator_cmd, 0.0, 0.0))
    qsc = fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm["metrics/cbarw-ft"]
    m = fdm["moments/m-aero-lbsft"]
    if term is not None:
        m -= fdm[term]
    return m / qsc


def assert_pitch_derivatives(spec, slopes, elevator, *, cm_at=None, alpha_e: float = 0.0, travel=None,
                             term: str | None = "aero/coefficient/Cmadot") -> None:
    """``spec``'s static pitch from JSBSim at fixed surfaces (:func:`cm_without_alpha_dot`, no turbulence): the
    stability and elevator checks of the per-aircraft tests (``test_jsbsim_<name>.py``).

    Args:
        spec: the harness ``AircraftSpec``.
        slopes: ``((alpha_a, alpha_b, want), ...)``, deg and 1/rad: ``(Cm(alpha_b) - Cm(alpha_a)) /
            (alpha_b - alpha_a)`` must equal ``want`` (a ``pytest.approx``: its tolerance is the test's).
        elevator: ``((cmd, want), ...)``: at alpha ``alpha_e`` (deg), ``(Cm(cmd) - Cm(0)) / delta_e`` per rad
            of the elevator must equal ``want``, ``delta_e`` the FCS's ``fcs/elevator-pos-rad`` at that command
            or, with ``travel = (up, down)`` (rad per unit command), ``cmd * up`` for a negative command and
            ``cmd * down`` otherwise (the surface's end as the model's XML gives it).
        cm_at: ``{alpha_deg: want}``: Cm at those alphas.
        term: the alpha-dot term left out (:func:`cm_without_alpha_dot`).

    Raises:
        AssertionError: the first check that fails, with the alphas or command in its message.
    """
    memo = {}

    def cm(alpha, cmd=0.0):
        if (alpha, cmd) not in memo:
            memo[alpha, cmd] = cm_without_alpha_dot(spec, alpha, cmd, term)
        return memo[alpha, cmd]

    for a, b, want in slopes:
        assert (cm(b) - cm(a)) / np.radians(b - a) == want, (a, b)
    for a, want in (cm_at or {}).items():
        assert cm(a) == want, a
    for cmd, want in elevator:
        if travel is None:
            de = ic_state(spec, alpha_e, cmds=(cmd, 0.0, 0.0))["fcs/elevator-pos-rad"]
        else:
            de = cmd * (travel[0] if cmd < 0 else travel[1])
        assert (cm(alpha_e, cmd) - cm(alpha_e)) / de == want, cmd


def assert_lateral_derivatives(spec, aileron, rudder, beta, *, alpha_deg: float = 0.0, rest: float = 1e-9,
                               aileron_cmds=(0.3, -0.3), rudder_cmds=(0.3, -0.3),
                               aileron_prop: str = "fcs/left-aileron-pos-rad") -> None:
    """``spec``'s rolling and yawing moments from JSBSim at fixed surfaces (:func:`ic_state`,
    :func:`lateral_coefficients`, no turbulence): the roll and yaw checks of the per-aircraft tests.

    At rest (``alpha_deg`` of alpha, no sideslip, zero commands) abs(Cl) and abs(Cn) are under ``rest``; the
    derivatives are the differences from rest per rad of the deflection (or of the sideslip). Each ``want`` is a
    ``pytest.approx`` (its tolerance is the test's), or None where the test checks nothing.

    Args:
        spec: the harness ``AircraftSpec``.
        aileron: ``(Cl_per_rad, Cn_per_rad)`` of the aileron property ``aileron_prop`` (JSBSim's sign: the
            project's Cl_delta_a and Cn_delta_a have the other), at each command of ``aileron_cmds``.
        rudder: ``(Cn_per_rad, Cl_per_rad)`` of ``fcs/rudder-pos-rad``, at each command of ``rudder_cmds``.
        beta: ``{alpha_deg: (Cl_beta, Cn_beta)}``: per rad of 4 deg of sideslip at that alpha, from that alpha's
            own rest.

    Raises:
        AssertionError: the first check that fails, with the command or alpha in its message.
    """
    def lat(cmds=(0.0, 0.0, 0.0), alpha=alpha_deg, beta_deg=0.0):
        return lateral_coefficients(ic_state(spec, alpha, beta_deg, cmds), aileron=aileron_prop)

    l0, n0, a0, r0 = lat()
    assert abs(l0) < rest and abs(n0) < rest, (l0, n0)
    for cmd in aileron_cmds:
        l1, n1, a1, _ = lat((0.0, cmd, 0.0))
        for got, want in zip(((l1 - l0) / (a1 - a0), (n1 - n0) / (a1 - a0)), aileron):
            assert want is None or got == want, ("aileron", cmd)
    for cmd in rudder_cmds:
        l2, n2, _, r2 = lat((0.0, 0.0, cmd))
        for got, want in zip(((n2 - n0) / (r2 - r0), (l2 - l0) / (r2 - r0)), rudder):
            assert want is None or got == want, ("rudder", cmd)
    for a, wants in beta.items():
        lb, nb, _, _ = lat(alpha=a)
        l3, n3, _, _ = lat(alpha=a, beta_deg=4.0)
        for got, want in zip(((l3 - lb) / np.radians(4.0), (n3 - nb) / np.radians(4.0)), wants):
            assert want is None or got == want, ("beta", a)


#: The normalised commands (elevator, aileron, rudder) of the surface checks (:func:`surface_state`).
SURFACE_CMDS = (0.3, -0.4, 0.2)


def surface_state(spec, gains: dict, *, up: float | None = None, alpha_deg: float = 4.0, r_rad_s: float = 0.0,
                  rel: float = 1e-9):
    """JSBSim at :func:`ic_state` (``alpha_deg`` of alpha, 4 deg of sideslip, the commands :data:`SURFACE_CMDS`, the
    yaw rate ``r_rad_s``, rad/s), once its FCS is checked to map each command straight to the surfaces: the
    per-aircraft tests' FCS checks.

    Args:
        spec: the harness ``AircraftSpec``.
        gains: ``{property: (channel, rad per unit command)}``, channel 0 elevator, 1 aileron, 2 rudder: the
            property must read the channel's command times the gain (to ``rel``; a mirrored surface has a
            negative gain).
        up: the elevator's rad per unit command on its trailing-edge-up side, or None: at the command (-0.3, 0, 0)
            (same alpha, no sideslip, no yaw rate) ``fcs/elevator-pos-rad`` must read -0.3 ``up``.

    Returns:
        The ``FGFDMExec`` at the commands (:func:`assert_aero_is_the_only_force` runs it on).

    Raises:
        AssertionError: a surface differs (its property in the message).
    """
    import pytest

    fdm = ic_state(spec, alpha_deg, 4.0, SURFACE_CMDS, r_rad_s)
    for prop, (channel, gain) in gains.items():
        assert fdm[prop] == pytest.approx(SURFACE_CMDS[channel] * gain, rel=rel), prop
    if up is not None:
        assert ic_state(spec, alpha_deg, cmds=(-0.3, 0.0, 0.0))["fcs/elevator-pos-rad"] == pytest.approx(-0.3 * up,
                                                                                                         rel=rel)
    return fdm


def check_direct_fcs(spec, min_lift_lbs: float) -> None:
    """Assert that ``spec``'s FCS maps the normalised commands straight to the surfaces its aerodynamics
    read (elevator -0.35..+0.30 rad, left aileron +-0.35 rad with the right its mirror, rudder +-0.35 rad,
    a yaw rate moving nothing: :func:`surface_state`), that JSBSim has no engine, and that after 50 frames
    every non-gravity force and moment is aerodynamic with at least ``min_lift_lbs`` of body-z force (the
    rascal's, sgs126's, navion's and fokker50's checks: all fly such an FCS).

    Raises:
        AssertionError: the first check that fails."""
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, 0.30), "fcs/left-aileron-pos-rad": (1, 0.35),
                               "fcs/right-aileron-pos-rad": (1, -0.35), "fcs/rudder-pos-rad": (2, 0.35)},
                        up=0.35, r_rad_s=0.2)
    assert fdm.get_propulsion().get_num_engines() == 0
    assert_aero_is_the_only_force(fdm, min_lift_lbs)


def assert_aileron_maps_back(spec, alpha_deg: float) -> None:
    """The harness's aileron command for 5 deg of the project's delta_a (trailing edge down on the right) through
    ``spec``'s ``aileron_sign`` and ``cmd_per_rad``, set at :func:`ic_state` (``alpha_deg``), reads back as 5 deg
    (``flight._deflections``, to 1e-9).

    Raises:
        AssertionError: the deflection differs."""
    import pytest

    from benchmarks.jsbsim_harness.flight import _deflections

    da = np.radians(5.0)
    cmd = da * spec.aileron_sign * spec.cmd_per_rad[1]
    assert _deflections(ic_state(spec, alpha_deg, 0.0, (0.0, cmd, 0.0)), spec)[1] == pytest.approx(da, rel=1e-9)


def assert_deflections_map_back(spec, deltas_deg=(-3.0, 5.0, 4.0)) -> None:
    """The harness's command for the project's deflections ``deltas_deg`` (delta_e, delta_a, delta_r, deg; the
    elevator trailing edge up by default, on its larger side for the ka350) through ``spec``'s signs and
    ``cmd_per_rad``, set at :func:`ic_state`, reads back as those deflections (``flight._deflections``, to 1e-4):
    the sign map and command scale of the ka350's, s23's and dr1's checks.

    Raises:
        AssertionError: the deflections differ."""
    import pytest

    from benchmarks.jsbsim_harness.flight import _deflections

    want = tuple(np.radians(deltas_deg))
    cmd = tuple(d * s * k for d, s, k in zip(want, (spec.elevator_sign, spec.aileron_sign, spec.rudder_sign),
                                             spec.cmd_per_rad))
    assert _deflections(ic_state(spec, 0.0, 0.0, cmd), spec) == pytest.approx(want, rel=1e-4)


def assert_aero_is_the_only_force(fdm, min_lift_lbs: float, external_zero: bool = False) -> None:
    """Run ``fdm`` 50 frames, then JSBSim's total body forces (lbs) and moments (lbs ft) must equal its
    aerodynamic ones on every axis (no engine, ground or other force), with at least ``min_lift_lbs`` of
    body-z aerodynamic force; ``external_zero``: the external forces and moments are also exactly 0.

    Raises:
        AssertionError: the first axis that differs, or too little lift."""
    for _ in range(50):
        fdm.run()
    for f in ("forces/fb{}-{}-lbs", "moments/{}-{}-lbsft"):
        for ax in ("xyz" if f.startswith("forces") else "lmn"):
            if external_zero:
                assert fdm[f.format(ax, "external")] == 0.0
            assert fdm[f.format(ax, "total")] == fdm[f.format(ax, "aero")], (f, ax)
    assert abs(fdm["forces/fbz-aero-lbs"]) > min_lift_lbs


def effect_state(spec, effects, cmds=(0.3, -0.4, 0.2), n=40, alpha_deg=None):
    """JSBSim (``FGFDMExec``) at the harness's initial condition with 4 deg of sideslip (and
    ``alpha_deg`` of alpha when given) and the fixed normalised commands ``cmds`` (elevator,
    aileron, rudder), after ``n`` frames at 200 Hz, with ``effects`` edited into a copy of the
    model's XML (none: the stock model). ``n = 0``: the initial condition itself, where
    ``run_ic`` has evaluated the models but nothing has been integrated, so that two models'
    forces and moments there are at the same state (JSBSim integrates first in each later frame,
    with the accelerations of the frame before)."""
    import tempfile
    from pathlib import Path

    from benchmarks.jsbsim_harness import FlightConfig
    from benchmarks.jsbsim_harness.effects import _write_model
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    with tempfile.TemporaryDirectory() as tmp:
        fdm = load_model(spec, 1 / 200, 0, _write_model(spec, effects, Path(tmp)) if effects else None)
        _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
        fdm["ic/beta-deg"] = 4.0
        if alpha_deg is not None:
            fdm["ic/alpha-deg"] = alpha_deg
        fdm["fcs/elevator-cmd-norm"], fdm["fcs/aileron-cmd-norm"], fdm["fcs/rudder-cmd-norm"] = cmds
        fdm.run_ic()
        for _ in range(n):
            fdm.run()
        return fdm


#: The injected moment effects: effect name -> (JSBSim function, moment property, reference length).
MOMENT_EFFECTS = {"Cm:alpha^2": ("injected_Cm_alpha2", "moments/m-aero-lbsft", "metrics/cbarw-ft"),
                  "Cl:alpha*beta": ("injected_Cl_alpha_beta", "moments/l-aero-lbsft", "metrics/bw-ft"),
                  "Cn:delta_a": ("injected_Cn_delta_a", "moments/n-aero-lbsft", "metrics/bw-ft")}


def injected_moment(spec, name, k, n=40, alpha_deg=None) -> tuple[float, float, float]:
    """One moment effect of ``effects.py`` as JSBSim computes it (:func:`effect_state`).

    Returns:
        ``(function, specified, change)``, lbf ft: the injected function's value
        (``aero/coefficient/injected_*``); ``k`` times its regressor (alpha^2, alpha beta, or the
        harness's delta_a) times ``qbar S`` and c or b, from JSBSim's own state; and the change of
        JSBSim's total aerodynamic moment on that axis against the stock model after the same
        frames (equal to the function only while both states are the same: ``n = 0``).
    """
    from benchmarks.jsbsim_harness.effects import Effect
    from benchmarks.jsbsim_harness.flight import _deflections

    func, moment, ref = MOMENT_EFFECTS[name]
    fdm, stock = effect_state(spec, [Effect(name, k)], n=n, alpha_deg=alpha_deg), \
        effect_state(spec, [], n=n, alpha_deg=alpha_deg)
    a, b, da = fdm["aero/alpha-rad"], fdm["aero/beta-rad"], _deflections(fdm, spec)[1]
    x = {"Cm:alpha^2": a * a, "Cl:alpha*beta": a * b, "Cn:delta_a": da}[name]
    want = k * x * fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm[ref]
    return fdm[f"aero/coefficient/{func}"], want, fdm[moment] - stock[moment]


def delay_trace(spec, delay_s: float, cmd: float = 0.5, n: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """The elevator and the delayed elevator the aerodynamics read with ``delay:delta_e`` = ``delay_s``,
    frame by frame (200 Hz) after a step of the normalised elevator command to ``cmd``.

    Returns:
        ``(position, delayed)``, each (n,) rad (``fcs/elevator-pos-rad``,
        ``fcs/elevator-pos-delayed-rad``).
    """
    import tempfile
    from pathlib import Path

    from benchmarks.jsbsim_harness import FlightConfig
    from benchmarks.jsbsim_harness.effects import Effect, _write_model
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    with tempfile.TemporaryDirectory() as tmp:
        fdm = load_model(spec, 1 / 200, 0, _write_model(spec, [Effect("delay:delta_e", delay_s)], Path(tmp)))
        _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
        fdm.run()
        fdm["fcs/elevator-cmd-norm"] = cmd
        pos, delayed = [], []
        for _ in range(n):
            fdm.run()
            pos.append(fdm["fcs/elevator-pos-rad"])
            delayed.append(fdm["fcs/elevator-pos-delayed-rad"])
    return np.array(pos), np.array(delayed)


#: The streams every harness .tlog carries (``docs/jsbsim.md``, "The log").
LOG_STREAMS = ("imu", "attitude", "servo", "aoa_ssa", "gps", "airspeed", "wind")


def decoded_servo_errors(files) -> tuple[list[str], dict[str, tuple[float, float]]]:
    """Decode a harness flight's .tlog with the pipeline's reader and map its servos back.

    Args:
        files: the harness ``FlightFiles`` (tlog, airframe, truth).

    Returns:
        ``(empty, errors)``: the :data:`LOG_STREAMS` the log lacks or holds no sample of, and per
        surface (``delta_e delta_a delta_r``) the largest absolute difference between the
        deflection from SERVO_OUTPUT_RAW through the airframe file and JSBSim's, and the standard
        deviation of JSBSim's, both rad (:func:`servo_against_truth`).
    """
    from gcs_sysid.telemetry import read_log

    flight = read_log(files.tlog)
    empty = [n for n in LOG_STREAMS if n not in flight.streams or flight.streams[n].t.size == 0]
    return empty, {k: (float(np.max(np.abs(a - b))), float(np.std(b)))
                   for k, (a, b) in servo_against_truth(flight, files).items()}


def non_aero_residual(truth: dict) -> float:
    """Largest absolute difference between JSBSim's total non-gravity forces and moments and the
    aerodynamic ones (N, N m) over a recording's truth: zero in a glide with the engine stopped."""
    return max(float(np.max(np.abs(truth[f"{k}_total"] - truth[f"{k}_aero"])))
               for k in ("Fx", "Fy", "Fz", "L", "M", "N"))


#: Flights of the final evaluation that a harness aircraft must fly inside its envelope:
#: (seed, turbulence, plan, [(effect, size), ...]).
EVALUATION_FLIGHTS = [
    (100, "light", "sweep", []),                                 # the diagnosis's reference flight
    (11, "light", "sweep", []),                                  # a clean diagnosis flight
    (1, "light", "sweep", [("Cl:alpha*beta", 3.0)]),             # the effect most likely to depart
    (1, "light", "sweep", [("delay:delta_e", 0.12)]),
    (2, "moderate", "standard", []),                             # eval_jsbsim, moderate turbulence
]

#: The evaluation flights an untouched aircraft's envelope test flies: :data:`EVALUATION_FLIGHTS`
#: and the evaluation's pair of effects.
ENVELOPE_FLIGHTS = EVALUATION_FLIGHTS + [(1, "light", "sweep", [("Cm:alpha^2", -8.0), ("Cn:delta_a", -0.06)])]


def assert_hidden_effects_in_jsbsim(spec, elevator_down_end_rad: float, n_side: int = 5,
                                    n_elevator_reads: int = 2, min_lbf: float = 10.0) -> None:
    """Every hidden effect of ``effects.py`` as JSBSim computes it on ``spec``'s XML (the aircraft
    tests' shared check).

    At the harness's initial condition with alpha 4 deg and sideslip 4 deg (:func:`effect_state`,
    ``n = 0``: the stock and the edited model at the same state) each injected moment
    (``Cm:alpha^2`` = -8, ``Cl:alpha*beta`` = 3, ``Cn:delta_a`` = -0.06) is more than 10 lbf ft and
    equals k times its regressor times qbar S c|b and the change of JSBSim's total aerodynamic
    moment, to 1e-9 (:func:`injected_moment`); ``CY:scale`` = 1.6 multiplies the sum of the model's
    ``n_side`` SIDE functions (more than ``min_lbf`` lbf) and the wind-axis side force
    ``forces/fwy-aero-lbs`` by 1.6;
    ``delay:delta_e`` = 0.12 s holds the elevator the aerodynamics read 24 frames (200 Hz) behind
    the surface, whose step to half the command reaches ``elevator_down_end_rad / 2`` (rad, the
    trailing-edge-down end), and redirects all ``n_elevator_reads`` aerodynamic reads of
    ``fcs/elevator-pos-rad``.

    Raises:
        AssertionError: one of these fails.
    """
    import copy
    import xml.etree.ElementTree as ET

    import pytest

    from benchmarks.jsbsim_harness.effects import EFFECTS, Effect, inject_xml, stock_model_dir

    assert set(EFFECTS) >= {"Cm:alpha^2", "Cl:alpha*beta", "Cn:delta_a", "CY:scale", "delay:delta_e"}
    for name, k in (("Cm:alpha^2", -8.0), ("Cl:alpha*beta", 3.0), ("Cn:delta_a", -0.06)):
        got, want, change = injected_moment(spec, name, k, n=0, alpha_deg=4.0)
        assert abs(want) > min_lbf, (name, want)                  # lbf ft
        assert got == pytest.approx(want, rel=1e-9) and change == pytest.approx(got, rel=1e-9), (name, got, change)
    root = ET.parse(stock_model_dir(spec) / f"{spec.model}.xml").getroot()
    side = [f.get("name") for ax in root.iter("axis") if ax.get("name") == "SIDE" for f in ax.findall("function")]
    assert len(side) == n_side, side
    stock, scaled = (effect_state(spec, e, n=0, alpha_deg=4.0) for e in ([], [Effect("CY:scale", 1.6)]))
    total = lambda fdm: sum(fdm[n] for n in side)   # noqa: E731
    assert total(scaled) == pytest.approx(1.6 * total(stock), rel=1e-9) and abs(total(stock)) > min_lbf
    assert scaled["forces/fwy-aero-lbs"] / stock["forces/fwy-aero-lbs"] == pytest.approx(1.6, rel=1e-9)
    pos, delayed = delay_trace(spec, 0.12)
    assert pos[0] == pytest.approx(0.5 * elevator_down_end_rad, rel=1e-3)
    assert np.all(delayed[:23] == 0.0) and delayed[23:] == pytest.approx(pos[0])
    edited = inject_xml(copy.deepcopy(root), spec, [Effect("delay:delta_e", 0.12)])
    reads = lambda r, p: sum((e.text or "").strip() == p for e in r.find("aerodynamics").iter("property"))  # noqa: E731
    assert reads(root, "fcs/elevator-pos-rad") == n_elevator_reads and reads(edited, "fcs/elevator-pos-rad") == 0
    assert reads(edited, "fcs/elevator-pos-delayed-rad") == n_elevator_reads


def assert_airspeed_bias_in_log(files, out_dir, bias: float = 2.0) -> None:
    """``bias:airspeed`` = ``bias`` m/s of TAS written into a second log of a harness flight.

    Args:
        files: the harness ``FlightFiles`` of a flight flown here (``recording`` set).
        out_dir: folder for the biased .tlog.

    Raises:
        AssertionError: the decoded airspeed (EAS, from SCALED_PRESSURE) of the biased log minus
            the clean log's (same seed, same sensor noise) differs from ``bias sqrt(rho / rho0)``
            by more than 0.01 m/s at a sample.
    """
    from pathlib import Path

    from benchmarks.jsbsim_harness import write_log
    from benchmarks.jsbsim_harness.effects import RHO0, _bias_airspeed
    from benchmarks.jsbsim_harness.sensors import make_sensors
    from gcs_sysid.telemetry import read_log

    rec, biased = files.recording, Path(out_dir) / "biased.tlog"
    write_log(rec, biased, sensors=_bias_airspeed(make_sensors(rec, "ahrs"), rec, bias))
    a, b = (read_log(p).streams["airspeed"] for p in (files.tlog, biased))
    want = bias * np.sqrt(np.interp(a.t, rec.t, rec.truth["rho"]) / RHO0)
    np.testing.assert_allclose(b.fields["eas"] - a.fields["eas"], want, atol=0.01)


def evaluation_envelope(name: str, seed: int, turbulence: str, plan: str, effects, out_dir) -> dict:
    """Fly one of the :data:`EVALUATION_FLIGHTS` (120 s) of aircraft ``name`` into ``out_dir``.

    Returns:
        ``flight_envelope`` of its truth file plus ``wild`` (True when ``Cl:alpha*beta`` is
        injected: the effect that reverses the dihedral effect), ``alt_min`` (lowest altitude
        above sea level, m) and ``sink_air_mps`` (mean sink through the air, m/s: the mean of the
        truth's ``vd - wd``, the ground's down velocity less the air's).
    """
    from benchmarks.jsbsim_harness import FlightConfig, make_flight
    from benchmarks.jsbsim_harness.effects import Effect, make_effect_flight
    from benchmarks.jsbsim_harness.envelope import flight_envelope

    cfg = FlightConfig(name, duration_s=120.0, turbulence=turbulence, seed=seed, plan=plan)
    files = (make_effect_flight(cfg, [Effect(n, v) for n, v in effects], out_dir) if effects
             else make_flight(cfg, out_dir))
    with np.load(files.truth) as z:
        alt_min = float(z["alt"].min())
        sink_air = float(np.mean(z["vd"] - z["wd"]))
    return flight_envelope(files.truth) | {"wild": any(n == "Cl:alpha*beta" for n, _ in effects), "alt_min": alt_min,
                                           "sink_air_mps": sink_air}


def assert_in_envelope(e: dict, alpha, beta, bank, speed, rate_std: float, rate_std_held: float,
                       alt_min: float = 0.0, sink_min: float = 3.0,
                       surface_std_min: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> None:
    """An :func:`evaluation_envelope` inside the aircraft's limits, with every axis excited.

    Args:
        alpha: (lowest, highest) alpha, deg. beta, bank: (clean, ``wild``) largest abs(beta) and
            bank, deg. speed: (lowest, highest) TAS, m/s. rate_std, rate_std_held: least standard
            deviation of each body rate on the whole flight and the held-out last 20 %, deg/s.
        alt_min: lowest altitude above sea level, m.
        sink_min: the glide sinks through the air (``sink_air_mps``) more than this, m/s (3 unless
            the aircraft glides flatter: the rascal sinks 1.6-2.2 m/s at 20 m/s). Through the air, not
            over the ground (``sink_mps``), since the fifteenth session: the mean vertical gust of
            MIL-F-8785C light turbulence over a 120-s flight is about 1-1.6 m/s (the rascal's seed-1
            flights sank 0.31-0.36 m/s over the ground, 1.9-2.1 through the air; the sgs126's rose by
            0.06-0.12 m/s and sank 1.0-1.3 through the air); in the old light turbulence the two agreed.
        surface_std_min: least standard deviation of (delta_e, delta_a, delta_r), deg: 1 deg each for every
            aircraft but the us25e, whose rudder is set from its yaw-moment power (twenty-second session: its
            Cn_delta_r -0.18 per rad is 2.5 times its Cn_beta, so 1 deg of rudder standard deviation costs
            sideslips beyond 10 deg and knock-it-offs; docs/jsbsim.md, "The us25e").

    Raises:
        AssertionError: a knock-it-off was flown, or a limit is exceeded; every surface moves by
            more than ``surface_std_min`` (standard deviation; 1 deg) and the glide sinks more than ``sink_min``.
    """
    w = int(e["wild"])
    assert e["aborts"] == [], e["aborts"]
    assert alpha[0] < e["alpha"][0] and e["alpha"][1] < alpha[1], e["alpha"]
    assert max(map(abs, e["beta"])) < beta[w] and e["bank_max"] < bank[w], e
    assert speed[0] < e["V"][0] and e["V"][1] < speed[1], e["V"]
    assert min(e["rate_std"]) > rate_std and min(e["rate_std_held"]) > rate_std_held, e      # deg/s
    assert all(s > m for s, m in zip(e["surface_std"], surface_std_min)), e
    assert e["sink_air_mps"] > sink_min and e["alt_min"] > alt_min, e


def same_xml(a, b) -> bool:
    """Whether two XML elements are equal: their tag, attributes, text and children, not their own tails (the
    derivation tests of the checked-in models: the ka350's, s23's, dr1's)."""
    import copy
    import xml.etree.ElementTree as ET

    a, b = map(copy.deepcopy, (a, b))
    a.tail = b.tail = None
    return ET.tostring(a) == ET.tostring(b)


def assert_kept_but_engines(src, der, tags, n_engines: int, n_tanks: int) -> None:
    """The derived model ``der`` keeps the checked-in ``src``'s elements ``tags`` (:func:`same_xml`; ``src`` indented
    as the derived XML first, ``ET.indent(src, space=" ")``) and its ``n_tanks`` fuel tanks one for one, and has none
    of ``src``'s ``n_engines`` ``<propulsion><engine>`` (the glide derivations' checks: the fokker50's, navion's,
    dr1's, s23's and ka350's).

    Raises:
        AssertionError: an element, an engine count or a tank differs. ValueError: the two have another number of
            tanks (``zip(strict=True)``)."""
    for tag in tags:
        assert same_xml(src.find(tag), der.find(tag)), tag
    assert len(src.findall("propulsion/engine")) == n_engines and der.find("propulsion/engine") is None
    tanks = list(zip(src.findall("propulsion/tank"), der.findall("propulsion/tank"), strict=True))
    assert len(tanks) == n_tanks and all(same_xml(a, b) for a, b in tanks), len(tanks)


def bare_xml(e) -> bytes:
    """The element's XML with every text and tail stripped of white space: its content, not its layout (to compare
    a function of a checked-in file with the derived model's, whose indentation ``ET.indent`` rewrote)."""
    import copy
    import xml.etree.ElementTree as ET

    e = copy.deepcopy(e)
    for x in e.iter():
        x.text = x.text.strip() if x.text else x.text
        x.tail = None
    return ET.tostring(e)


def checked_in_model(name: str, model: str, src: str, n_bytes: int, sha256: str):
    """The checked-in XML ``src`` (a path from the repository root) of the harness aircraft ``name`` is the copy its
    README describes (``n_bytes`` long, SHA-256 ``sha256``), the aircraft flies it as the derived ``model``, and the
    spec's notes name the derived XML's digest.

    Returns:
        ``(source_root, derived_root, spec)``: the parsed source and derived XML (``ElementTree`` elements) and the
        :class:`~benchmarks.jsbsim_harness.AircraftSpec`.

    Raises:
        AssertionError: one of these fails.
    """
    import hashlib
    import xml.etree.ElementTree as ET

    from benchmarks.jsbsim_harness import aircraft
    from benchmarks.jsbsim_harness.derived import REPO_DERIVED, derived_sha, derived_xml
    from benchmarks.jsbsim_harness.logfile import _REPO

    raw = (_REPO / src).read_bytes()
    assert len(raw) == n_bytes and hashlib.sha256(raw).hexdigest() == sha256
    spec = aircraft(name)
    assert spec.model == model and REPO_DERIVED[spec.model][0] == src
    assert f"XML sha256 {derived_sha(spec.model)}" in spec.notes
    return ET.fromstring(raw), ET.fromstring(derived_xml(spec.model)), spec


def assert_openflightsim_assembly(name: str, folder: str, files: dict, parts: tuple, reads: dict) -> None:
    """The checked-in files of a UASLab/OpenFlightSim model (the ultrastick's, the us25e's) are the ones its README
    lists, and its derived model assembles them changing no number (``derived._openflightsim_glide``).

    Args:
        name: the harness aircraft.
        folder: the checked-in folder, from the repository root.
        files: file name -> (bytes, SHA-256), the main file first (the README's table).
        parts: ``(tag, file)`` of the metrics, mass and gear files and, last, ``("aerodynamics", file)``.
        reads: the aerodynamics' ``<property>`` reads renamed by the derivation -> how many there are
            (``fcs/posElev_rad`` -> ``fcs/elevator-pos-rad``, ``fcs/posRud_rad`` -> ``fcs/rudder-pos-rad``).

    Raises:
        AssertionError: a file differs from the README, the derived model has another layout (the fileheader,
            the three parts, an empty propulsion, the direct FCS, the aerodynamics; no system), a part differs
            from its file, or the aerodynamics differ from the file but for the renamed reads.
    """
    import hashlib
    import xml.etree.ElementTree as ET

    from benchmarks.jsbsim_harness import aircraft
    from benchmarks.jsbsim_harness.derived import REPO_DERIVED, derived_sha, derived_xml
    from benchmarks.jsbsim_harness.logfile import _REPO

    for f, (n, sha) in files.items():
        raw = (_REPO / folder / f).read_bytes()
        assert len(raw) == n and hashlib.sha256(raw).hexdigest() == sha, f
    spec = aircraft(name)
    assert REPO_DERIVED[spec.model][0] == f"{folder}/{next(iter(files))}"
    assert f"XML sha256 {derived_sha(spec.model)}" in spec.notes
    der = ET.fromstring(derived_xml(spec.model))
    canon = lambda e: "".join(ET.tostring(e, encoding="unicode").split())   # noqa: E731  (layout aside: ET.indent)
    assert [c.tag for c in der] == ["fileheader", "metrics", "mass_balance", "ground_reactions", "propulsion",
                                    "flight_control", "aerodynamics"]
    for tag, f in parts[:-1]:
        assert canon(der.find(tag)) == canon(ET.parse(_REPO / folder / f).getroot()), tag
    assert list(der.find("propulsion")) == [] and der.find("system") is None
    aero = ET.parse(_REPO / folder / parts[-1][1]).getroot()
    got = [p.text for p in aero.iter("property")]
    assert {k: got.count(k) for k in reads} == reads
    rename = {"fcs/posElev_rad": "fcs/elevator-pos-rad", "fcs/posRud_rad": "fcs/rudder-pos-rad"}
    for p in aero.iter("property"):
        p.text = rename.get(p.text, p.text)
    assert canon(aero) == canon(der.find("aerodynamics"))


def assert_openflightsim_direct_surfaces(name: str, surface_rad: float, min_lift_lbs: float) -> None:
    """A UASLab/OpenFlightSim derived model (the ultrastick's, the us25e's) maps each command straight to its surface,
    +-``surface_rad`` (``aerosurface_scale``, no actuator dynamics, no damper): elevator -> ``fcs/elevator-pos-rad``,
    rudder -> ``fcs/rudder-pos-rad``, aileron -> ``fcs/posAilL_rad`` and ``fcs/posAilR_rad`` = -left (the harness reads
    both, delta_a = -0.5 (left - right) = -left); the flaps stay 0; a yaw rate does not move the rudder. No engine;
    after 50 frames every non-gravity force and moment is aerodynamic, at least ``min_lift_lbs`` of lift.

    Raises:
        AssertionError: the first check that fails.
    """
    from benchmarks.jsbsim_harness import aircraft

    spec = aircraft(name)
    assert not spec.gear_up and spec.aileron_props == ("fcs/posAilL_rad", "fcs/posAilR_rad")
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, surface_rad), "fcs/posAilL_rad": (1, surface_rad),
                               "fcs/posAilR_rad": (1, -surface_rad), "fcs/rudder-pos-rad": (2, surface_rad)},
                        alpha_deg=2.0, r_rad_s=0.2)
    assert fdm.get_propulsion().get_num_engines() == 0
    assert fdm["fcs/posFlapL_rad"] == 0.0 and fdm["fcs/posFlapR_rad"] == 0.0
    assert_aileron_maps_back(spec, 2.0)
    assert_aero_is_the_only_force(fdm, min_lift_lbs, external_zero=True)


#: The roster in the order the aircraft were added, the fokker50 last (the summaries' label tests take prefixes).
ROSTER_ORDER = ("c172x", "pa28", "j3cub", "c182", "t37", "t6", "b747", "f16", "f4n", "rascal", "sgs126", "asw20",
                "iar80", "c684", "ultrastick", "b737", "c172p", "eternity", "us25e", "ka350", "s23", "dr1", "navion",
                "fokker50")


def assert_summaries_label_bare(tmp_path, last: str, clean: tuple[str, ...]) -> None:
    """The markdown summaries of ``eval_jsbsim`` and ``eval_jsbsim_diagnose`` label every aircraft of
    :data:`ROSTER_ORDER` up to ``last`` bare (synthetic rows of those aircraft alone): no row reads
    "(untouched)" or "(held out)", every aircraft has its ``| NAME | light`` row in the first, and each of ``clean``
    its ``| NAME | clean |`` row in the second.

    Args:
        tmp_path: a folder for the two synthetic .jsonl files.
        last: the last aircraft of the roster's prefix written.
        clean: the aircraft whose clean rows the diagnosis summary must show.

    Raises:
        AssertionError: a label or row differs.
    """
    import json

    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose
    from gcs_sysid.aero.table import COEFFICIENTS

    def row(ac):
        errs = {k: {c: 10.0 for c in COEFFICIENTS} for k in ("meas", "gp", "true", "ls")}
        return {"aircraft": ac, "turbulence": "light", "aoa": "ahrs", "seed": 1, **errs, "cov_gp": 90.0,
                "cov_true": 90.0, "alpha_deg": 0.1, "beta_deg": 0.1, "alpha_rms_deg": 1.0, "beta_rms_deg": 1.0}

    acs = ROSTER_ORDER[:ROSTER_ORDER.index(last) + 1]
    p = tmp_path / "r.jsonl"
    p.write_text("".join(json.dumps(row(ac)) + "\n" for ac in acs))
    lines = eval_jsbsim.summarize([str(p)]).splitlines()
    for ac in acs:
        assert any(ln.startswith(f"| {ac} | light") for ln in lines), ac
    assert not any("(held out)" in ln or "(untouched)" in ln for ln in lines)
    d = tmp_path / "d.jsonl"
    d.write_text("".join(json.dumps({"aircraft": ac, "seed": 11, "effects": [], "score": {"ok": True}}) + "\n"
                         for ac in acs))
    lines = eval_jsbsim_diagnose.summarize([str(d)]).splitlines()
    for ac in clean:
        assert any(ln.startswith(f"| {ac} | clean |") for ln in lines), ac
    assert not any("(untouched)" in ln for ln in lines)


def assert_same_aero_as_stock(state, stock_state, n_engines: int, zero=()) -> None:
    """At three states (alpha 4, -3, 0 deg; sideslip 4, -2, 0 deg; the commands (0.3, -0.4, 0.2), (-0.2, 0.3, -0.5),
    0), JSBSim's aerodynamic forces and moments of a derived model (``state(alpha, beta, cmds)``, no engine) equal
    those of the wheel's stock model (``stock_state``, its ``n_engines`` engines stopped) to the last bit (the
    navion's, s23's and dr1's derivation checks: the derivation changes no number). The properties ``zero`` read 0
    in both.

    Raises:
        AssertionError: an engine count, a ``zero`` property or a force or moment differs."""
    for alpha, beta, cmds in ((4.0, 4.0, (0.3, -0.4, 0.2)), (-3.0, -2.0, (-0.2, 0.3, -0.5)), (0.0, 0.0, (0, 0, 0))):
        a, b = state(alpha, beta, cmds), stock_state(alpha, beta, cmds)
        assert a.get_propulsion().get_num_engines() == 0 and b.get_propulsion().get_num_engines() == n_engines
        for k in zero:
            assert a[k] == b[k] == 0.0, (alpha, k)
        for k in ("forces/fbx-aero-lbs", "forces/fby-aero-lbs", "forces/fbz-aero-lbs", "moments/l-aero-lbsft",
                  "moments/m-aero-lbsft", "moments/n-aero-lbsft"):
            assert a[k] == b[k], (alpha, k)
