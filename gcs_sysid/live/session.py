"""A live session: link -> raw log -> incremental learner, with the component speaking back.

Threads: the link receiver (:class:`gcs_sysid.telemetry.live.LinkReceiver`) writes every packet to
``raw.tlog`` first and queues it; the learner thread feeds the queue, in arrival order, to the
:class:`~gcs_sysid.live.learner.Learner` (so a slow GP step never blocks the link: the queue grows
and is drained after); the calling thread runs the schedule (requests, heartbeat, status texts,
console) every :data:`TICK_S` until the duration ends or Ctrl-C, then writes the report.

The learner itself runs in the spare worker process (:mod:`gcs_sysid.parallel`) when there is one
(:class:`~gcs_sysid.live.remote.RemoteLearner`): the learner thread here then only sends it the
queued records in batches, so the estimation and the GP do not hold this process's interpreter
lock against the receiver. ``session.learner`` is the learner's copy of its status while the session
runs and the :class:`~gcs_sysid.live.learner.Learner` itself (with its model) after :meth:`LiveSession.close`.
"""

from __future__ import annotations

import queue
import signal
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ..errors import InputError
from ..component import targets
from ..telemetry.live import sample_of
from .requests import rates_from_params
from .edge import LiveEdge
from .learner import LearnOptions, Learner

__all__ = ["ListenOptions", "LiveSession", "run_listen", "stop_on_signals", "TICK_S"]

TICK_S = 0.25
_EDGE = {"RAW_IMU", "SCALED_IMU", "HIGHRES_IMU", "ATTITUDE", "VFR_HUD", "AOA_SSA"}


BEHIND_RECORDS = 2000
"""Records waiting for the learner beyond which it counts as behind (1 s at 2,000 msg/s)."""

BATCH_S = 0.25
"""Seconds the learner thread lets records gather before it sends a batch to the learner's process."""

@dataclass(frozen=True)
class ListenOptions:
    """Options of :func:`run_listen`.

    Attributes:
        connection: pymavlink connection string; baud: serial baud rate.
        learn: the learner's schedule (:class:`LearnOptions`); None: log and monitor only.
        request: ask the vehicle for the sysid rates.
        rates: message -> asked rate, Hz (None: the component's ``SID_*_HZ`` parameters).
        component: run the MAVLink component (heartbeat, status texts, confidence, parameters).
        system_id, component_id: the component's ids (None system: the vehicle's, once seen).
        duration_s: stop after this wall time (None: until Ctrl-C).
        silence_s: a gap longer than this is reported as a silence.
        console: show the rich live console.
        use_mavsdk: serve parameters with MAVSDK (else pymavlink's PARAM protocol).
        can: ``INTERFACE:CHANNEL`` of a CAN bus to log (``DIR/can.log``) and decode (DroneCAN actuator
            status and air data, :mod:`gcs_sysid.telemetry.can`) beside the MAVLink link.
        parallel: run the learner in a worker process (None: when more than one CPU is usable and
            ``GCS_SYSID_PARALLEL`` is not 0, :func:`gcs_sysid.parallel.default_enabled`).
    """

    connection: str
    baud: int = 57600
    learn: LearnOptions | None = field(default_factory=LearnOptions)
    request: bool = True
    rates: dict[str, float] | None = None
    component: bool = True
    system_id: int | None = None
    component_id: int = 191
    duration_s: float | None = None
    silence_s: float = 30.0
    console: bool = True
    use_mavsdk: bool = True
    can: str | None = None
    parallel: bool | None = None


