"""``benchmarks/pool_eval.py``'s arms: a worker runs many jobs and the evaluation scripts set module-level switches
from their options, so every arm must name the same options, or a switch one arm set leaks into the next arm's job.
(The pool's runs themselves fly JSBSim and take minutes; they are measured in docs/benchmarks.md, fortieth session.)"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks.pool_eval import EFFECT_GROUPS, parse_arms


def test_arms_that_name_the_same_options_parse():
    arms = parse_arms(["base:--wind-residual-scale off", "ws: --wind-residual-scale on"])
    assert arms == [("base", ["--wind-residual-scale", "off"]), ("ws", ["--wind-residual-scale", "on"])]
    assert parse_arms(["a:", "b:"]) == [("a", []), ("b", [])]
    assert [n for n, _ in parse_arms(["a:--x=on", "b:--x off"])] == ["a", "b"]       # --opt=value names --opt
    assert parse_arms(["x:--sparse-thresholds '{\"a\": 1}'"]) == [("x", ["--sparse-thresholds", '{"a": 1}'])]


@pytest.mark.parametrize("specs, words", [
    (["base:", "ws:--wind-residual-scale on"], "same options"),       # the switch would leak into base's next job
    (["base:--wind-window 15", "ws:--wind-residual-scale on"], "same options"),
    (["--wind-residual-scale on"], "NAME:OPTIONS"),
    (["a:--x 1", "a:--x 2"], "twice"),
])
def test_arms_that_would_leak_a_switch_are_refused(specs, words):
    with pytest.raises(ValueError, match=words):
        parse_arms(specs)


def test_a_clean_only_arm_must_be_an_arm(capsys):
    from benchmarks.pool_eval import main

    with pytest.raises(SystemExit):
        main(["issue9", "--seed", "3", "--arm", "a:", "--clean-only-arms", "b", "--work", "W", "--out", "O"])
    assert "--clean-only-arms b: no such --arm" in capsys.readouterr().err


def test_the_effect_groups_cover_issue_9s_six_effects_once():
    from benchmarks.eval_jsbsim_diagnose import EFFECTS

    names = [e for g in EFFECT_GROUPS for e in g]
    assert sorted(names) == sorted(EFFECTS) and len(set(names)) == len(names)


POOL_SCRIPT = r'''
import pathlib, sys
import numpy  # noqa: F401  (NumPy loaded before the fork, as the harness loads it in pool_eval's parent)
from threadpoolctl import threadpool_info, threadpool_limits
from benchmarks.pool_eval import _run_pool


def _blas_threads(job):
    """A pool job: the most threads any loaded BLAS would use in this worker (the pool's result tuple)."""
    n = max((lib["num_threads"] for lib in threadpool_info() if lib.get("user_api") == "blas"), default=0)
    return f"blas {job}", 0, 0.0, f"{n}\n", ""


blas = [lib["num_threads"] for lib in threadpool_info() if lib.get("user_api") == "blas"]
assert blas, "no BLAS loaded"
with threadpool_limits(limits=2, user_api="blas"):     # as on a 2-core box without tests/conftest.py's limit
    if max(lib["num_threads"] for lib in threadpool_info() if lib.get("user_api") == "blas") < 2:
        print("one-thread BLAS")
        sys.exit(0)
    print("failed", _run_pool(1, [(_blas_threads, [0, 1])], pathlib.Path(sys.argv[1]), lambda job: "blas.txt"))
'''


def test_a_pinned_worker_runs_one_blas_thread_though_numpy_loaded_before_the_fork(tmp_path):
    # NumPy (loaded in the parent long before) sized its BLAS from every core; a worker pinned to one core must
    # not keep that pool (16 BLAS threads on one core stalled a 16-core run). The pool runs in a fresh interpreter,
    # as pool_eval does: a fork of this pytest worker would copy its threads and its signal set-up.
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")]))}
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        env.pop(var, None)
    proc = subprocess.run([sys.executable, "-c", POOL_SCRIPT, str(tmp_path)], capture_output=True, text=True,
                          timeout=120, cwd=root, env=env)
    assert proc.returncode == 0, proc.stderr
    if proc.stdout.strip() == "one-thread BLAS":
        # a BLAS capped at one thread cannot give a worker more than one either: the stall this test
        # guards against cannot occur, and the test's premise (a two-thread parent) cannot be built
        pytest.skip("this BLAS runs one thread at most here")
    assert proc.stdout.split() == ["failed", "0"], proc.stdout
    assert (tmp_path / "blas.txt").read_text().split() == ["1", "1"]
