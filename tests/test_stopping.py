"""gcs_sysid.stopping: a signal during an import ends the process cleanly, without raising inside it.

An exception raised into Python code that an extension module's initialisation calls (jaxlib's
``xla_extension``, imported while a replay's worker decodes) crashed the replay with SIGSEGV/SIGABRT
instead of 143. The watcher now leaves a main thread that is inside an import alone. This test puts the
main thread in a slow pure-Python import (a busy loop at module level, which would take the
asynchronous exception at once) and checks that nothing is raised inside it and that the process still
ends with 143 and its one line.
"""

import signal
import subprocess
import sys
import time

SCRIPT = r'''
import pathlib, sys, time
from gcs_sysid import stopping
tmp = pathlib.Path(sys.argv[1])
(tmp / "slowmod.py").write_text(
    "import pathlib, sys, time\n"
    "try:\n"
    "    t_end = time.monotonic() + 20.0\n"
    "    while time.monotonic() < t_end:\n"
    "        pass\n"
    "except BaseException as e:\n"
    "    pathlib.Path(sys.argv[1], 'raised-inside-import').write_text(type(e).__name__)\n"
    "    raise\n")
sys.path.insert(0, str(tmp))
stopping.install()
print("importing", flush=True)
try:
    import slowmod
except stopping.Stopped:
    stopping.park()
'''


def test_signal_inside_an_import_is_not_raised_into_it(tmp_path):
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT, str(tmp_path)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "importing"
    time.sleep(0.3)   # well inside the 20-s import
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=30)
    took = time.monotonic() - t0
    assert not (tmp_path / "raised-inside-import").exists(), "Stopped was raised inside the import"
    assert proc.returncode == 128 + signal.SIGTERM, (proc.returncode, stderr)
    assert stderr.strip() == "gcs-sysid: stopped by SIGTERM", stderr
    assert took < 3.0, took


FORK_SCRIPT = r'''
import multiprocessing as mp, os, pathlib, signal, sys, time
from gcs_sysid import stopping
tmp = pathlib.Path(sys.argv[1])
stopping.install()
stopping.register(lambda: (tmp / "cleaned").write_text(str(os.getpid())) and None)
ctx = mp.get_context("fork")
child = ctx.Process(target=time.sleep, args=(30,))
child.start()
time.sleep(0.3)
child.terminate()            # SIGTERM, as Pool.terminate sends its workers
child.join(10)
time.sleep(0.5)              # a byte in the shared wakeup pipe would have stopped this process by now
print("parent alive", child.exitcode, flush=True)
'''


def test_a_forked_child_does_not_share_the_parents_stop(tmp_path):
    # A forked child inherited the wakeup pipe: the SIGTERM a multiprocessing pool sends its workers at the end
    # reached the parent's watcher and ended the parent (a pytest worker that had run a command in-process and
    # then a pool: CI's run of 2026-11-25 lost the worker and hung). The child also ran the parent's clean-ups.
    proc = subprocess.run([sys.executable, "-c", FORK_SCRIPT, str(tmp_path)], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, (proc.returncode, proc.stderr)
    assert proc.stdout.split() == ["parent", "alive", str(-signal.SIGTERM)], proc.stdout   # default SIGTERM
    assert "stopped by" not in proc.stderr, proc.stderr
    assert not (tmp_path / "cleaned").exists(), "the child ran the parent's clean-up"


UNINSTALL_SCRIPT = r'''
import os, signal, threading
from gcs_sysid import stopping
# Python's own SIGINT handler, whatever this process inherited: a shell starts background jobs with SIGINT
# ignored, and Python then keeps SIG_IGN (CI run from `.ci/run &`, 2026-11-26: no KeyboardInterrupt below)
signal.signal(signal.SIGINT, signal.default_int_handler)
before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
stopping.install()
stopping.register(lambda: "never")
assert any(t.name == "gcs-sysid-signals" for t in threading.enumerate())
stopping.uninstall()
stopping.uninstall()                      # a no-op the second time
assert not stopping.installed()
assert all(signal.getsignal(s) is h for s, h in before.items())
assert signal.set_wakeup_fd(-1) == -1     # no wakeup pipe left
assert not any(t.name == "gcs-sysid-signals" for t in threading.enumerate())
try:
    os.kill(os.getpid(), signal.SIGINT)   # Python's own handling again
    for _ in range(100):
        threading.Event().wait(0.01)
except KeyboardInterrupt:
    print("KeyboardInterrupt", flush=True)
stopping.install()                        # and it can be installed again
assert stopping.installed()
'''


def test_uninstall_gives_back_what_install_took():
    # The test suite runs CLI commands in its worker processes (tests/conftest.py uninstalls after each test):
    # a watcher left behind ended the worker at a later test's signal (nineteenth session) or fork (2026-11-26).
    proc = subprocess.run([sys.executable, "-c", UNINSTALL_SCRIPT], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, (proc.returncode, proc.stderr)
    assert proc.stdout.split() == ["KeyboardInterrupt"], proc.stdout
    assert "stopped by" not in proc.stderr and "interrupted" not in proc.stderr, proc.stderr