class LiveSession:
    """One listening session (see the module docstring). Use :func:`run_listen` from code.

    Args:
        airframe: the loaded airframe.
        out_dir: output directory (``raw.tlog``, ``session.json``, ``report.md``, ``model/``).
        options: :class:`ListenOptions`.
        link: an open link (default: opened from ``options.connection``).
    """

    def __init__(self, airframe, out_dir: str | Path, options: ListenOptions, link=None):
        from pymavlink.dialects.v20 import ardupilotmega as mavlink

        from ..component import DEFAULT_PARAMS
        from ..telemetry.live import LinkReceiver, RawLog, open_link
        from .requests import RateRequester, rates_from_params

        self.options = options
        self.out = Path(out_dir)
        self.link = link if link is not None else open_link(options.connection, options.baud)   # fail fast
        self.helper = None
        self.can = None
        try:
            # heavy imports (JAX, SciPy; in the worker when there is one) before raw.tlog exists: once it does,
            # Ctrl-C is handled (run_listen); packets arriving meanwhile wait in the socket's buffer
            self.out.mkdir(parents=True, exist_ok=True)
            keep = max(2.0 * options.learn.window_s if options.learn is not None else 60.0, 60.0)
            if options.can:
                from ..telemetry.can import CanListener, open_bus

                self.can = CanListener(open_bus(options.can), self.out / "can.log", keep_s=keep)
            self.learner = self._start_learner(airframe, options, keep) if options.learn is not None else None
            self._remote = self.learner is not None and not isinstance(self.learner, Learner)
            self.edge = LiveEdge()
            self.raw = RawLog(self.out / "raw.tlog")
            self._q: queue.Queue = queue.Queue()
            self._msgs: queue.Queue = queue.Queue()
            self.receiver = LinkReceiver(self.link, self.raw, [self._on_packet], silence_s=options.silence_s)
            self.params = {k: v for k, (v, _) in DEFAULT_PARAMS.items()}
            mav = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
            self.requester = RateRequester(mav, self.receiver.send, options.rates or rates_from_params(self.params)) \
                if options.request else None
            self.component = None
            self.events: list[str] = []
            self.texts: list[str] = []
            self._told_suggestion = ""
            self._told_events = 0
            self._learner_error: str | None = None
            self._stop = threading.Event()
            self._signalled: int | None = None   # set by the handler of run_listen's stop_on_signals
            self._closed: dict | None = None
            self._learn_thread = threading.Thread(target=self._learn_loop, name="gcs-sysid-learn", daemon=True)
            if isinstance(self.learner, Learner):   # behind: coalesce steps, defer the map (Learner.behind)
                self.learner.behind = lambda: self._q.qsize() > BEHIND_RECORDS
        except BaseException:   # a bad CAN bus, Ctrl-C during the imports: give the link back
            if getattr(self, "learner", None) is not None and not isinstance(self.learner, Learner):
                self.learner.close()
            if self.helper is not None:
                self.helper.close(wait=False)
            if self.can is not None:
                self.can.bus.shutdown()
            if link is None:
                self.link.close()
            raise
        self.started = time.time()

    def _start_learner(self, airframe, options: ListenOptions, can_keep_s: float):
        """The learner: in the worker process when there is one (:class:`RemoteLearner`), else here."""
        from ..parallel import Helper, default_enabled

        parallel = default_enabled() if options.parallel is None else options.parallel
        if parallel:
            from .remote import WARM, RemoteLearner

            # SIGTERM to the process group ends a listen cleanly, with the learner's model: the worker holds on
            self.helper = Helper(enabled=True, warm=WARM, hold_sigterm=True)
            if self.helper.parallel:
                return RemoteLearner(airframe, options.learn, self.helper,
                                     can_keep_s if self.can is not None else None, BEHIND_RECORDS)
            self.helper = None   # the worker could not start: learn here
        learner = Learner(airframe, options.learn)
        if self.can is not None:   # measured surface positions and airspeed into each window
            learner.can_source = self.can.streams
        return learner

    # --- threads ------------------------------------------------------------------------------

    def _on_packet(self, stamp_us: int, buf: bytes, msg) -> None:   # receiver thread: return fast
        if self.learner is not None:
            self._q.put((stamp_us, buf))
            if self._remote:
                self.learner.record_queued()
        name = msg.get_type()
        if name in _EDGE and (self.receiver.stats.vehicle is None
                              or (msg.get_srcSystem(), msg.get_srcComponent()) == self.receiver.stats.vehicle):
            t = getattr(msg, "time_boot_ms", None)
            t = t * 1e-3 if t is not None else (msg.time_usec * 1e-6 if hasattr(msg, "time_usec") else None)
            self.edge.feed(name, sample_of(msg), t)
        if msg.get_type() in ("COMMAND_ACK", "PARAM_REQUEST_LIST", "PARAM_REQUEST_READ", "PARAM_SET",
                              "HEARTBEAT", "PARAM_EXT_REQUEST_LIST", "PARAM_EXT_REQUEST_READ", "PARAM_EXT_SET"):
            self._msgs.put(msg)

    def _learn_loop(self) -> None:
        if not isinstance(self.learner, Learner):
            return self._send_loop()
        while True:
            item = self._q.get()
            if item is None:
                return
            try:
                self.learner.feed(*item)
            except Exception as exc:   # a bug in a stage must not stop the link or lose the log
                self._learner_stopped(exc)
                return

    def _send_loop(self) -> None:
        """The learner thread with the learner in the worker: send what is queued in batches, in order."""
        learner, q = self.learner, self._q
        end = False
        while not end:
            item = q.get()
            if item is None:
                return
            time.sleep(BATCH_S)   # let a batch gather (the learner's schedule counts stamps, not batches)
            batch = [item]
            for _ in range(q.qsize()):
                item = q.get_nowait()
                if item is None:
                    end = True
                    break
                batch.append(item)
            try:
                learner.feed_batch(batch, self.can.drain() if self.can is not None else ())
            except Exception as exc:   # a bug in a stage, the worker gone: the link and the log go on
                self._learner_stopped(exc)
                return

    def _learner_stopped(self, exc: Exception) -> None:
        self._learner_error = f"{type(exc).__name__}: {exc}"
        note = f"learning stopped: {self._learner_error}"
        if isinstance(self.learner, Learner):
            self.learner.notes.append(note)
        else:
            self.learner.note(note)
        while self._q.get() is not None:
            pass

    # --- schedule -----------------------------------------------------------------------------

    def _ensure_component(self) -> None:
        from ..component import SysidComponent

        if self.component is not None or not self.options.component:
            return
        vehicle = self.receiver.stats.vehicle
        sysid = self.options.system_id if self.options.system_id is not None else (vehicle[0] if vehicle else None)
        if sysid is None:
            return
        self.component = SysidComponent(self.receiver.send, sysid, self.options.component_id, self.params,
                                        use_mavsdk=self.options.use_mavsdk)

    def tick(self) -> None:
        """One round of the schedule (requests, component, texts); called every :data:`TICK_S`."""
        st = self.receiver.stats
        now = time.time()
        if self.requester is not None and self.requester.target is None and st.vehicle is not None:
            self.requester.target = st.vehicle
        self._ensure_component()
        while True:
            try:
                msg = self._msgs.get_nowait()
            except queue.Empty:
                break
            if self.requester is not None:
                self.requester.handle(msg)
            if self.component is not None:
                self.component.handle(msg)
        if self.requester is not None:
            self.requester.tick(lambda: st.rates(now))
        for _, text in st.events[self._told_events:]:
            self.events.append(text)
            self._say(text, 4 if ("reboot" in text or "silent" in text) else 6)
            if "reboot" in text and self.requester is not None:
                self.requester.restart()   # a rebooted vehicle forgot the rates it was asked for
        self._told_events = len(st.events)
        if self.requester is not None:
            for line in self.requester.log:
                self.events.append(line)
            self.requester.log.clear()
        if self.component is not None:
            self.component.tick()
            self._params_changed(dict(self.params), self.component.refresh_params())
        learner = self.learner
        if learner is not None and learner.suggestions:
            top = learner.suggestions[0].reason
            if top != self._told_suggestion:
                self._told_suggestion = top
                self._say("sysid: " + top, 6)
                wanted = targets(self.params["SID_TARGETS"])
                conf = {c: v for c, v in learner.confidence().items() if c in wanted}
                if self.component is not None:
                    self.component.confidence(conf)
                low = [c for c, v in conf.items() if v < self.params["SID_CONF_MIN"]]
                if low:
                    self._say("sysid: low confidence " + ", ".join(low), 4)

    def _params_changed(self, before: dict[str, float], now: dict[str, float]) -> None:
        """A ground station set parameters: note it; new rates are asked of the vehicle again."""
        changed = {k: v for k, v in now.items() if before.get(k) != v}
        if not changed:
            return
        self.params.update(changed)
        self.events.append("parameters set: " + ", ".join(f"{k}={v:g}" for k, v in changed.items()))
        if self.requester is not None and any(k.endswith("_HZ") for k in changed):
            self.requester.rates = rates_from_params(now)
            self.requester.restart()

    def _say(self, text: str, severity: int) -> None:
        self.texts.append(text)
        if self.component is not None:
            self.component.statustext(text, severity)

    def snapshot(self) -> dict:
        """What the console and the report show (JSON-able)."""
        st = self.receiver.stats
        now = time.time()
        learner = self.learner
        req = self.requester
        snap = {
            "connection": self.options.connection,
            "link": ("no data yet" if not st.last_s else
                     "silent" if now - st.last_s > min(self.options.silence_s, 3.0) else "receiving"),
            "vehicle": list(st.vehicle) if st.vehicle else None,
            "elapsed_s": now - self.started,
            "packets": st.records, "raw_log": str(self.raw.path), "raw_records": self.raw.records,
            "bad_data": st.bad_data, "seq_lost": st.seq_lost,
            "rates": {k: round(v, 2) for k, v in sorted(st.rates(now).items())},
            "mean_rates": {k: round(v, 2) for k, v in st.mean_rates().items()},
            "asked": dict(req.rates) if req else {},
            "requests": dict(req.result) if req else {},
            "shortfalls": {k: list(v) for k, v in req.shortfalls.items()} if req else {},
            "costs": list(req.costs) if req else [],
            "edge": {k: round(v, 4) for k, v in self.edge.values.items()},
            "can": self.can.summary() if self.can is not None else None,
            "events": list(self.events), "texts_sent": list(self.texts),
            "params": dict(self.params),
            "param_backend": self.component.param_backend if self.component else None,
            "component_sent": dict(self.component.sent) if self.component else {},
        }
        if learner is not None:
            snap.update({
                "samples_learned": learner.n_learned, "steps": learner.steps,
                "queue": self._q.qsize() + getattr(learner, "in_flight", 0),
                "outputs": list(learner.outputs), "confidence": learner.confidence(),
                "identifiable": {k: list(v) for k, v in learner.identifiable.items()},
                "top_suggestion": learner.suggestions[0].reason if learner.suggestions else None,
                "learner_notes": list(learner.notes), "timings": dict(learner.timings),
                "control_sources": dict(learner.control_sources), "steps_coalesced": learner.coalesced,
                "map_refreshes_deferred": learner.refreshes_deferred,
                "coalesced_at_us": list(learner.coalesced_at),
                "air_roll": dict(getattr(learner, "air_roll", {})),
                "stated_errors": dict(getattr(learner, "errors", {})),
                "lift_line": dict(getattr(learner, "lift_line", {})),
                "air_pitch": dict(getattr(learner, "air_pitch", {})),
                "learner_in": "worker process" if self._remote else "this process",
            })
        return snap

    # --- run ----------------------------------------------------------------------------------

    def run(self, on_tick: Callable[[dict], None] | None = None) -> dict:
        """Listen until the duration ends or Ctrl-C; then finish learning and write the report.

        Returns:
            The final :meth:`snapshot` (also written to ``session.json``).
        """
        self.receiver.start()
        if self.can is not None:
            self.can.start()
        self.start_learning()
        interrupted = False
        try:
            while not self._stop.is_set() and self._signalled is None and (self.options.duration_s is None
                                               or time.time() - self.started < self.options.duration_s):
                time.sleep(TICK_S)
                self.tick()
                if on_tick is not None:
                    on_tick(self.snapshot())
        except KeyboardInterrupt:   # a host without stop_on_signals
            interrupted = True
        except Exception as exc:   # a bug in the schedule: still stop cleanly and write the report
            self.events.append(f"session stopped by an internal error: {type(exc).__name__}: {exc}")
            self.close(False)
            raise
        return self.close(interrupted or self._signalled is not None)

    def start_learning(self) -> None:
        """Start the learner thread (once; :meth:`run` does it, a host that feeds packets calls it)."""
        if self.learner is not None and not self._learn_thread.is_alive() and self._learn_thread.ident is None:
            self._learn_thread.start()

    def stop(self) -> None:
        """Ask :meth:`run` to end (from another thread) as at the end of the duration."""
        self._stop.set()

    def close(self, interrupted: bool = False) -> dict:
        """Stop the link, drain the learner (finishing the last window), save the model and the report.

        Idempotent: a second call returns the first one's snapshot.
        """
        if self._closed is not None:
            return self._closed
        self._closed = {"interrupted": interrupted}
        self.receiver.stop()
        if self.can is not None:
            self.can.stop()
        try:
            self.tick()
        except Exception:
            pass
        if self.learner is not None and self._learn_thread.is_alive():
            self._q.put(None)
            self._learn_thread.join()
            if self._learner_error is None:
                if isinstance(self.learner, Learner):
                    self.learner.finish()
                else:   # the learner comes back from its process, with its model
                    try:
                        self.learner = self.learner.finish(self.can.drain() if self.can is not None else ())
                    except Exception as exc:
                        self.learner.note(f"learning stopped: {type(exc).__name__}: {exc}")
        if self._remote and not isinstance(self.learner, Learner):
            self.learner.close()   # not finished (it stopped, or never started): its shared counter goes
        if self.helper is not None:
            self.helper.close(wait=False)
        if self.component is not None:
            self.component.close()
        self.link.close()
        self.raw.close()
        snap = self.snapshot()
        snap["interrupted"] = interrupted
        if self.learner is not None and self.learner.model is not None:
            self.learner.model.save(self.out / "model")
            snap["model"] = str(self.out / "model")
        from .report import write_session_report

        write_session_report(snap, self.out)
        self._closed = snap
        return snap


