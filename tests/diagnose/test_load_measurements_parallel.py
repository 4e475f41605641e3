"""``diagnose``'s front end with the spare worker (decode split, specific force) equals the one without."""

from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.diagnose import run as diagnose_run
from gcs_sysid.parallel import PARALLEL_ENV, Helper

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.mark.slow   # ~5 s on a quiet machine; the split and the helper's smoother are checked in the default
# suite by tests/test_pipeline_parallel.py
def test_measurements_with_the_worker_equal_those_without(monkeypatch):
    log, airframe = DATA / "flights" / "sim-trainer-sysid.tlog", DATA / "airframes" / "sim-trainer.toml"
    monkeypatch.setattr(diagnose_run, "SPLIT_MIN_BYTES", 0)     # the sample log is smaller than the threshold
    monkeypatch.setenv(PARALLEL_ENV, "1")
    jobs = []
    real_submit = Helper.submit

    def submit(self, target, *args, **kwargs):
        jobs.append((target, self.parallel))
        return real_submit(self, target, *args, **kwargs)

    monkeypatch.setattr(Helper, "submit", submit)
    a = diagnose_run.load_measurements(log, airframe, 60.0, 150.0)
    monkeypatch.setenv(PARALLEL_ENV, "0")
    b = diagnose_run.load_measurements(log, airframe, 60.0, 150.0)
    used = {t.split(":")[1] for t, par in jobs if par}
    assert {"scan_tlog", "smooth_specific_force"} <= used            # the worker did take both jobs
    assert a.flight.messages == b.flight.messages and a.states.notes == b.states.notes
    for k in a.states.data:
        np.testing.assert_array_equal(a.states.data[k], b.states.data[k], err_msg=k)
    np.testing.assert_array_equal(a.table.X, b.table.X)
    np.testing.assert_array_equal(a.table.Y, b.table.Y)
