"""Model file: term parsing, errors, round trip, evaluation (numpy and JAX agree with a hand sum)."""

import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.errors import InputError
from gcs_sysid.sim.model_file import (VOCABULARY, AeroModel, canonical_term, evaluate_weights, features, load_model,
                                      model_from_dict, parse_term, save_model)


def test_parse_term_canonical_forms():
    assert parse_term("1") == ()
    assert parse_term("alpha") == (0,)
    assert parse_term("alpha^2") == (0, 0)
    assert parse_term("alpha*beta") == (0, 1)
    assert parse_term("q_hat*delta_e") == (3, 5)
    assert canonical_term((1, 0)) == "alpha*beta"
    assert canonical_term((9, 9)) == "V^2"
    assert len(VOCABULARY) == 66 and len(set(VOCABULARY)) == 66
    assert all(canonical_term(parse_term(t)) == t for t in VOCABULARY)


@pytest.mark.parametrize("text, words", [
    ("gamma", "unknown variable 'gamma'"),
    ("beta*alpha", "write 'alpha*beta'"),
    ("alpha*alpha", "write 'alpha^2'"),
    ("alpha^2*beta", "degree 3"),
    ("alpha^3", "only '^2'"),
    ("", "empty"),
])
def test_parse_term_errors_name_file_and_term(text, words):
    with pytest.raises(InputError) as e:
        parse_term(text, "m.toml", "Cm")
    msg = str(e.value)
    assert "m.toml" in msg and "[Cm]" in msg and words in msg and "\n" not in msg


def test_evaluate_matches_hand_sum_and_jax(model):
    rng = np.random.default_rng(0)
    X = rng.normal(size=(50, 10)) * 0.1
    X[:, 9] = 20 + rng.normal(size=50)
    Y = model.evaluate(X)
    a, q_hat, de = X[:, 0], X[:, 3], X[:, 5]
    cm = 0.03 - 0.8 * a - 12.0 * q_hat - 0.9 * de
    cx = -0.035 + 0.05 * a + 3.5 * a**2 - 0.02 * de
    assert np.allclose(Y[:, COEFFICIENTS.index("Cm")], cm)
    assert np.allclose(Y[:, COEFFICIENTS.index("CX")], cx)
    Yj = np.asarray(evaluate_weights(jnp.asarray(X), jnp.asarray(model.weights())))
    assert np.allclose(Yj, Y)
    F = features(X)
    assert F.shape == (50, 66)
    k = VOCABULARY.index("beta*delta_r")
    assert np.allclose(F[:, k], X[:, 1] * X[:, 7])


def test_round_trip_and_with_terms(tmp_path, model):
    m2 = model.with_terms({"Cm": {"alpha^2": -0.5}, "Cl": {"alpha*beta": 0.1}})
    assert m2.value("Cm", "alpha^2") == -0.5 and m2.value("Cm", "alpha") == model.value("Cm", "alpha")
    m3 = m2.with_terms({"Cm": {"alpha": 0.1}}, add=True)
    assert m3.value("Cm", "alpha") == pytest.approx(model.value("Cm", "alpha") + 0.1)
    p = tmp_path / "m.toml"
    save_model(m2, p, header="fitted by a test")
    assert p.read_text().startswith("# fitted by a test")
    back = load_model(p)
    assert back.terms == m2.terms and back.name == m2.name
    X = np.random.default_rng(1).normal(size=(5, len(REGRESSORS)))
    assert np.allclose(back.evaluate(X), m2.evaluate(X))


def test_model_file_errors(tmp_path):
    with pytest.raises(InputError, match="unknown table or field 'CD'"):
        model_from_dict({"CD": {"alpha": 1.0}}, "x.toml")
    with pytest.raises(InputError, match=r"x.toml: \[Cm\] term 'alpha' must be a finite number"):
        model_from_dict({"Cm": {"alpha": "big"}}, "x.toml")
    with pytest.raises(InputError, match=r"\[Cn\] term 'r_hat\*beta'"):
        model_from_dict({"Cn": {"r_hat*beta": 1.0}}, "x.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[Cm\nalpha = 1")
    with pytest.raises(InputError, match="not valid TOML"):
        load_model(bad)
    with pytest.raises(InputError, match="not found"):
        load_model(tmp_path / "missing.toml")
    with pytest.raises(InputError, match="unknown coefficient 'CL'"):
        AeroModel({}).with_terms({"CL": {"alpha": 1.0}})


def test_shipped_model_signs(model):
    v = model.value
    assert 4.5 <= -v("CZ", "alpha") <= 5.0
    assert -1.0 <= v("Cm", "alpha") <= -0.5 and -15 <= v("Cm", "q_hat") <= -10
    assert -0.5 <= v("Cl", "p_hat") <= -0.4 and v("Cl", "delta_a") < 0
    assert 0.05 <= v("Cn", "beta") <= 0.1 and -0.2 <= v("Cn", "r_hat") <= -0.1
    assert v("Cm", "delta_e") < 0 and v("Cn", "delta_r") < 0 and v("CY", "delta_r") > 0
    assert v("CX", "alpha^2") != 0
