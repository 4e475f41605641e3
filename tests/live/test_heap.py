"""The learner's heap trim gives freed, fragmented memory back to the system (glibc only).

The measurement runs in a fresh interpreter: whether freed chunks stay resident depends on the heap
the process already has (a test worker that ran JAX and other tests before may hand them back at
once), so the test owns its process.
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from gcs_sysid.live.heap import trim_available

SCRIPT = r'''
import gc, json
from pathlib import Path
import numpy as np
from gcs_sysid.live.heap import release_free_heap

def rss_mib():
    line = next(x for x in Path("/proc/self/status").read_text().splitlines() if x.startswith("VmRSS:"))
    return int(line.split()[1]) / 1024.0

# ~160 MiB of 64 KiB arrays (below glibc's mmap threshold once raised, so on the heap) with a small
# survivor after each: freeing the big ones leaves free chunks between live ones, which glibc keeps
# resident until trimmed (what a learner step's temporaries do beside the stores)
np.ones(1 << 19)                 # a freed large block raises the dynamic mmap threshold
big, keep = [], []
for _ in range(2500):
    big.append(np.ones(8192))     # 64 KiB
    keep.append(bytes(1000) + bytes([len(keep) % 256]))   # > 512 B: from malloc, not pymalloc
before = rss_mib()
del big
gc.collect()
held = rss_mib()
trimmed = release_free_heap()
after = rss_mib()
print(json.dumps({"before": before, "held": held, "after": after, "trimmed": trimmed, "kept": len(keep)}))
'''


@pytest.mark.skipif(not trim_available(), reason="the C library has no malloc_trim (not glibc)")
@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="no /proc/self/status to read the RSS from")
def test_trim_returns_fragmented_free_memory():
    p = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout.strip().splitlines()[-1])
    assert r["trimmed"] is True
    assert r["held"] - r["before"] > -20.0      # freeing alone gave (almost) nothing back: fragmented
    assert r["held"] - r["after"] > 100.0, r
    assert r["kept"] == 2500
