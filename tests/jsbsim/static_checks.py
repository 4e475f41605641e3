"""Checks of JSBSim's own properties at the harness's initial condition (:func:`ic_state`, no turbulence, nothing
flown) shared by the per-aircraft tests (``test_jsbsim_<name>.py``) and the roster tests: the FCS
(:func:`surface_state`, :func:`check_direct_fcs`, :func:`assert_aileron_maps_back`,
:func:`assert_deflections_map_back`, :func:`assert_aero_is_the_only_force`), static stability and control
(:func:`assert_pitch_derivatives`, :func:`assert_lateral_derivatives`: each test passes its own numbers and
tolerances as ``pytest.approx``) and the hidden effects as JSBSim computes them (:func:`effect_state`,
:func:`injected_moment`, :func:`delay_trace`, :func:`assert_hidden_effects_in_jsbsim`).

Twenty-eighth session: folded from sixteen per-aircraft files' copies with every assertion and tolerance kept;
twenty-ninth: moved here unchanged from ``truth_fits.py`` (which keeps the checks of flown flights).
"""

import numpy as np

__all__ = ["ic_state", "lateral_coefficients", "cm_without_alpha_dot", "assert_pitch_derivatives",
           "assert_lateral_derivatives", "SURFACE_CMDS", "surface_state", "check_direct_fcs",
           "assert_aileron_maps_back", "assert_deflections_map_back", "assert_aero_is_the_only_force",
           "effect_state", "MOMENT_EFFECTS", "injected_moment", "delay_trace", "assert_hidden_effects_in_jsbsim"]


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
