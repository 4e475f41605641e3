"""The learner in the helper process: the listening process only decodes, logs and queues.

A :class:`~gcs_sysid.live.learner.Learner` step decodes a window, runs the smoothers (the rate
smoother's two hold models compared by likelihood, the specific-force air-angle aiding), computes
the coefficients, updates the GP and refreshes the confidence map: seconds of Python that hold the
interpreter lock. In the listening process that lock is shared with the link receiver, whose
per-message handling then waits for it (measured: p99 4.8-5.6 ms at 2,000 msg/s,
``docs/benchmarks.md``). :class:`RemoteLearner` runs the whole learner in the spare worker process
of :mod:`gcs_sysid.parallel` instead; the listening process sends it the queued records in
batches and keeps a copy of what its console and report show (steps, rows learned, notes,
confidence, the top suggestion).

The learner in the worker is the same class fed the same records in the same order, and its
``behind`` test sees the same count as in one process: the records queued after the one being fed,
i.e. the records received so far (a counter this process's receiver keeps in a shared 8-byte
memory map, read there when a step is due) minus those fed. So a session
replayed from its ``raw.tlog`` (:func:`~gcs_sysid.live.learner.learn_from_tlog`, given the
session's ``coalesced_at_us``) ends with the same model. CAN samples decoded here travel with
each batch (:meth:`gcs_sysid.telemetry.can.CanListener.drain`, only what is new) and are
gathered there (:class:`~gcs_sysid.telemetry.can.CanSamples`), so each window merges the CAN data
received up to its last record, as before.

Without a worker (one CPU, ``GCS_SYSID_PARALLEL=0``, ``ListenOptions(parallel=False)``) the same
functions run in this process. If the worker dies mid-session its learner is gone: the next batch
raises :class:`~gcs_sysid.errors.SysidError` (the session notes "learning stopped"; ``raw.tlog``
keeps every packet, so the model can be learned again from it).
"""

from __future__ import annotations

import itertools
import mmap
import os
import struct
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SysidError

__all__ = ["RemoteLearner", "SuggestionText", "WARM"]

#: modules the worker imports while the session starts (the learner's stages)
WARM = ("gcs_sysid.live.learner", "gcs_sysid.telemetry.tlog_reader", "gcs_sysid.estimation", "gcs_sysid.aero",
        "gcs_sysid.gp", "gcs_sysid.envelope", "gcs_sysid.maneuvers", "gcs_sysid.pipeline")

_LEARNERS: dict = {}           # key -> _Held, in the process that runs the learner
_KEYS = itertools.count()


@dataclass(frozen=True)
class SuggestionText:
    """A maneuver suggestion as the listening process sees it (its text only).

    Attributes:
        reason: the suggestion's one-line reason (``Suggestion.reason``).
    """

    reason: str


# --- the side that runs the learner (the worker, or this process without one) ---------------------


def _rss_mib() -> float:
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def _status(learner) -> dict:
    model = learner.model
    rows = getattr(model, "rows", None) if model is not None else None
    return {"steps": learner.steps, "n_learned": learner.n_learned, "outputs": tuple(learner.outputs),
            "notes": list(learner.notes), "timings": dict(learner.timings),
            "control_sources": dict(learner.control_sources), "coalesced": learner.coalesced,
            "refreshes_deferred": learner.refreshes_deferred, "coalesced_at": list(learner.coalesced_at),
            "identifiable": dict(learner.identifiable), "confidence": learner.confidence(),
            "suggestions": [SuggestionText(str(s.reason)) for s in learner.suggestions[:5]],
            "has_model": model is not None, "rows_stored": len(rows) if rows is not None else 0,
            "air_roll": dict(learner.air_roll), "errors": dict(learner.errors),
            "lift_line": dict(learner.lift_line), "air_pitch": dict(learner.air_pitch), "pid": os.getpid(),
            "rss_mib": _rss_mib()}


class _Held:
    """A learner with what its process keeps beside it: the CAN samples, the received-records counter."""

    def __init__(self, learner, can, counter_path: str):
        self.learner, self.can, self.fed = learner, can, 0
        with open(counter_path, "rb") as f:
            self.counter = mmap.mmap(f.fileno(), 8, access=mmap.ACCESS_READ)

    def received(self) -> int:
        return struct.unpack_from("<q", self.counter, 0)[0]

    def close(self) -> None:
        self.counter.close()


