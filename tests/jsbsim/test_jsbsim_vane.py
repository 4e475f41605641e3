"""Vanes: an airframe that declares its AOA_SSA as vane measurements gets them as alpha and beta;
the same log with the default declaration (the autopilot's estimate) keeps the kinematic angles."""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, load_truth, make_flight
from gcs_sysid.airframe import airframe_from_dict, airframe_to_dict, load_airframe
from gcs_sysid.errors import InputError
from gcs_sysid.estimation import estimate_states
from gcs_sysid.telemetry import read_log


def _angle_errors(states, truth):
    X, _ = truth.at(states.t)
    m = states.valid & np.isfinite(X[:, 0])
    return [float(np.degrees(np.sqrt(np.mean((states.data[k][m] - X[m, i]) ** 2)))) for i, k in
            ((0, "alpha"), (1, "beta"))]


def test_vane_angles_are_used_only_when_declared(tmp_path):
    files = make_flight(FlightConfig("sgs", duration_s=20.0, turbulence="moderate", seed=5), tmp_path, aoa="vane")
    truth = load_truth(files.truth)
    flight = read_log(files.tlog)
    vane_af = load_airframe(files.airframe)
    assert vane_af.air_angles == "vane"
    est_af = load_airframe(_write(tmp_path / "est.toml", files.airframe.read_text().split("[air_data]")[0]))
    assert est_af.air_angles == "estimate"
    with_vanes = estimate_states(flight, vane_af)
    without = estimate_states(flight, est_af)
    a_v, b_v = _angle_errors(with_vanes, truth)
    a_k, b_k = _angle_errors(without, truth)
    assert a_v < 0.15 and b_v < 0.15            # the vanes' 0.1 deg noise
    assert a_k > 2 * a_v and b_k > 2 * b_v      # moderate gusts: kinematics + slow wind miss them
    assert "vane" in with_vanes.sources["alpha"] and "vane" not in without.sources["alpha"]
    assert any("from the vanes" in n for n in with_vanes.notes)


def _write(path, text):
    path.write_text(text)
    return path


def test_air_data_table_is_checked(data_dir):
    doc = airframe_to_dict(load_airframe(data_dir / "airframes" / "jsbsim-c172x.toml"))
    assert "air_data" not in doc
    doc["air_data"] = {"angles": "vane"}
    af = airframe_from_dict(doc, "x.toml")
    assert af.air_angles == "vane" and airframe_to_dict(af)["air_data"] == {"angles": "vane"}
    with pytest.raises(InputError, match=r"x.toml: \[air_data\] angles must be"):
        airframe_from_dict(dict(doc, air_data={"angles": "boom"}), "x.toml")
    with pytest.raises(InputError, match=r"\[air_data\] must be a table with only 'angles'"):
        airframe_from_dict(dict(doc, air_data={"angles": "vane", "lag": 0.1}), "x.toml")
