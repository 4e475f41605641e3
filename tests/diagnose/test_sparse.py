"""The differential sparse search (gcs_sysid/diagnose/sparse.py) on the project's synthetic flights."""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.sparse import merge_findings, sparse_search, stlsq

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured


@pytest.fixture(scope="module")
def airframe():
    return load_airframe(AIRFRAME)


def _ctx(airframe, effects=(), seed=5, inadequacy=None):
    """A synthetic flight of BASE with ``effects`` added to Y and an ``inadequacy`` shared with the reference."""
    table, states = measured(BASE, seed=seed, hidden=None, duration=90.0)
    for j, f in list(effects) + list(inadequacy or []):
        table.Y[:, j] += f(table)
    ctx = DiagContext.build(table, airframe, BASE, states)
    return ctx, ctx.Y - ctx.model_values()


def test_stlsq_recovers_a_sparse_vector_and_prunes_the_rest():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(800, 30))
    theta = np.zeros(30)
    theta[[2, 17]] = [0.8, -0.5]
    y = A @ theta + 0.05 * rng.normal(size=800)
    th = stlsq(A, y, threshold=0.1)
    assert set(np.nonzero(th)[0]) == {2, 17}
    assert th[[2, 17]] == pytest.approx([0.8, -0.5], abs=0.02)
    assert stlsq(A, 0.01 * rng.normal(size=800), threshold=0.5).tolist() == [0.0] * 30


# shared model inadequacy: present in the reference flight and in the flight under test
_INADEQUATE = [(4, lambda t: -0.8 * np.maximum(0.0, t.x("alpha") - np.radians(4.0)))]


def test_two_effects_at_once_are_both_named_and_the_shared_inadequacy_is_not(airframe):
    ref = _ctx(airframe, seed=4, inadequacy=_INADEQUATE)
    ctx, R = _ctx(airframe, [(5, lambda t: -0.08 * t.x("delta_a")), (3, lambda t: 2.0 * t.x("alpha") * t.x("beta"))],
                  seed=5, inadequacy=_INADEQUATE)
    res = sparse_search(ctx, R, reference=ref)
    causes = {f["cause"]: f for f in res["findings"]}
    assert set(causes) == {"Cn:delta_a", "Cl:alpha*beta"}, [(f["cause"], f["evidence"]["score"])
                                                           for f in res["findings"]]
    assert causes["Cn:delta_a"]["estimate"] - causes["Cn:delta_a"]["model_value"] == pytest.approx(-0.08, rel=0.25)
    assert causes["Cl:alpha*beta"]["estimate"] - causes["Cl:alpha*beta"]["model_value"] == pytest.approx(2.0, rel=0.25)
    assert all(f["gain"]["percent"] >= 50 for f in causes.values()), [(c, f["gain"]) for c, f in causes.items()]
    assert res["differential"] and res["segment"]["untouched_rows"] > 0
    # without the reference, the same inadequacy is named as a cause of the flight: the differential step matters
    alone = sparse_search(ctx, R)
    assert any(f["coefficient"] == "Cm" for f in alone["findings"])


def test_nothing_changed_nothing_named(airframe):
    ref = _ctx(airframe, seed=4, inadequacy=_INADEQUATE)
    ctx, R = _ctx(airframe, seed=6, inadequacy=_INADEQUATE)
    res = sparse_search(ctx, R, reference=ref)
    assert res["findings"] == [], [(f["cause"], f["evidence"]["score"]) for f in res["findings"]]


def test_merge_puts_sensor_causes_first_and_drops_unconfirmed_terms():
    findings = [{"cause": "cg_offset", "evidence": {}},
                {"cause": "bias:airspeed", "evidence": {"domain": "data compatibility"}},
                {"cause": "Cn:delta_a", "evidence": {}}]
    sparse = {"findings": [{"cause": "Cn:delta_a", "evidence": {"domain": "sparse search"}}]}
    out = merge_findings(findings, sparse)
    assert [f["cause"] for f in out] == ["bias:airspeed", "Cn:delta_a"]
    assert out[1]["source"] == "sparse search"


