"""The wide-library search: forward stepwise by block PRESS on training rows, gain measured once held out."""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.core import diagnose
from gcs_sysid.diagnose.search import candidate_library, press_stepwise, search_residual

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured


@pytest.fixture(scope="module")
def airframe():
    return load_airframe(AIRFRAME)


def _ctx(airframe, effects=(), seed=5):
    table, states = measured(BASE, seed=seed, hidden=None, duration=90.0)
    for j, f in effects:
        table.Y[:, j] += f(table)
    ctx = DiagContext.build(table, airframe, BASE, states)
    return ctx, ctx.Y - ctx.model_values()


def test_library_spans_cubics_hinges_lags(airframe):
    ctx, _ = _ctx(airframe)
    names, Phi = candidate_library(ctx)
    assert Phi.shape == (len(ctx.t), len(names))
    for n in ("alpha^3", "alpha*beta*delta_a", "delta_t^2*alpha", "alpha_dot_hat", "delta_e(t-0.1)-delta_e"):
        assert n in names or n.replace("delta_t^2*alpha", "alpha*delta_t^2") in names, n
    assert sum(n.startswith("max(0,alpha-") for n in names) == 4
    i = names.index("alpha^2*beta")
    assert np.allclose(Phi[:, i], ctx.x("alpha") ** 2 * ctx.x("beta"))


def test_library_keeps_a_constant_hinge_when_asked(airframe):
    """A hinge whose knot alpha never crosses is all zeros: the search's library leaves it out, while the
    library rebuilt at perturbed angles to re-evaluate selected terms keeps every candidate (the
    thirty-fifth session's roster crashed with KeyError 'max(0,alpha-2.4deg)' on an ultrastick flight when
    the alpha-scale sensitivity moved alpha below a knot)."""
    ctx, _ = _ctx(airframe)
    top = float(np.nanmax(ctx.x("alpha")))
    knots = np.array([top - 0.02, top + 0.01])
    names, Phi = candidate_library(ctx, alpha_knots=knots)
    every, Phi_all = candidate_library(ctx, alpha_knots=knots, drop_constant=False)
    inside, beyond = (f"max(0,alpha-{np.degrees(k):.1f}deg)" for k in knots)
    assert inside in names and beyond not in names
    assert beyond in every and not Phi_all[:, every.index(beyond)].any()
    assert set(names) <= set(every)
    for n in names:
        assert np.array_equal(Phi[:, names.index(n)], Phi_all[:, every.index(n)])


def test_press_stepwise_against_brute_force():
    """Block PRESS of the chosen first term equals a direct leave-one-block-out refit."""
    rng = np.random.default_rng(0)
    N, K = 600, 12
    Phi = rng.normal(size=(N, K))
    r = 0.7 * Phi[:, 3] + 0.05 * rng.normal(size=N)
    fold = np.arange(N) * 4 // N
    res = press_stepwise(Phi, r, fold, max_terms=3)
    assert res["selected"][0] == 3 and len(res["selected"]) == 1      # nothing else lowers PRESS by 2 %
    direct = 0.0
    for k in range(4):
        m = fold == k
        th = np.linalg.lstsq(Phi[~m][:, [3]], r[~m], rcond=None)[0]
        direct += np.sum((r[m] - Phi[m][:, [3]] @ th) ** 2)
    assert res["press"][1] == pytest.approx(direct, rel=1e-6)


def _press_stepwise_loop(Phi, r, fold, max_terms=6, min_press_gain=0.02):
    """The straightforward form: one solve per candidate and fold (the batched code must agree)."""
    scale = np.sqrt(np.mean(Phi**2, axis=0))
    A = Phi / np.where(scale > 0, scale, 1.0)
    F = int(fold.max()) + 1
    Gk = np.stack([A[fold == k].T @ A[fold == k] for k in range(F)])
    bk = np.stack([A[fold == k].T @ r[fold == k] for k in range(F)])
    rk = np.array([r[fold == k] @ r[fold == k] for k in range(F)])
    G, b = Gk.sum(0), bk.sum(0)
    ridge = 1e-9 * np.trace(G) / G.shape[0]
    sel, press = [], [float(rk.sum())]
    while len(sel) < max_terms:
        best, best_p = None, press[-1]
        for c in range(A.shape[1]):
            if c in sel:
                continue
            S = sel + [c]
            p = 0.0
            for k in range(F):
                th = np.linalg.solve(G[np.ix_(S, S)] - Gk[k][np.ix_(S, S)] + ridge * np.eye(len(S)), b[S] - bk[k][S])
                p += rk[k] - 2 * th @ bk[k][S] + th @ Gk[k][np.ix_(S, S)] @ th
            if p < best_p:
                best, best_p = c, p
        if best is None or press[-1] - best_p < min_press_gain * press[-1]:
            break
        sel.append(best)
        press.append(float(best_p))
    return sel, press


