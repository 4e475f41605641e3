"""The replay with its worker process (decode split, specific force, figures) equals the replay without."""

from pathlib import Path

import numpy as np

from gcs_sysid.pipeline import ReplayOptions, run_replay

DATA = Path(__file__).resolve().parents[1] / "data"


def test_parallel_replay_equals_serial(tmp_path):
    log, airframe = DATA / "flights" / "sim-trainer-sysid.tlog", DATA / "airframes" / "sim-trainer.toml"
    # the whole log is decoded; a 90 s window is fitted; suggestions for Cn only (``replay --target``)
    opts = dict(progress=False, t_from=60.0, t_to=150.0, targets=("Cn",))
    a = run_replay(log, airframe, tmp_path / "parallel", ReplayOptions(parallel=True, **opts))
    b = run_replay(log, airframe, tmp_path / "serial", ReplayOptions(parallel=False, **opts))
    assert a.messages == b.messages and a.notes == b.notes
    assert a.states.data.keys() == b.states.data.keys()
    for k in a.states.data:
        np.testing.assert_allclose(a.states.data[k], b.states.data[k], rtol=1e-9, atol=1e-12, err_msg=k)
    np.testing.assert_allclose(a.table.Y, b.table.Y, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a.pred_mean, b.pred_mean, rtol=1e-6, atol=1e-9)
    assert [s.kind for s in a.suggestions] == [s.kind for s in b.suggestions]
    assert a.suggestions and all(set(s.coefficients) == {"Cn"} for s in a.suggestions), a.suggestions
    for name in ("report.html", "summary.md", "coefficients.csv", "suggestions.json"):
        assert (tmp_path / "parallel" / name).stat().st_size > 0 and (tmp_path / "serial" / name).is_file()
