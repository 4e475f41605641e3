"""Test-suite configuration: 64-bit JAX (as the CLI uses) and the repository's data paths."""

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
