"""A signal ends a live session at its next tick, never as an exception inside the schedule.

`KeyboardInterrupt` raised wherever the main thread is can land between a lock's acquisition and the
`with` block that releases it (a `queue.Queue` call in `LiveSession.tick`), and the clean end then
waits on that lock for ever (`listen` once outlived its SIGINT by 30 s under CI's load). Here the
signal is sent from inside a tick that keeps running Python for a while: with the signal raising,
the exception lands inside the tick and the test fails; with `stop_on_signals` the tick runs to its
end and the session closes as after a Ctrl-C, with its report.

The session runs in its own interpreter, as `listen` does: the test process's signal state is not
`listen`'s (an in-process CLI test installs `gcs_sysid.stopping`, whose wakeup-fd watcher ends the
process on any SIGINT whatever Python handler is set).
"""

import json
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, free_port  # noqa: E402

SESSION = r"""
import json, os, signal, sys, time
from gcs_sysid.live.session import ListenOptions, LiveSession, run_listen

airframe, out, port = sys.argv[1], sys.argv[2], int(sys.argv[3])
calls, raised_inside = [], []
tick = LiveSession.tick


def signalling_tick(self):
    calls.append(time.monotonic())
    try:
        if len(calls) == 2:
            os.kill(os.getpid(), signal.SIGINT)
            end = time.monotonic() + 0.3
            while time.monotonic() < end:   # Python bytecode: a pending signal handler runs in here
                pass
        tick(self)
    except BaseException as exc:
        raised_inside.append(type(exc).__name__)
        raise


LiveSession.tick = signalling_tick
before = signal.getsignal(signal.SIGINT)
opts = ListenOptions(connection=f"udpin:127.0.0.1:{port}", learn=None, component=False, request=False,
                     console=False, duration_s=20.0)
t0 = time.monotonic()
snap = run_listen(airframe, out, opts)
print(json.dumps({"raised_inside": raised_inside, "interrupted": snap["interrupted"], "ticks": len(calls),
                  "seconds": time.monotonic() - t0, "handler_restored": signal.getsignal(signal.SIGINT) is before}))
"""


def test_sigint_inside_a_tick_ends_the_session_after_the_tick(tmp_path):
    out = tmp_path / "s"
    r = subprocess.run([sys.executable, "-c", SESSION, str(AIRFRAME), str(out), str(free_port())],
                       capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-3000:]
    got = json.loads(r.stdout.strip().splitlines()[-1])
    assert got["raised_inside"] == []
    assert got["interrupted"] is True and got["seconds"] < 10.0
    assert got["handler_restored"] is True   # the caller's handler is back after the session
    assert 3 <= got["ticks"] <= 4            # one more tick (in close) after the signalled one, none further
    assert json.loads((out / "session.json").read_text())["interrupted"] is True
    assert "Ctrl-C" in (out / "report.md").read_text()