def test_cli_reference_log_must_exist(tmp_path, capsys):
    from diag_flights import MODEL

    from gcs_sysid.cli import main

    log = AIRFRAME.parents[1] / "flights" / "sim-trainer-sysid.tlog"
    rc = main(["diagnose", str(log), "--airframe", str(AIRFRAME), "--model", str(MODEL), "--out",
               str(tmp_path / "out"), "--search", "--reference", str(tmp_path / "missing.tlog")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "--reference" in err[0] and "missing.tlog" in err[0], err


def test_merge_keeps_the_simpler_catalogue_term():
    cat = {"cause": "Cm:alpha", "coefficient": "Cm", "evidence": {}}
    sparse = {"findings": [{"cause": "Cm:alpha*delta_t", "coefficient": "Cm", "evidence": {}}]}
    out = merge_findings([cat], sparse)
    assert [f["cause"] for f in out] == ["Cm:alpha"] and out[0]["source"].startswith("catalogue")
    other = {"cause": "Cm:beta", "coefficient": "Cm", "evidence": {}}
    assert [f["cause"] for f in merge_findings([other], sparse)] == ["Cm:alpha*delta_t"]


def test_merge_keeps_the_searched_power_without_simpler_catalogue_powers():
    """``simpler_catalogue_powers`` False (the default): a catalogue ``x`` does not replace the search's ``x^2`` (the
    regressor itself is the left-out factor), and still replaces a product with another regressor (``alpha*delta_t``);
    True restores the rule before (the catalogue's ``x`` replaces the power too)."""
    cat = {"cause": "Cm:alpha", "coefficient": "Cm", "evidence": {}}
    power = {"cause": "Cm:alpha^2", "coefficient": "Cm", "evidence": {}}
    product = {"cause": "Cm:alpha*delta_t", "coefficient": "Cm", "evidence": {}}
    for sparse in ({"findings": [power]}, {"findings": [power], "thresholds": {"simpler_catalogue_powers": False}}):
        out = merge_findings([cat], sparse)
        assert [f["cause"] for f in out] == ["Cm:alpha^2"] and out[0]["source"] == "sparse search"
    assert [f["cause"] for f in merge_findings([cat], {"findings": [product]})] == ["Cm:alpha"]
    before = {"findings": [power], "thresholds": {"simpler_catalogue_powers": True}}
    assert [f["cause"] for f in merge_findings([cat], before)] == ["Cm:alpha"]


def test_side_force_scale_is_named_as_scale_of_cy(airframe):
    """CY k times the model's: the residual is (k - 1) times the model's CY, the ``scale:CY`` candidate."""
    ref = _ctx(airframe, seed=4)
    cy = lambda t: 0.4 * (BASE["CY"]["beta"] * t.x("beta") + BASE["CY"]["delta_r"] * t.x("delta_r"))  # noqa: E731
    ctx, R = _ctx(airframe, [(1, cy)], seed=5)
    res = sparse_search(ctx, R, reference=ref)
    assert res["findings"] and res["findings"][0]["cause"] == "scale:CY", \
        [(f["cause"], f["evidence"]["score"]) for f in res["findings"]]
    f = res["findings"][0]
    assert f["estimate"] == pytest.approx(1.4, abs=0.1) and f["model_value"] == 1.0
    # a scale of a moment is not in the library (it would stand in for term-level causes)
    assert not any(t["term"].startswith("scale:") for e in res["coefficients"] if e["coefficient"] != "CY"
                   for t in e["terms"])


def _alpha_error_flight(airframe, seed, e2, cm_alpha2=0.0):
    """A synthetic flight whose measured alpha carries ``e2 * alpha / V`` (a wind-estimate error of the
    AHRS angle of attack), and optionally a Cm:alpha^2 change that acts on the true alpha."""
    from diag_synthetic import measured

    table, states = measured(BASE, seed=seed, hidden=None, duration=90.0)
    a_true = table.X[:, 0].copy()
    table.Y[:, 4] += cm_alpha2 * a_true**2
    table.X[:, 0] = a_true + e2 * a_true / table.X[:, 9]
    ctx = DiagContext.build(table, airframe, BASE, states)
    return ctx, ctx.Y - ctx.model_values()


def test_angle_error_over_airspeed_is_removed_as_a_nuisance_not_named(airframe):
    ref = _ctx(airframe, seed=4)
    ctx, R = _alpha_error_flight(airframe, 6, e2=1.8)       # alpha reads 10 % high at 18 m/s
    res = sparse_search(ctx, R, reference=ref)
    assert res["findings"] == [], [(f["cause"], f["evidence"]["score"]) for f in res["findings"]]
    assert res["angle_nuisance"]["alpha"][2] == pytest.approx(1.8, rel=0.2)
    # without the nuisance the same flight gets a lift "change": the test can fail
    off = sparse_search(ctx, R, reference=ref, thresholds={"angle_nuisance": False})
    assert any(f["coefficient"] in ("CZ", "CX") for f in off["findings"]), off["findings"]


def test_moment_term_survives_the_angle_nuisance(airframe):
    """The nuisance is fitted on the forces only: a Cm:alpha^2 change is still named and sized."""
    ref = _ctx(airframe, seed=4)
    ctx, R = _alpha_error_flight(airframe, 7, e2=1.8, cm_alpha2=-3.0)
    res = sparse_search(ctx, R, reference=ref, keep_residual=True)
    assert res["findings"] and res["findings"][0]["cause"] == "Cm:alpha^2", res["findings"]
    # keep_residual: what the search saw; its Cm part on the training rows follows the injected -3 alpha^2
    tr, te = res["rows"]["train"], res["rows"]["untouched"]
    assert res["residual"].shape == R.shape and tr.max() < te.min()
    a2 = ctx.X[tr, 0] ** 2
    slope = np.polyfit(a2 - a2.mean(), res["residual"][tr, 4], 1)[0]
    assert slope == pytest.approx(-3.0, rel=0.3)
    f = res["findings"][0]
    assert f["estimate"] - f["model_value"] == pytest.approx(-3.0, rel=0.25)
    assert f["evidence"]["std_error_method"].startswith("Morelli and Klein")
    # the library keeps the measured mean alpha (the slow test below shows the shift without it)
    assert res["angle_nuisance"]["library_shift_rad"][0] == pytest.approx(0.0, abs=1e-12)


def _slow_alpha_error_flight(airframe, seed, rms_deg, cm_alpha2=0.0):
    """A synthetic flight whose measured alpha carries a slowly wandering error (below 0.1 Hz, a
    wind-estimate error of the AHRS angle), and optionally a Cm:alpha^2 change on the true alpha.
    Returns (ctx, R, the error in rad)."""
    from diag_synthetic import smooth

    table, states = measured(BASE, seed=seed, hidden=None, duration=90.0)
    a_true = table.X[:, 0].copy()
    table.Y[:, 4] += cm_alpha2 * a_true**2
    dt = float(np.median(np.diff(table.t)))
    err = smooth(np.random.default_rng(100 + seed), len(a_true), dt, 0.1, np.radians(rms_deg))
    table.X[:, 0] = a_true + err
    ctx = DiagContext.build(table, airframe, BASE, states)
    return ctx, ctx.Y - ctx.model_values(), err


def test_lift_alpha_error_recovers_a_slow_angle_error(airframe):
    """The lift residual through the model's lift slope gives back the slow alpha error."""
    from gcs_sysid.diagnose.lift_alpha import lift_alpha_error

    ctx, R, err = _slow_alpha_error_flight(airframe, 8, 0.5)
    e, info = lift_alpha_error(ctx.t, ctx.X, R[:, 2], ctx.model_values, ctx.valid, cutoff_hz=0.2)
    v = ctx.valid
    resid = (e - err)[v] - np.mean((e - err)[v])            # a constant is the intercept's
    assert np.sqrt(np.mean(resid**2)) < 0.3 * np.sqrt(np.mean(err[v] ** 2))
    assert info["slope_median"] == pytest.approx(BASE["CZ"]["alpha"], rel=0.05)
    # nothing to find on a flight whose alpha is right
    ctx0, R0 = _ctx(airframe, seed=8)
    e0, _ = lift_alpha_error(ctx0.t, ctx0.X, R0[:, 2], ctx0.model_values, ctx0.valid)
    assert np.sqrt(np.mean(e0[ctx0.valid] ** 2)) < 0.1 * np.sqrt(np.mean(err[v] ** 2))


@pytest.mark.slow
def test_alpha_squared_term_on_a_slowly_wrong_alpha(airframe):
    """Cm:alpha^2 on a flight whose alpha wanders by 0.6 deg: with the lift-equation correction the
    term is named, sized within 25 % and its untouched gain is larger than without it."""
    ref = _ctx(airframe, seed=4)
    ctx, R, _ = _slow_alpha_error_flight(airframe, 9, 0.6, cm_alpha2=-3.0)
    on = sparse_search(ctx, R, reference=ref, thresholds={"lift_alpha_hz": 0.2})
    off = sparse_search(ctx, R, reference=ref, thresholds={"lift_alpha_hz": 0})
    assert on["findings"] and on["findings"][0]["cause"] == "Cm:alpha^2", on["findings"]
    f = on["findings"][0]
    assert f["estimate"] - f["model_value"] == pytest.approx(-3.0, rel=0.25)
    assert "lift_alpha" in on and "lift_alpha" not in off
    g_off = next((e["held_out"]["percent"] for e in off["coefficients"] if e["coefficient"] == "Cm"), 0.0)
    assert f["gain"]["percent"] > g_off + 5.0, (f["gain"], g_off)


@pytest.mark.slow
def test_angle_nuisance_does_not_shift_the_mean_alpha_of_the_library(airframe):
    """The nuisance's fit has a free constant per coefficient, so the level of the angle error is not
    determined; the library keeps the measured mean alpha (an arbitrary shift turned JSBSim's
    alpha^2 into alpha^3). With the centring off the same flight gets a shift: the test can fail."""
    ref = _ctx(airframe, seed=4)
    ctx, R = _alpha_error_flight(airframe, 6, e2=1.8, cm_alpha2=-3.0)
    on = sparse_search(ctx, R, reference=ref)
    off = sparse_search(ctx, R, reference=ref, thresholds={"angle_error_centred": False})
    assert on["angle_nuisance"]["library_shift_rad"][0] == pytest.approx(0.0, abs=1e-12)
    assert abs(off["angle_nuisance"]["library_shift_rad"][0]) > 1e-4, off["angle_nuisance"]
    f = on["findings"][0]
    assert f["cause"] == "Cm:alpha^2" and f["estimate"] - f["model_value"] == pytest.approx(-3.0, rel=0.25)


def _hinge_design(seed):
    """Candidates in alpha (polynomials and hinges at four knots) over a slow sweep, five blocks."""
    rng = np.random.default_rng(seed)
    n = 2000
    a = np.radians(2.0) + np.radians(2.5) * np.sin(np.linspace(0, 7 * np.pi, n)) + np.radians(0.3) * rng.normal(size=n)
    knots = np.radians([-0.6, 0.1, 1.5, 3.5])
    names = ["alpha", "alpha^2", "alpha^3"] + [f"max(0,alpha-{k:.1f}deg)" for k in np.degrees(knots)] + ["delta_e"]
    A = np.column_stack([a, a**2, a**3] + [np.maximum(0.0, a - k) for k in knots] + [rng.normal(size=n)])
    A = A - A.mean(axis=0)
    fold = np.minimum((np.arange(n) * 5) // n, 4)
    return names, A, a, fold, rng


def test_one_standard_error_rule_prefers_the_polynomial_over_a_hinge():
    """A curvature -4 alpha^2 that a hinge happens to fit as well is named alpha^2 (the smooth_se rule);
    a true break at 1.5 deg stays a hinge (the polynomial loses by far more than the folds' spread)."""
    from gcs_sysid.diagnose.sparse import _prefer_smooth

    names, A, a, fold, rng = _hinge_design(3)
    ih = names.index("max(0,alpha-1.5deg)")
    r = -4.0 * a**2 + 0.002 * rng.normal(size=a.size)
    r -= r.mean()
    assert [names[k] for k in _prefer_smooth(A, r, fold, [ih], names, 1.0)] == ["alpha^2"]
    # the other selected terms are kept in place
    assert [names[k] for k in _prefer_smooth(A, r, fold, [ih, len(names) - 1], names, 1.0)] == ["alpha^2", "delta_e"]
    brk = -0.6 * np.maximum(0.0, a - np.radians(1.5)) + 0.0005 * rng.normal(size=a.size)
    brk -= brk.mean()
    assert [names[k] for k in _prefer_smooth(A, brk, fold, [ih], names, 1.0)] == ["max(0,alpha-1.5deg)"]


def _wind_axes_to_body(a, b, D, Yw, L):
    """Body-axis (CX, CY, CZ) of wind-axis drag, side force and lift (JSBSim's ``Tw2b``, forces
    ``(-D, Y_w, -L)``; Stevens, Lewis and Johnson 3rd ed. sec. 2.3)."""
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    return (ca * cb * -D - ca * sb * Yw - sa * -L, sb * -D + cb * Yw, sa * cb * -D - sa * sb * Yw + ca * -L)


def test_scale_columns_hold_the_wind_axis_side_force():
    """A side force k times the model's adds ``(k - 1) cos(beta) C_Yw`` to the body-axis CY, not ``(k - 1) CY``:
    the drag's ``-sin(beta) C_D`` part does not scale. The CY column is exactly that; fitted on it, the change
    reads k - 1, fitted on the body-axis CY it reads ``(k - 1) C_Yw,beta / (C_Yw,beta - C_D)``."""
    from gcs_sysid.diagnose.sparse import scale_columns

    rng = np.random.default_rng(3)
    T, k = 4000, 1.6
    a, b = np.radians(3.0 + rng.normal(0, 2.0, T)), np.radians(rng.normal(0, 4.0, T))
    D, Yw, L = 0.08 + 0.5 * a ** 2, -0.2 * b, 0.4 + 5.0 * a
    CX, CY, CZ = _wind_axes_to_body(a, b, D, Yw, L)
    M = np.zeros((T, 6))
    M[:, 0], M[:, 1], M[:, 2], M[:, 4] = CX, CY, CZ, 0.3
    X = np.zeros((T, 10))
    X[:, 0], X[:, 1] = a, b
    S = scale_columns(M, X)
    assert S[:, 1] == pytest.approx(np.cos(b) * Yw, abs=1e-12)
    assert np.array_equal(np.delete(S, 1, axis=1), np.delete(M, 1, axis=1))
    assert np.array_equal(scale_columns(M, X, wind_axis=False), M)
    dCY = _wind_axes_to_body(a, b, D, k * Yw, L)[1] - CY
    fit = lambda x: np.linalg.lstsq(np.c_[np.ones(T), x], dCY, rcond=None)[0][1]  # noqa: E731
    assert fit(S[:, 1]) == pytest.approx(k - 1, rel=1e-6)
    assert fit(CY) == pytest.approx((k - 1) * -0.2 / (-0.2 - 0.08), rel=0.03)      # 0.43, not 0.6


@pytest.mark.slow
def test_a_wind_axis_side_force_scale_reads_k_minus_1(airframe):
    """The synthetic flight's wind-axis side force (the model's, rotated with its drag) scaled by 1.6: the
    search's ``scale:CY`` reads 0.6 on the wind-axis column and less on the body-axis CY (the rule before)."""
    from gcs_sysid.diagnose.sparse import scale_columns

    ref = _ctx(airframe, seed=4)
    ctx, _ = _ctx(airframe, seed=5)
    extra = 0.6 * scale_columns(ctx.model_values(), ctx.X)[:, 1]
    got = {}
    for wind in (True, False):
        c2, R = _ctx(airframe, [(1, lambda t: extra)], seed=5)
        res = sparse_search(c2, R, reference=ref, thresholds={"side_force_wind_axis": wind})
        f = [f for f in res["findings"] if f["cause"] == "scale:CY"]
        got[wind] = f[0]["estimate"] if f else None
    assert got[True] == pytest.approx(1.6, abs=0.02), got
    assert got[False] is None or got[False] < got[True] - 0.02, got


def test_a_hinge_the_flight_never_reaches_does_not_break_the_differential_search(airframe):
    """The reference's top alpha hinge lies above every alpha of the flight under test, so that column is
    constant on this flight and left out of its library: the reference's ridge inadequacy is still applied
    (the JSBSim rascal's ``Cm:alpha^2 = -8`` flight in light turbulence crashed the search with a shape
    mismatch), and the flight's own change is still named."""
    from gcs_sysid.diagnose.sparse import _library, alpha_quantile_knots

    table, states = measured(BASE, seed=4, hidden=None, duration=90.0)
    a = table.X[:, 0]
    med = np.nanmedian(a)
    table.X[:, 0] = np.where(a > med, med + 4.0 * (a - med), a)       # the reference flew to higher alpha
    rctx = DiagContext.build(table, airframe, BASE, states)
    ref = (rctx, rctx.Y - rctx.model_values())
    ctx, R = _ctx(airframe, [(5, lambda t: -0.08 * t.x("delta_a"))], seed=5)
    knots = alpha_quantile_knots(rctx)
    assert np.nanmax(ctx.x("alpha")) < knots[-1]
    assert len(_library(ctx, knots)[0]) < len(_library(rctx, knots)[0])
    res = sparse_search(ctx, R, reference=ref)
    causes = {f["cause"]: f for f in res["findings"]}
    assert "Cn:delta_a" in causes, [(f["cause"], f["evidence"]["score"]) for f in res["findings"]]
    assert causes["Cn:delta_a"]["estimate"] - causes["Cn:delta_a"]["model_value"] == pytest.approx(-0.08, rel=0.25)


def test_a_change_within_its_expanded_uncertainty_is_not_a_change():
    """GUM coverage factor 2 on the combined uncertainty a named term reports (``naming_coverage_factor``).

    The numbers are the asw20's in MIL-F-8785C light turbulence (sixteenth session, branch i9-asw): on the
    ``Cm:alpha^2 = -8`` flight of seed 2 the search named ``Cm:alpha`` 0.528 with a combined standard uncertainty of
    0.752 (the air angles' stated offset and scale uncertainty, type B), while ``Cn:delta_a`` read -0.0500 +- 0.0014.
    """
    from gcs_sysid.diagnose.sparse import NAMING_COVERAGE_FACTOR, THRESHOLDS, beyond_expanded_uncertainty

    assert NAMING_COVERAGE_FACTOR == 2.0 and THRESHOLDS["naming_coverage_factor"] == NAMING_COVERAGE_FACTOR

    def finding(estimate, model_value, u_c):
        ev = {} if u_c is None else {"uncertainty": {"combined": u_c}}
        return {"estimate": estimate, "model_value": model_value, "std_error": u_c, "evidence": ev}

    inside = beyond_expanded_uncertainty(finding(0.528, 0.0, 0.752))
    assert not inside["beyond"] and inside["change"] == pytest.approx(0.528) and "not a change" in inside["why"]
    assert beyond_expanded_uncertainty(finding(-0.0438, 0.0062, 0.0014))["beyond"]
    # the factor, not a t of 1: 1.5 standard uncertainties is still inside the interval; 2.5 is outside
    assert not beyond_expanded_uncertainty(finding(1.5, 0.0, 1.0))["beyond"]
    assert beyond_expanded_uncertainty(finding(-2.5, 0.0, 1.0))["beyond"]
    # a scale finding's change is its factor minus 1 (model_value 1)
    assert not beyond_expanded_uncertainty(finding(1.05, 1.0, 0.03))["beyond"]
    assert beyond_expanded_uncertainty(finding(1.3, 1.0, 0.03))["beyond"]
    # no combined uncertainty reported (a delay): its own decisions stand
    assert beyond_expanded_uncertainty(finding(0.06, 0.0, None))["beyond"]
    assert beyond_expanded_uncertainty(finding(0.5, 0.0, 1.0), k=0.25)["beyond"]


def test_centred_estimate_is_the_named_coefficient_whatever_companion_is_selected():
    """centred_estimate (seventeenth session): a correction that is exactly k alpha^2, fitted with alpha^3 and a
    hinge in alpha beside alpha^2 (as the JSBSim iar80's search selected), reads k through the reparameterised
    columns; the bare alpha^2 coefficient of a fit whose companions move it does not. Parents are listed in the
    library's spelling. Mechanism check on synthetic columns (no flight)."""
    from gcs_sysid.diagnose.sparse import _centre_columns, _parent_terms

    assert _parent_terms("alpha^2") == ["alpha"]
    assert _parent_terms("alpha*beta") == ["alpha", "beta"]
    assert set(_parent_terms("alpha^2*beta")) == {"alpha", "beta", "alpha^2", "alpha*beta"}
    assert _parent_terms("max(0,alpha-1.0deg)") == [] and _parent_terms("alpha") == []
    rng = np.random.default_rng(0)
    a = 0.03 + 0.035 * rng.standard_normal(3000)          # mean alpha 1.7 deg, sd 2 deg
    d = rng.standard_normal(3000)
    k = -8.0
    # the selection's fitted correction: k alpha^2 written with companions that share its curvature
    terms = ["alpha^2", "alpha^3", "max(0,alpha-0.8deg)", "alpha", "delta_e"]
    A = np.column_stack([np.ones_like(a), a**2, a**3, np.maximum(0, a - np.radians(0.8)), a, d])
    theta = np.array([0.0, k - 3.0, 40.0, -0.2, 0.01, 0.0])
    y = A @ theta
    # least squares on the same columns returns theta: the bare alpha^2 coefficient is k - 3
    assert np.linalg.lstsq(A, y, rcond=None)[0][1] == pytest.approx(k - 3.0)
    # the reparameterised columns give the named coefficient of the best [1, alpha, alpha^2] description
    rows = np.arange(a.size)
    Ac = _centre_columns(A, terms, "alpha^2", rows)
    th_c = np.linalg.lstsq(Ac, y, rcond=None)[0]
    B = np.column_stack([np.ones_like(a), a, a**2])
    expected = np.linalg.lstsq(B, y - d * theta[5], rcond=None)[0][2]
    assert th_c[1] == pytest.approx(expected, rel=1e-8)
    assert np.allclose(Ac @ th_c, y)                         # the same fitted function
    # a correction that is only k alpha^2 reads k exactly, whatever companions the fit carries
    y2 = k * a**2 + 0.5 * d
    assert np.linalg.lstsq(Ac, y2, rcond=None)[0][1] == pytest.approx(k, rel=1e-8)
    # the delta_e column is in other regressors: left alone
    assert np.allclose(Ac[:, 5], d)


def test_centred_scale_gives_the_named_term_the_scale_share_along_its_regressor():
    """centred_scale (twenty-third session, branch i9-cyscale): a side-force correction fitted as ``d beta + s S``,
    ``S`` the model's wind-axis side force (beta and a spurious r_hat column, as the eternity's reference carries),
    reads along beta ``d + s dS/dbeta`` once the scale's own part in beta is projected on the named term; without it
    the named coefficient is ``d`` alone (the half of the eternity's scale that was missing). The own part is the
    model's side force with every other regressor at its mean, so its slope is the model's wind-axis derivative.
    Mechanism check on synthetic columns (no flight)."""
    from types import SimpleNamespace

    from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
    from gcs_sysid.diagnose.sparse import _centre_columns, _centred_weights, _scale_own_part

    rng = np.random.default_rng(1)
    T = 4000
    X = np.zeros((T, len(REGRESSORS)))
    X[:, REGRESSORS.index("alpha")] = 0.08 + 0.01 * rng.standard_normal(T)
    X[:, REGRESSORS.index("beta")] = 0.03 * rng.standard_normal(T)
    X[:, REGRESSORS.index("r_hat")] = 0.02 * rng.standard_normal(T) + 0.3 * X[:, REGRESSORS.index("beta")]
    X[:, REGRESSORS.index("V")] = 17.0
    cyb, cyr, cx, cz = -0.226, -0.529, -0.06, -0.5

    def model_values(Xp, model=None):
        M = np.zeros((len(Xp), 6))
        M[:, COEFFICIENTS.index("CX")] = cx
        M[:, COEFFICIENTS.index("CZ")] = cz
        M[:, COEFFICIENTS.index("CY")] = cyb * Xp[:, REGRESSORS.index("beta")] + cyr * Xp[:, REGRESSORS.index("r_hat")]
        return M

    ctx = SimpleNamespace(model_values=model_values)
    rows = np.arange(T)
    jy = COEFFICIENTS.index("CY")
    b = X[:, REGRESSORS.index("beta")]
    a_mean = X[:, REGRESSORS.index("alpha")].mean()
    part = _scale_own_part(ctx, X, X, rows, None, jy, {"beta"}, wind_axis=False)
    assert np.polyfit(b, part, 1)[0] == pytest.approx(cyb, rel=1e-9)          # body axis: the model's CY_beta
    part_w = _scale_own_part(ctx, X, X, rows, None, jy, {"beta"}, wind_axis=True)
    c_d = -np.cos(a_mean) * cx - np.sin(a_mean) * cz
    assert np.polyfit(b, part_w, 1)[0] == pytest.approx(cyb + c_d, rel=0.01)   # wind axis: CY_beta + C_D
    # the fit's columns: 1, beta, the whole scale column (wind axis), p_hat-like noise column
    S = np.cos(b) * (np.cos(b) * model_values(X)[:, jy] + np.sin(b) * c_d)
    other = rng.standard_normal(T)
    terms = ["beta", "scale:CY", "p_hat"]
    A = np.column_stack([np.ones(T), b, S, other])
    d, s = -0.066, 0.208
    y = d * b + s * S + 0.03 * other
    bare = np.linalg.lstsq(_centre_columns(A, terms, "beta", rows), y, rcond=None)[0][1]
    assert bare == pytest.approx(d, rel=1e-8)                                 # no holder: the bare coefficient
    w = _centred_weights(A, terms, "beta", rows, {1: part_w})
    assert w[1] == pytest.approx(np.polyfit(b, part_w, 1)[0], rel=1e-6) and w[2] == 0.0
    Ac = _centre_columns(A, terms, "beta", rows, {1: part_w})
    th = np.linalg.lstsq(Ac, y, rcond=None)[0]
    assert th[1] == pytest.approx(d + s * w[1], rel=1e-8)                     # the whole slope along beta
    assert np.allclose(Ac @ th, y)                                            # the same fitted function
    # a weight given (the reference's fit takes the flight's)
    assert np.allclose(_centre_columns(A, terms, "beta", rows, fixed={1: w[1]}), Ac)
    # the other way round: scale:CY named, beta selected beside it; beta's own column projected on the scale's
    terms2 = ["scale:CY", "beta"]
    A2 = np.column_stack([np.ones(T), S, b])
    w2 = _centred_weights(A2, terms2, "scale:CY", rows, {1: b})
    Bs = np.column_stack([np.ones(T), S])
    assert w2[1] == pytest.approx(np.linalg.lstsq(Bs, b, rcond=None)[0][1], rel=1e-9)
    y2 = s * S + d * b
    th2 = np.linalg.lstsq(_centre_columns(A2, terms2, "scale:CY", rows, {1: b}), y2, rcond=None)[0]
    # the named factor is what a scale fitted alone on the whole correction reads
    assert th2[1] == pytest.approx(np.linalg.lstsq(Bs, y2, rcond=None)[0][1], rel=1e-6)


def test_library_control_trim_keeps_a_curvature_apart_from_its_elevator_product(airframe):
    """At a large elevator trim ``alpha^2*delta_e`` is ``delta_e0 alpha^2`` plus a small part (the JSBSim dr1,
    twenty-sixth session, i9-cma2): the search split a ``Cm:alpha^2`` between the two. With
    ``library_control_trim`` the library's surfaces are measured about the reference's trim, the product's column
    is nearly orthogonal to ``alpha^2``, and a flight whose elevator trim is the reference's reads the same
    product columns whatever that trim. Fails if the trim is not applied."""
    from gcs_sysid.diagnose.search import candidate_library
    from gcs_sysid.diagnose.sparse import THRESHOLDS, control_trim

    assert THRESHOLDS["library_control_trim"] is False             # opt-in
    table, states = measured(BASE, seed=4, hidden=None, duration=90.0)
    table.X[:, 5] = table.X[:, 5] - 0.18                             # a 10-deg nose-up elevator trim
    rctx = DiagContext.build(table, airframe, BASE, states)
    trim = control_trim(rctx)
    assert trim["delta_e"] == pytest.approx(float(np.mean(rctx.x("delta_e")[rctx.train])), abs=1e-12)
    assert trim["delta_e"] < -0.15 and abs(trim["delta_a"]) < 0.05

    def corr(names, Phi, a, b):
        x, y = Phi[rctx.valid, names.index(a)], Phi[rctx.valid, names.index(b)]
        return abs(np.corrcoef(x, y)[0, 1])

    n0, P0 = candidate_library(rctx)
    n1, P1 = candidate_library(rctx, control_trim=trim)
    assert n0 == n1
    assert corr(n0, P0, "alpha^2", "alpha^2*delta_e") > 0.8          # collinear through the trim
    assert corr(n1, P1, "alpha^2", "alpha^2*delta_e") < 0.5          # apart about it
    de = rctx.x("delta_e") - trim["delta_e"]
    k = n1.index("alpha^2*delta_e")
    assert np.allclose(P1[:, k], rctx.x("alpha") ** 2 * de)
    # the lags and hinges do not depend on the trim
    lag = [i for i, n in enumerate(n0) if n.startswith("delta_e(t-") or n.startswith("max(")]
    assert lag and np.allclose(P0[:, lag], P1[:, lag])


def _shifted_curvature_searches(airframe, offset_deg):
    """The sparse search without and with ``power_with_parent = ("alpha",)`` on a flight with a hidden
    ``Cm:alpha^2`` of -3 whose measured alpha is ``offset_deg`` off the air's, against a clean reference."""
    ref = _ctx(airframe, seed=4)
    table, states = measured(BASE, seed=9, hidden=None, duration=90.0)
    a = table.X[:, 0].copy()
    table.Y[:, 4] += -3.0 * a**2
    table.X[:, 0] = a + np.radians(offset_deg)
    ctx = DiagContext.build(table, airframe, BASE, states)
    R = ctx.Y - ctx.model_values()
    return tuple(sparse_search(ctx, R, reference=ref, thresholds={"power_with_parent": blocks})
                 for blocks in ((), ("alpha",)))


def test_power_with_parent_names_a_curvature_about_a_shifted_alpha(airframe):
    """A ``Cm:alpha^2`` of -3 on a flight whose measured alpha is 3 deg off the air's (the JSBSim dr1's
    flight-mean vertical wind, twenty-sixth session, i9-cma2): ``-3 (alpha_m - e)^2`` has a linear part larger
    than its curvature, and with one term a step the search names ``Cm:alpha^3``. With ``power_with_parent``
    ``alpha^2`` enters with ``alpha`` and is named, its change within 25 % and the pair's untouched gain
    reported as the finding's."""
    from gcs_sysid.diagnose.sparse import THRESHOLDS, power_parent_blocks

    assert power_parent_blocks(["alpha", "beta", "alpha^2", "beta^2", "alpha^3"], ("alpha", "q_hat")) == [(2, 0)]
    off, on = _shifted_curvature_searches(airframe, 3.0)
    assert [f["cause"] for f in off["findings"]] != ["Cm:alpha^2"]
    assert [f["cause"] for f in on["findings"]] == ["Cm:alpha^2"], on["findings"]
    f = on["findings"][0]
    assert f["evidence"]["entered_with"] == ["alpha"]
    assert [t["term"] for t in f["evidence"]["terms"][:2]] == ["alpha^2", "alpha"]
    assert f["estimate"] - f["model_value"] == pytest.approx(-3.0, rel=0.25)
    assert f["gain"]["percent"] >= 50.0
    assert THRESHOLDS["power_with_parent"] in ((), ("alpha",), ("Cm:alpha",), ("Cm:alpha", "Cl:alpha*beta"))


def test_power_with_parent_leaves_a_curvature_that_wins_alone_to_the_search_without_blocks(airframe):
    """A ``Cm:alpha^2`` of -3 with alpha 1 deg off the air's: the square is the best single term, so it enters
    alone and ``alpha`` follows on its own PRESS, as with the option off; the finding carries no ``entered_with``
    and the differential step judges the term alone (twenty-eighth session, i9-pwp2: before, the block took the
    first step and the finding was judged with ``alpha`` beside it, which lost the s23's and t6's flights)."""
    off, on = _shifted_curvature_searches(airframe, 1.0)
    cm = [next(c for c in res["coefficients"] if c["coefficient"] == "Cm") for res in (off, on)]
    assert [t["term"] for t in cm[1]["terms"]][:2] == ["alpha^2", "alpha"] == [t["term"] for t in cm[0]["terms"]][:2]
    assert "entered_with" not in cm[1]
    assert [f["cause"] for f in on["findings"]] == [f["cause"] for f in off["findings"]] == ["Cm:alpha^2"]
    assert "entered_with" not in on["findings"][0]["evidence"]
    assert on["findings"][0]["estimate"] == pytest.approx(off["findings"][0]["estimate"])


def _coefficients_a_block_entered(monkeypatch, ctx, R, ref, blocks):
    """The sparse search with ``power_with_parent = blocks``, and the coefficients in whose forward search a
    block (more than one column in one step) entered."""
    from gcs_sysid.diagnose import sparse

    entered, current = [], [None]
    fit, select = sparse._fit_coefficient, sparse.select_terms

    def fit_logged(*a, **kw):
        current[0] = kw.get("coefficient", a[8] if len(a) > 8 else None)
        return fit(*a, **kw)

    def select_logged(*a, steps=None, **kw):
        steps = [] if steps is None else steps
        out = select(*a, steps=steps, **kw)
        entered.extend(current[0] for st in steps if len(st) > 1)
        return out

    monkeypatch.setattr(sparse, "_fit_coefficient", fit_logged)
    monkeypatch.setattr(sparse, "select_terms", select_logged)
    res = sparse_search(ctx, R, reference=ref, thresholds={"power_with_parent": blocks})
    monkeypatch.undo()
    return res, set(entered)


def test_power_with_parent_named_for_cm_offers_the_block_only_in_cms_search(airframe, monkeypatch):
    """``power_with_parent = ("Cm:alpha",)``: the block ``(alpha^2, alpha)`` is offered in ``Cm``'s search only
    (twenty-ninth session, i9-pwp3: offered to every coefficient, it entered the sgs126's ``Cn`` search and kept
    ``p_hat`` out). A flight with the same curvature about a 3-deg-shifted alpha hidden in ``Cm`` and in ``CZ``:
    with ``("alpha",)`` the block enters both searches; named for ``Cm`` it enters ``Cm``'s alone, and ``Cm``'s
    curvature is still named with its parent."""
    from gcs_sysid.diagnose.sparse import power_parent_blocks

    names = ["alpha", "beta", "alpha^2", "beta^2"]
    assert power_parent_blocks(names, ("Cm:alpha",), "Cm") == [(2, 0)]
    assert power_parent_blocks(names, ("Cm:alpha",), "Cn") == power_parent_blocks(names, ("Cm:alpha",)) == []
    assert power_parent_blocks(names, ("alpha",), "Cn") == [(2, 0)]
    ref = _ctx(airframe, seed=4)
    table, states = measured(BASE, seed=9, hidden=None, duration=90.0)
    a = table.X[:, 0].copy()
    table.Y[:, 4] += -3.0 * a**2
    table.Y[:, 2] += -3.0 * a**2
    table.X[:, 0] = a + np.radians(3.0)
    ctx = DiagContext.build(table, airframe, BASE, states)
    R = ctx.Y - ctx.model_values()
    _, every = _coefficients_a_block_entered(monkeypatch, ctx, R, ref, ("alpha",))
    assert "Cm" in every and every - {"Cm"}, every
    res, only = _coefficients_a_block_entered(monkeypatch, ctx, R, ref, ("Cm:alpha",))
    assert only == {"Cm"}, only
    cm = next(f for f in res["findings"] if f["coefficient"] == "Cm")
    assert cm["cause"] == "Cm:alpha^2" and cm["evidence"]["entered_with"] == ["alpha"]


def test_the_naming_floor_is_where_the_share_gates_stop_a_term():
    """sparse.naming_floor: a term below ``f n`` takes less than ``min_press_drop`` of the PRESS (not named however
    significant); one well above it takes more. Synthetic: white noise n = 1 and one curvature term in alpha."""
    from gcs_sysid.diagnose.sparse import THRESHOLDS, _fit_coefficient, naming_floor

    rng = np.random.default_rng(3)
    T = 4000
    alpha = 0.05 + 0.03 * np.sin(np.linspace(0, 40 * np.pi, T)) + 0.01 * rng.standard_normal(T)
    beta = 0.02 * rng.standard_normal(T)
    names = ["alpha", "alpha^2", "beta", "alpha*beta"]
    Phi = np.column_stack([alpha, alpha ** 2, beta, alpha * beta])
    tr, te = np.arange(0, 3200), np.arange(3200, T)
    th = dict(THRESHOLDS)
    noise = rng.standard_normal(T)
    floor = naming_floor(names, Phi, noise, te, th)
    f = np.sqrt(th["min_press_drop"] / (1 - th["min_press_drop"]))       # the PRESS gate binds at today's gates
    assert floor["factor"] == pytest.approx(max(f, np.sqrt(1 / 0.9 ** 2 - 1)))
    assert floor["term_rms_min"] == pytest.approx(floor["factor"] * np.std(noise[te]))
    k_min = floor["min_change"]["alpha^2"]
    assert k_min == pytest.approx(floor["term_rms_min"] / np.std(alpha[te] ** 2))
    # a curvature at 0.5 and 1.6 of the floor: the first's PRESS drop stays under the gate, the second's is over
    drops = []
    for size in (0.5, 1.6):
        r = size * k_min * (alpha ** 2 - np.mean(alpha ** 2)) + noise
        entry, _ = _fit_coefficient(names, Phi, r, tr, te, 5, th, 4000, "Cm")
        drops.append(entry["score"])
        assert entry["naming_floor"]["residual_rms"] < 1.1          # the residual after the selected terms
    assert drops[0] < th["min_press_drop"] < drops[1], drops


def test_the_report_shows_the_naming_floor():
    from gcs_sysid.diagnose.report import _floor_section

    fl = {"residual_rms": 0.002, "factor": 0.816, "term_rms_min": 0.00163, "min_change": {"alpha*beta": 4.1}}
    page = _floor_section({"coefficients": [{"coefficient": "Cl", "naming_floor": fl}]})
    assert "What this flight could name" in page and "smallest alpha*beta change" in page and "4.1" in page
    assert "0.82 times the residual" in page
    assert _floor_section(None) == "" and _floor_section({"coefficients": [{"coefficient": "Cl"}]}) == ""


def test_hierarchy_se_names_the_square_where_the_flight_cannot_tell_it_from_a_cubic():
    """sparse ``hierarchy_se``: a cubic selected over a narrow range of alpha away from zero is replaced by the
    square with its parent when their block PRESS lies within 2 standard errors (the pair stands as the block,
    ``entered_with``); over a range through zero the cubic is told apart and stays; 0 leaves the cubic."""
    from gcs_sysid.diagnose.sparse import THRESHOLDS, _fit_coefficient

    names = ["alpha", "alpha^2", "alpha^3", "beta"]
    tr, te = np.arange(0, 3200), np.arange(3200, 4000)

    def selected(centre, amplitude, hse, seed=5):
        rng = np.random.default_rng(seed)
        alpha = centre + amplitude * np.sin(np.linspace(0, 40 * np.pi, 4000)) + 0.005 * rng.standard_normal(4000)
        Phi = np.column_stack([alpha, alpha ** 2, alpha ** 3, 0.02 * rng.standard_normal(4000)])
        r = -40 * alpha ** 3 + 0.002 * rng.standard_normal(4000)
        entry, _ = _fit_coefficient(names, Phi, r, tr, te, 5, dict(THRESHOLDS, hierarchy_se=hse), 4000, "Cm")
        return [t["term"] for t in entry["terms"]], entry.get("entered_with"), entry["score"]

    assert selected(0.07, 0.025, 0.0)[:2] == (["alpha^3"], None)
    terms, parents, score = selected(0.07, 0.025, 2.0)
    assert terms == ["alpha^2", "alpha"] and parents == ["alpha"] and score > 0.9
    assert selected(0.0, 0.08, 2.0)[:2] == (["alpha^3"], None)


def _shifted_product_searches(airframe, offset_deg, k=3.0):
    """The sparse search with ``power_with_parent`` ``("Cm:alpha",)`` and ``("Cm:alpha", "Cl:alpha*beta")`` on a
    flight with a hidden ``Cl:alpha*beta`` of ``k`` whose measured alpha is ``offset_deg`` off the air's, against a
    clean reference."""
    ref = _ctx(airframe, seed=4)
    table, states = measured(BASE, seed=9, hidden=None, duration=90.0)
    a = table.X[:, 0].copy()
    table.Y[:, 3] += k * a * table.X[:, 1]
    table.X[:, 0] = a + np.radians(offset_deg)
    ctx = DiagContext.build(table, airframe, BASE, states)
    R = ctx.Y - ctx.model_values()
    return tuple(sparse_search(ctx, R, reference=ref, thresholds={"power_with_parent": blocks})
                 for blocks in (("Cm:alpha",), ("Cm:alpha", "Cl:alpha*beta")))


def test_power_with_parent_names_a_product_about_a_shifted_alpha(airframe):
    """A ``Cl:alpha*beta`` of 3 on a flight whose measured alpha is 4 deg off the air's (the alpha level a flight
    does not fix: the JSBSim Eternity's, fifty-fifth session): ``3 (alpha_m - e) beta`` is ``3 alpha_m beta`` less
    ``3 e beta``, and with one term a step the search names something else (here ``Cl:alpha^2*beta`` 0.34, the cubic
    standing for the pair; on the Eternity ``Cl:beta``). With the product as a ``power_with_parent`` entry,
    ``alpha*beta`` enters with ``beta`` and is named, its change within 25 %."""
    from gcs_sysid.diagnose.sparse import power_parent_blocks

    names = ["alpha", "beta", "alpha^2", "alpha*beta", "beta*delta_e"]
    assert power_parent_blocks(names, ("Cl:alpha*beta",), "Cl") == [(3, 1)]
    assert power_parent_blocks(names, ("Cl:alpha*beta",), "Cn") == []
    assert power_parent_blocks(names, ("Cm:alpha", "Cl:alpha*beta"), "Cm") == [(2, 0)]
    off, on = _shifted_product_searches(airframe, 4.0)
    assert [f["cause"] for f in off["findings"] if f["coefficient"] == "Cl"] != ["Cl:alpha*beta"], off["findings"]
    cl = [f for f in on["findings"] if f["coefficient"] == "Cl"]
    assert [f["cause"] for f in cl] == ["Cl:alpha*beta"], on["findings"]
    assert cl[0]["evidence"]["entered_with"] == ["beta"]
    assert cl[0]["estimate"] - cl[0]["model_value"] == pytest.approx(3.0, rel=0.25)
