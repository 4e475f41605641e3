"""Test-suite configuration: 64-bit JAX (as the CLI uses) and the repository's data paths."""

import os

# One BLAS thread per process: the suite runs on 2 cores next to JAX's own thread pool, and
# oversubscribed OpenBLAS made small linear algebra several times slower (measured in the envelope
# and maneuver tests: 31 s -> 19 s). Set before numpy is imported.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

# Compiled JAX programs go to a cache private to this test session (inherited by the CLI
# subprocesses), so the suite neither reads nor fills the user's cache.
import tempfile  # noqa: E402

os.environ.setdefault("GCS_SYSID_JAX_CACHE", tempfile.mkdtemp(prefix="gcs-sysid-jax-"))

from pathlib import Path

import pytest

from gcs_sysid.jaxconfig import enable_x64

enable_x64()

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "data"


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The repository's data/ directory."""
    return DATA