def test_press_stepwise_batched_equals_the_loop():
    """Same terms, same PRESS path (1e-9) as one solve per candidate and fold, with a near-collinear pair."""
    rng = np.random.default_rng(3)
    for trial in range(3):
        N, K = 1500, 60
        Phi = rng.normal(size=(N, K)) * rng.uniform(0.1, 10.0, K)
        Phi[:, 5] = 0.999 * Phi[:, 3] + 0.001 * rng.normal(size=N)
        Phi[:, 7] = 0.0                                                      # an empty column
        z = Phi / Phi.std(0).clip(1e-12)
        r = z[:, [3, 17, 40]] @ np.array([0.5, -0.2, 0.05]) + 0.3 * np.sin(z[:, 50]) + 0.1 * rng.normal(size=N)
        fold = np.minimum((np.arange(N) * 5) // N, 4)
        res = press_stepwise(Phi, r, fold)
        sel, press = _press_stepwise_loop(Phi, r, fold)
        assert res["selected"] == sel and len(sel) >= 3
        assert np.allclose(res["press"], press, rtol=1e-9, atol=0.0)


def test_two_effects_outside_the_vocabulary_are_both_found(airframe):
    """A cubic in Cm and a break in the Cl slope at 5 deg alpha, at once; nothing found elsewhere."""
    ctx, R = _ctx(airframe, [(4, lambda t: -40.0 * t.x("alpha") ** 3),
                             (3, lambda t: -0.8 * np.maximum(0.0, t.x("alpha") - np.radians(5.0)))])
    res = {e["coefficient"]: e for e in search_residual(ctx, R)}
    cm = res["Cm"]
    assert cm["terms"][0]["term"] == "alpha^3"
    assert cm["terms"][0]["estimate"] == pytest.approx(-40.0, rel=0.25)
    assert cm["held_out"]["percent"] >= 50.0
    cl = res["Cl"]
    assert cl["terms"] and all(t["term"].startswith("max(0,alpha-") for t in cl["terms"])
    assert cl["held_out"]["percent"] >= 50.0
    for c in ("CX", "CY", "CZ", "Cn"):
        assert res[c]["terms"] == [] or res[c]["held_out"]["percent"] < 5.0, res[c]


def test_nothing_hidden_nothing_selected(airframe):
    ctx, R = _ctx(airframe, seed=4)
    res = search_residual(ctx, R)
    assert len(res) == 6
    assert all(e["held_out"]["percent"] < 5.0 for e in res), [(e["coefficient"], e["terms"]) for e in res]


@pytest.mark.slow
def test_diagnose_reports_the_search(airframe):
    table, states = measured(BASE, seed=5, hidden=None, duration=90.0)
    table.Y[:, 4] += -40.0 * table.x("alpha") ** 3
    d = diagnose(table, airframe, BASE, states, output_error=False, search=True)
    cm = next(e for e in d.data["search"] if e["coefficient"] == "Cm")
    assert "alpha^3" in [t["term"] for t in cm["terms"]]
    assert "search_s" in d.data["timings"]


def test_a_block_enters_in_one_step_when_its_columns_alone_lose():
    """``k (x - e)^2`` about a shifted origin: its linear part is larger than its curvature, so ``x`` alone enters
    first; offered as a block, ``(x^2, x)`` enters in one step, with the block PRESS of a direct refit."""
    rng = np.random.default_rng(2)
    N = 900
    x = rng.normal(size=N)
    Phi = np.column_stack([x, x**2, x**3, rng.normal(size=(N, 5))])
    r = (x - 1.5) ** 2
    r = r - r.mean() + 0.05 * rng.normal(size=N)
    Phi = Phi - Phi.mean(axis=0)
    fold = np.minimum((np.arange(N) * 5) // N, 4)
    single = press_stepwise(Phi, r, fold, max_terms=2)
    assert single["selected"][0] == 0 and single["steps"] == [[c] for c in single["selected"]]
    res = press_stepwise(Phi, r, fold, max_terms=3, blocks=[(1, 0)])
    assert res["steps"][0] == [1, 0] and res["selected"][:2] == [1, 0]
    direct = 0.0
    for k in range(5):
        m = fold == k
        th = np.linalg.lstsq(Phi[~m][:, [1, 0]], r[~m], rcond=None)[0]
        direct += np.sum((r[m] - Phi[m][:, [1, 0]] @ th) ** 2)
    assert res["press"][1] == pytest.approx(direct, rel=1e-6)
    assert res["press"][1] < 0.05 * single["press"][1]
    # a block that does not fit within max_terms is not offered
    assert press_stepwise(Phi, r, fold, max_terms=1, blocks=[(1, 0)])["selected"] == [0]


def test_a_square_that_wins_alone_enters_alone_and_its_parent_on_its_own_press():
    """The block rescues a square that a correlated single beats; where the square is the step's best single it
    enters alone (the path without blocks), and the parent follows only on its own PRESS (twenty-eighth session,
    i9-pwp2: before, the block took the first step of the s23's and t6's ``Cm:alpha^2`` flights where the square
    won alone, and the parent beside it halved the curvature)."""
    rng = np.random.default_rng(3)
    N = 900
    x = rng.normal(size=N)
    Phi = np.column_stack([x, x**2, x**3, rng.normal(size=(N, 5))])
    r = (x - 0.2) ** 2                      # the curvature dominates; its linear part, -0.4 x, is real but smaller
    r = r - r.mean() + 0.05 * rng.normal(size=N)
    Phi = Phi - Phi.mean(axis=0)
    fold = np.minimum((np.arange(N) * 5) // N, 4)
    single = press_stepwise(Phi, r, fold, max_terms=3)
    assert single["steps"][:2] == [[1], [0]]
    # offered the block, the search takes the same path, one column a step (before: the block, [[1, 0]])
    res = press_stepwise(Phi, r, fold, max_terms=3, blocks=[(1, 0)])
    assert res["steps"] == single["steps"] and res["press"] == pytest.approx(single["press"])
