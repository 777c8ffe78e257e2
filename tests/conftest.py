import os
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"


@pytest.fixture
def rng():
    """A seeded generator: every random test is repeatable."""
    return np.random.default_rng(20261121)


@pytest.fixture
def shared_data():
    """Path to ../shared/data; under CI a missing folder fails the test instead of skipping it."""
    def get(rel: str) -> Path:
        p = SHARED / rel
        if not p.exists():
            if os.environ.get("CI"):
                pytest.fail(f"shared data {p} is missing under CI")
            pytest.skip(f"shared data {p} not present")
        return p
    return get


@pytest.fixture
def sample_dir():
    return ROOT / "sample_data"