@contextmanager
def stop_on_signals(session: LiveSession, signals=(signal.SIGINT, signal.SIGTERM)):
    """While the block runs, SIGINT and SIGTERM end ``session`` at its next tick instead of raising.

    Python raises ``KeyboardInterrupt`` wherever the main thread happens to be when the signal lands,
    including between a lock's acquisition and the ``with`` block that would release it (a
    ``queue.Queue`` call in :meth:`LiveSession.tick`): the session's clean end then waits on that lock
    for ever. Here the handler only records the signal; :meth:`LiveSession.run` reads it at the top
    of its loop (within :data:`TICK_S`) and closes as after a Ctrl-C. A second signal before the
    session has closed raises ``KeyboardInterrupt`` as before (the user insists: the report is given up,
    ``raw.tlog`` keeps what was received). Off the main thread (an embedding host) nothing is installed.

    Source: the Python library reference, ``signal``, "Note on signal handlers and exceptions".
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        if session._signalled is not None:
            raise KeyboardInterrupt
        session._signalled = signum

    previous = {s: signal.signal(s, handler) for s in signals}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def run_listen(airframe_path: str | Path, out_dir: str | Path, options: ListenOptions) -> dict:
    """Listen on ``options.connection`` (see :class:`ListenOptions`) with the rich console if asked.

    Raises:
        InputError: bad airframe, link or options.
    """
    from ..airframe import load_airframe

    airframe = load_airframe(airframe_path)
    if options.duration_s is not None and options.duration_s <= 0:
        raise InputError(f"--duration {options.duration_s}: must be > 0 s")
    session = LiveSession(airframe, out_dir, options)
    try:   # Ctrl-C at any moment from here on ends the session cleanly, with its report
        with stop_on_signals(session):
            if not options.console:
                return session.run()
            from .console import LiveConsole

            with LiveConsole() as console:
                return session.run(on_tick=console.update)
    except KeyboardInterrupt:
        if session._closed is not None:   # a second signal during the close: the report is given up
            raise
        return session.close(interrupted=True)
