"""The learner's heap trim gives freed, fragmented memory back to the system (glibc only)."""

import gc
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.live.heap import release_free_heap, trim_available


def _rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    pytest.skip("no /proc/self/status")


@pytest.mark.skipif(not trim_available(), reason="the C library has no malloc_trim (not glibc)")
def test_trim_returns_fragmented_free_memory():
    # ~160 MiB of 64 KiB arrays (below glibc's mmap threshold once raised, so on the heap) with a
    # small survivor after each: freeing the big ones leaves free chunks between live ones, which
    # glibc keeps resident until trimmed (what a learner step's temporaries do beside the stores)
    np.ones(1 << 19)                 # a freed large block raises the dynamic mmap threshold
    big, keep = [], []
    for _ in range(2500):
        big.append(np.ones(8192))     # 64 KiB
        keep.append(bytes(1000) + bytes([len(keep) % 256]))   # > 512 B: from malloc, not pymalloc
    before = _rss_mib()
    del big
    gc.collect()
    held = _rss_mib()
    assert release_free_heap() is True
    after = _rss_mib()
    assert held - before > -20.0      # freeing alone gave (almost) nothing back: fragmented
    assert held - after > 100.0, (before, held, after)
    assert len(keep) == 2500
