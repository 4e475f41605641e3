"""Test-suite configuration: 64-bit JAX (as the CLI uses) and the repository's data paths."""

import os

# One BLAS thread per process: the suite runs on 2 cores next to JAX's own thread pool, and
# oversubscribed OpenBLAS made small linear algebra several times slower (measured in the envelope
# and maneuver tests: 31 s -> 19 s). Set before numpy is imported.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

# With a CUDA build of jaxlib each JAX process takes 75 % of the GPU's memory at its first call, so of several test
# processes on one GPU (the xdist workers, the CLI subprocesses) all but the first fail; allocate on demand instead
# (JAX's documentation, "GPU memory allocation"). The CPU build ignores it. docs/gp.md, "On a GPU".
os.environ.setdefault("XLA_PYTHON_CLIENT_PREALLOCATE", "false")

# Compiled JAX programs go to a cache private to this test session (inherited by the xdist
# workers and the CLI subprocesses), so the suite neither reads nor fills the user's cache. The
# process that made the folder removes it at exit (the workers and subprocesses have ended by then);
# a folder given by the caller is left alone.
import atexit  # noqa: E402
import shutil  # noqa: E402
import tempfile  # noqa: E402

if not os.environ.get("GCS_SYSID_JAX_CACHE", "").strip():
    os.environ["GCS_SYSID_JAX_CACHE"] = tempfile.mkdtemp(prefix="gcs-sysid-jax-")
    atexit.register(shutil.rmtree, os.environ["GCS_SYSID_JAX_CACHE"], ignore_errors=True)

from pathlib import Path

import pytest

from gcs_sysid.jaxconfig import enable_compilation_cache, enable_x64

enable_x64()
# Each test process reads and fills that cache from its start (before, only after its first replay):
# a program one xdist worker compiled is loaded by the other, and by later CLI subprocesses. Measured:
# tests/gp/test_honest.py 68.7 s CPU without the cache, 14.3 s with it warm; but -n 2 on four GP
# files only -2.3 % (the workers mostly compile different programs; docs/benchmarks.md, ci-cut).
enable_compilation_cache()

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "data"


@pytest.fixture(autouse=True)
def _signal_handling_restored():
    """Each test leaves SIGINT/SIGTERM as it found them: a CLI command run in-process installs
    :mod:`gcs_sysid.stopping` (or, for ``listen``, its own SIGTERM handler) in this worker, and a later
    test's signal or fork then reached that watcher and ended the worker (nineteenth session; CI of
    2026-11-25, which lost a worker and hung)."""
    import signal

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    from gcs_sysid import stopping

    stopping.uninstall()
    for s, h in before.items():
        if signal.getsignal(s) is not h and h is not None:
            signal.signal(s, h)


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The repository's data/ directory."""
    return DATA


#: Seconds per test file in the default run on CI's 2-core machine (the tenth session's fresh-clone
#: runs' ``--durations``, less what the eleventh session's ci-cut moved to slow; files under ~9 s are
#: left out). ``--dist loadfile`` hands whole files to the two workers in xdist's order, most tests
#: first, which left the long one-test files (a live session, the parallel replay) to the end, where one
#: worker finished them while the other idled. The files named here go first, longest first (longest
#: processing time first); the others follow in xdist's order. A stale or missing entry changes only
#: the order, never which tests run.
FILE_SECONDS = {
    "tests/diagnose/test_diagnose_e2e.py": 62, "tests/test_cli_robust.py": 57, "tests/test_cli.py": 54,
    "tests/gp/test_honest.py": 42, "tests/test_roundtrip.py": 41, "tests/jsbsim/test_effects_diagnose.py": 38,
    "tests/diagnose/test_faults.py": 35, "tests/live/test_listen_can_learner.py": 30,
    "tests/test_data_files.py": 25, "tests/test_pipeline_parallel.py": 23, "tests/gp/test_lmc.py": 22,
    "tests/gp/test_streaming.py": 21, "tests/diagnose/test_physical.py": 20, "tests/gp/test_model.py": 20,
    "tests/report/test_report.py": 19, "tests/test_maneuvers.py": 16, "tests/live/test_mavproxy.py": 16,
    "tests/test_campaign.py": 16, "tests/diagnose/test_diagnose_sim.py": 14, "tests/sim/test_sim_effects.py": 13,
    "tests/gp/test_joint.py": 12, "tests/live/test_learner_catch_up.py": 10, "tests/jsbsim/test_predict.py": 10,
    "tests/estimation/test_estimation_sim_roundtrip.py": 9,
}


@pytest.hookimpl(optionalhook=True)   # pytest-xdist's hook; without xdist nothing is distributed
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the files of :data:`FILE_SECONDS` first, longest first."""
    if config.getoption("dist", None) != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class LongestFirst(LoadFileScheduling):
        def _assign_work_unit(self, node):
            if not getattr(self, "_ordered", False):   # the queue is complete at the first assignment
                self._ordered = True
                queue = getattr(self, "workqueue", None)   # xdist 3.x's internal queue of files
                if isinstance(queue, dict):                # any other shape keeps xdist's own order
                    units = sorted(queue.items(), key=lambda u: -FILE_SECONDS.get(u[0], 0))   # stable
                    queue.clear()
                    queue.update(units)
            super()._assign_work_unit(node)

    return LongestFirst(config, log)
