"""Live sessions: listen to a MAVLink link, learn while the aircraft flies, speak back.

Entry points: :func:`run_listen` (the ``gcs-sysid listen`` command), :class:`LiveSession`,
:class:`Learner` and :func:`learn_from_tlog` (the same incremental pipeline fed from a file).
See ``docs/live.md``.
"""

from .learner import LearnOptions, Learner, learn_from_tlog
from .session import ListenOptions, LiveSession, run_listen

__all__ = ["LearnOptions", "Learner", "learn_from_tlog", "ListenOptions", "LiveSession", "run_listen"]
