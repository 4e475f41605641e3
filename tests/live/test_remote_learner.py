"""The learner behind `RemoteLearner` (gcs_sysid.live.remote), run here (a Helper without a worker runs its jobs in
this process, through the same functions the worker runs): 'behind' counts the records the receiver queued
(the shared counter), not the batch; a learner whose process is gone says so in one line.
(Learner in the worker = replay of raw.tlog: tests/live/test_listen_player.py and test_listen_can_learner.py.)"""

import sys
from itertools import islice
from pathlib import Path

import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.errors import SysidError
from gcs_sysid.live import remote
from gcs_sysid.live.learner import LearnOptions, iter_tlog_records
from gcs_sysid.live.remote import RemoteLearner
from gcs_sysid.parallel import Helper

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT  # noqa: E402

OPTS = LearnOptions(window_s=4.0, step_s=2.0, lag_s=1.0, min_rows=10 ** 9)


def _records(n):
    return list(islice(iter_tlog_records(FLIGHT), n))


def test_behind_reads_the_receivers_count():
    records = _records(2400)                     # ~9 s of the sample flight (258 msg/s): steps due at 4, 6, 8 s
    rl = RemoteLearner(load_airframe(AIRFRAME), OPTS, Helper(enabled=False), behind_records=2000)
    try:
        for _ in range(len(records)):
            rl.record_queued()
        rl.feed_batch(records)                   # all received before any was fed: few wait after the last ones
        steps = rl.steps
        assert steps >= 2 and rl.coalesced == 0
        for _ in range(5000):                    # the receiver queued 5,000 more while the batch was learned
            rl.record_queued()
        more = _records(4000)[2400:]
        rl.feed_batch(more)                      # now every due step finds > 2,000 records waiting: merged
        assert rl.coalesced >= 2 and rl.steps == steps
        assert rl.coalesced_at and all(s in {r[0] for r in more} for s in rl.coalesced_at)
        assert rl.queued == 7400
    finally:
        rl.drop()
    assert not Path(rl._counter_path).exists()


def test_a_lost_learner_says_so():
    with pytest.raises(SysidError, match="learner's process stopped; its state is lost"):
        remote.feed_batch("no-such-learner", [], [], b"", 2000, [])
