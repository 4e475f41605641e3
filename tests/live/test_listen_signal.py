"""A signal ends a live session at its next tick, never as an exception inside the schedule.

`KeyboardInterrupt` raised wherever the main thread is can land between a lock's acquisition and the
`with` block that releases it (a `queue.Queue` call in `LiveSession.tick`), and the clean end then
waits on that lock for ever (`listen` once outlived its SIGINT by 30 s under CI's load). Here the
signal is sent from inside a tick that keeps running Python for a while: with the signal raising,
the exception lands inside the tick and the test fails; with `stop_on_signals` the tick runs to its
end and the session closes as after a Ctrl-C, with its report.
"""

import json
import os
import signal
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, free_port  # noqa: E402

from gcs_sysid.live.session import ListenOptions, LiveSession, run_listen  # noqa: E402


def _busy(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:   # Python bytecode: a pending signal handler runs in here
        pass


def test_sigint_inside_a_tick_ends_the_session_after_the_tick(tmp_path, monkeypatch):
    calls, raised_inside = [], []
    tick = LiveSession.tick

    def signalling_tick(self):
        calls.append(time.monotonic())
        try:
            if len(calls) == 2:
                os.kill(os.getpid(), signal.SIGINT)
                _busy(0.3)
            tick(self)
        except BaseException as exc:
            raised_inside.append(type(exc).__name__)
            raise

    monkeypatch.setattr(LiveSession, "tick", signalling_tick)
    before = signal.getsignal(signal.SIGINT)
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{free_port()}", learn=None, component=False,
                         request=False, console=False, duration_s=20.0)
    t0 = time.monotonic()
    snap = run_listen(AIRFRAME, tmp_path / "s", opts)
    assert raised_inside == []
    assert snap["interrupted"] is True and time.monotonic() - t0 < 10.0
    assert json.loads((tmp_path / "s" / "session.json").read_text())["interrupted"] is True
    assert "Ctrl-C" in (tmp_path / "s" / "report.md").read_text()
    assert signal.getsignal(signal.SIGINT) is before   # the handler is the caller's again
    # one more tick (in close) after the signalled one, none further
    assert 3 <= len(calls) <= 4
