"""The spare worker process: jobs run there, errors come back, and every failure falls back to here."""

import os
import signal
import threading
import time

import pytest

from gcs_sysid.parallel import PARALLEL_ENV, Helper, default_enabled


@pytest.fixture
def helper():
    h = Helper(enabled=True)
    assert h.parallel
    yield h
    h.close()


def test_job_runs_in_the_worker(helper):
    job = helper.submit("math:hypot", 3.0, 4.0)
    assert job.result() == 5.0 and job.ran_in_worker
    pid = helper.submit("os:getpid").result()
    assert pid != os.getpid()


def test_jobs_keep_their_order_and_keyword_arguments(helper):
    jobs = [helper.submit("builtins:round", x, ndigits=1) for x in (1.26, 2.34, 3.45)]
    assert [j.result() for j in jobs] == [1.3, 2.3, 3.5]


def test_error_of_the_job_is_raised_here(helper):
    job = helper.submit("math:sqrt", -1.0)
    with pytest.raises(ValueError, match="math domain error"):
        job.result()
    assert helper.submit("math:sqrt", 9.0).result() == 3.0   # the worker survives it


def test_unpicklable_argument_runs_here(helper):
    lock = threading.Lock()
    job = helper.submit("builtins:repr", lock)
    assert job.result() == repr(lock) and not job.ran_in_worker


def test_prints_in_the_worker_do_not_corrupt_results(helper):
    assert helper.submit("builtins:print", "noise on stdout").result() is None
    assert helper.submit("math:factorial", 5).result() == 120


def test_dead_worker_falls_back_to_this_process(helper):
    pid = helper.submit("os:getpid").result()
    os.kill(pid, signal.SIGKILL)
    time.sleep(0.2)
    job = helper.submit("math:factorial", 6)
    assert job.result() == 720 and not job.ran_in_worker


def test_disabled_helper_runs_everything_here():
    with Helper(enabled=False) as h:
        assert not h.parallel
        job = h.submit("math:cos", 0.0)
        assert job.result() == 1.0 and not job.ran_in_worker


def test_bad_target_is_an_error():
    with Helper(enabled=False) as h:
        with pytest.raises(ValueError, match="module:function"):
            h.submit("math.sqrt", 4.0).result()


def test_environment_switch(monkeypatch):
    monkeypatch.setenv(PARALLEL_ENV, "0")
    assert not default_enabled()
    with Helper() as h:
        assert not h.parallel
        assert h.submit("math:sqrt", 16.0).result() == 4.0