def open_learner(key: str, airframe, options, can_keep_s: float | None, counter_path: str) -> dict:
    """Create the learner ``key`` here (the worker's job; imports JAX, sets x64). Returns its status.

    Args:
        key: the learner's name.
        airframe, options: as for :class:`~gcs_sysid.live.learner.Learner`.
        can_keep_s: seconds of CAN samples kept (None: no CAN bus).
        counter_path: an 8-byte file the listening process keeps the count of received records in.
    """
    from ..telemetry.can import CanSamples
    from .learner import Learner

    learner = Learner(airframe, options)
    can = None
    if can_keep_s is not None:
        can = CanSamples(keep_s=can_keep_s)
        learner.can_source = can.streams
    _LEARNERS[key] = _Held(learner, can, counter_path)
    return _status(learner)


def _get(key: str):
    try:
        return _LEARNERS[key]
    except KeyError:
        raise SysidError("the learner's process stopped; its state is lost (raw.tlog keeps every packet: "
                         "gcs_sysid.live.learn_from_tlog learns the model again from it)") from None


def feed_batch(key: str, stamps: np.ndarray, lengths: np.ndarray, blob: bytes, behind_records: int,
               can_new: list) -> dict:
    """Feed one batch of records to the learner ``key`` (the worker's job). Returns its status.

    Args:
        key: the learner (:func:`open_learner`).
        stamps: record stamps, us, shape (N,), int64.
        lengths: packet lengths, bytes, shape (N,).
        blob: the N packets, concatenated.
        behind_records: the learner is behind while more records than this wait after the one fed (the
            records received so far, from the shared counter, minus those fed).
        can_new: CAN samples decoded since the last batch, ``(stream, field, t s, value)``.

    Raises:
        SysidError: no learner ``key`` here (the worker that held it stopped).
    """
    held = _get(key)
    learner = held.learner
    if held.can is not None and can_new:
        held.can.add(can_new)
    learner.behind = lambda: held.received() - held.fed > behind_records
    ends = np.cumsum(lengths)
    start = 0
    for i in range(len(stamps)):
        held.fed += 1
        end = int(ends[i])
        learner.feed(int(stamps[i]), blob[start:end])
        start = end
    return _status(learner)


def finish_learner(key: str, can_new: list):
    """Finish the learner ``key`` (its last window) and hand it over, the learner's own process forgetting it.

    Returns:
        The :class:`~gcs_sysid.live.learner.Learner` (its callables removed), with the model.
    """
    held = _get(key)
    learner = held.learner
    if held.can is not None and can_new:
        held.can.add(can_new)
    learner.behind = None
    learner.finish()
    learner.can_source = None
    del _LEARNERS[key]
    held.close()
    return learner


def save_model(key: str, path: str) -> bool:
    """Save the model of the learner ``key`` to ``path`` now. Returns False when it has no model yet."""
    learner = _get(key).learner
    if learner.model is None:
        return False
    learner.model.save(Path(path))
    return True


def drop_learner(key: str) -> None:
    """Forget the learner ``key`` (a session that stopped learning)."""
    held = _LEARNERS.pop(key, None)
    if held is not None:
        held.close()


# --- the listening process's side -------------------------------------------------------------------------


