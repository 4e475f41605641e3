"""What `gcs-sysid replay` imports, and when (docs/architecture.md, "The second core").

The replay starts its worker decoding the log before it imports the estimation stage's modules (SciPy's
signal and stats packages, filterpy: about 0.8 CPU s, ``docs/benchmarks.md``), so that those imports
overlap the decoding; JAX and optax (about 0.6 CPU s) come later, while the worker smooths the specific
force (the estimation stage's ``meanwhile``); and the main process never imports matplotlib, which only
the worker's figures use. A module-level import of any of these in the CLI, the pipeline or the layers they load before
the decode would put it back on the replay's critical path; these checks fail when that happens (they read
``sys.modules`` in a fresh interpreter; nothing is timed).
"""

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
HEAVY = ("jax", "jaxlib", "optax", "scipy.signal", "scipy.stats", "scipy.optimize", "filterpy", "matplotlib")

PROBE = r"""
import json, sys
heavy = json.loads(sys.argv[1])
loaded = lambda: sorted(m for m in heavy if m in sys.modules)
import gcs_sysid.cli as cli
a = cli.build_parser().parse_args(["replay", sys.argv[2], "--airframe", sys.argv[3], "--out", sys.argv[4]])
from gcs_sysid.pipeline import _load_stages, check_replay
check_replay(a.log, a.airframe, a.out, cli._replay_options(a))    # everything the replay does before the decode
before = loaded()
import gcs_sysid.telemetry.tlog_scan                              # the worker's decoding job
worker = loaded()
_load_stages()                                                    # what runs while the worker decodes
stages = loaded()
from gcs_sysid.pipeline import _load_model_stages
_load_model_stages()                                              # what runs while it smooths the forces
print(json.dumps({"before": before, "worker": worker, "stages": stages, "model_stages": loaded()}))
"""


def test_replay_imports_heavy_modules_only_while_the_worker_decodes(tmp_path):
    out = subprocess.run(
        [sys.executable, "-c", PROBE, json.dumps(HEAVY), str(REPO / "data/flights/sim-trainer-sysid.tlog"),
         str(REPO / "data/airframes/sim-trainer.toml"), str(tmp_path / "report")],
        capture_output=True, text=True, timeout=120, cwd=REPO)
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["before"] == [], f"imported before the log is decoded: {got['before']}"
    assert got["worker"] == [], f"the decoding job imports {got['worker']}"
    # the stage imports do load the heavy packages (so the first check is not vacuous) but not matplotlib;
    # JAX and optax only with the later stages (they would lengthen the decode, the worker's scan being shorter)
    assert {"scipy.signal", "filterpy"} <= set(got["stages"])
    assert not {"jax", "jaxlib", "optax"} & set(got["stages"]), f"the decode's imports load {got['stages']}"
    assert {"jax", "optax", "scipy.signal", "filterpy"} <= set(got["model_stages"])
    assert "matplotlib" not in got["model_stages"], "the main process imports matplotlib (the worker draws the figures)"