class RemoteLearner:
    """A :class:`~gcs_sysid.live.learner.Learner` run by a :class:`~gcs_sysid.parallel.Helper`'s worker.

    Holds a copy of the learner's status for the console and the report (the attributes the session
    reads from a ``Learner``: ``steps``, ``n_learned``, ``outputs``, ``notes``, ``timings``,
    ``control_sources``, ``coalesced``, ``refreshes_deferred``, ``coalesced_at``, ``identifiable``,
    ``suggestions``, ``air_roll``, :meth:`confidence`); ``model`` is None until :meth:`finish` brings the learner back.

    Args:
        airframe: the airframe.
        options: :class:`~gcs_sysid.live.learner.LearnOptions`.
        helper: the worker (:class:`~gcs_sysid.parallel.Helper`; without a worker its jobs run here).
        can_keep_s: seconds of CAN samples the learner keeps (None: no CAN bus).
        behind_records: records waiting beyond which the learner counts as behind.

    Raises:
        SysidError: the learner could not be created (its own error, re-raised).
    """

    def __init__(self, airframe, options, helper, can_keep_s: float | None = None, behind_records: int = 2000):
        self.airframe, self.options, self.helper = airframe, options, helper
        self.behind_records = behind_records
        self.key = f"{os.getpid()}-{id(self)}-{next(_KEYS)}"
        self.model = None
        self.in_flight = 0
        self.worker_pid: int | None = None
        self.rss_mib = float("nan")
        self.has_model = False
        self.rows_stored = 0
        self.steps = self.n_learned = self.coalesced = self.refreshes_deferred = 0
        self.outputs: tuple[str, ...] = ()
        self.notes: list[str] = []
        self.timings: dict = {}
        self.control_sources: dict = {}
        self.coalesced_at: list = []
        self.identifiable: dict = {}
        self.suggestions: list = []
        self.air_roll: dict = {}
        self.errors: dict = {}
        self.lift_line: dict = {}
        self.air_pitch: dict = {}
        self._confidence: dict = {}
        self._extra_notes: list[str] = []
        self.queued = 0
        fd, self._counter_path = tempfile.mkstemp(prefix="gcs-sysid-received-")
        try:
            os.write(fd, bytes(8))
            self._counter = mmap.mmap(fd, 8)
        finally:
            os.close(fd)
        try:
            self._update(helper.submit("gcs_sysid.live.remote:open_learner", self.key, airframe, options,
                                       can_keep_s, self._counter_path).result())
        except BaseException:
            self.close()
            raise

    def record_queued(self) -> None:
        """One more record queued for the learner (the receiver thread calls this; the learner's ``behind``)."""
        self.queued += 1
        struct.pack_into("<q", self._counter, 0, self.queued)

    def close(self) -> None:
        """Remove the shared counter (after :meth:`finish` or :meth:`drop`)."""
        try:
            self._counter.close()
        except (BufferError, ValueError):
            pass
        try:
            os.unlink(self._counter_path)
        except OSError:
            pass

    def _update(self, st: dict) -> None:
        for k in ("steps", "n_learned", "outputs", "timings", "control_sources", "coalesced", "refreshes_deferred",
                  "coalesced_at", "identifiable", "suggestions", "has_model", "rows_stored", "rss_mib", "air_roll",
                  "errors", "lift_line", "air_pitch"):
            setattr(self, k, st[k])
        self.notes = st["notes"] + self._extra_notes
        self._confidence = st["confidence"]
        self.worker_pid = st["pid"]

    def feed_batch(self, records: list[tuple[int, bytes]], can_new: list = ()) -> None:
        """Send ``records`` (``(stamp_us, packet)``, arrival order) to the learner and wait for it.

        Args:
            records: the batch.
            can_new: CAN samples decoded since the last batch (``CanListener.drain``).

        Raises:
            SysidError: the learner's state is lost (its worker stopped); any error of a stage.
        """
        stamps = np.fromiter((s for s, _ in records), np.int64, len(records))
        lengths = np.fromiter((len(p) for _, p in records), np.int64, len(records))
        blob = b"".join(p for _, p in records)
        self.in_flight = len(records)
        try:
            st = self.helper.submit("gcs_sysid.live.remote:feed_batch", self.key, stamps, lengths, blob,
                                    self.behind_records, list(can_new)).result()
        finally:
            self.in_flight = 0
        self._update(st)

    def note(self, text: str) -> None:
        """Add a note of this side (e.g. "learning stopped")."""
        self._extra_notes.append(text)
        self.notes.append(text)

    def confidence(self) -> dict[str, float]:
        """Coefficient -> confidence score in [0, 1] from the latest map (empty before the first)."""
        return dict(self._confidence)

    def save(self, path: str | Path) -> bool:
        """Save the current model to ``path`` (in the learner's process). False without a model."""
        return bool(self.helper.submit("gcs_sysid.live.remote:save_model", self.key, str(path)).result())

    def finish(self, can_new: list = ()):
        """Learn the last window and bring the learner back here.

        Returns:
            The :class:`~gcs_sysid.live.learner.Learner`, with its model and the notes of this side.
        """
        try:
            learner = self.helper.submit("gcs_sysid.live.remote:finish_learner", self.key, list(can_new)).result()
        finally:
            self.close()
        learner.notes.extend(self._extra_notes)
        return learner

    def drop(self) -> None:
        """Forget the learner in its process (no model wanted)."""
        try:
            self.helper.submit("gcs_sysid.live.remote:drop_learner", self.key).result()
        except Exception:
            pass
        self.close()
