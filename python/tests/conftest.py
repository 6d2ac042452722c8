"""Shared fixtures: the repository's paths and the ``shoal`` binary to compare with."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def repo() -> Path:
    """The repository root."""
    return REPO


@pytest.fixture(scope="session")
def tiny() -> Path:
    """The small test scenario: 40 reef fish, a shark, food and a rock."""
    return REPO / "scenarios" / "tiny.ron"


@pytest.fixture(scope="session")
def shoal_bin() -> str:
    """The ``shoal`` command: ``SHOAL_BIN`` (``tests/python_package.rs`` sets it to the binary
    cargo built), else one on ``PATH``; the tests that compare with it skip without one."""
    path = os.environ.get("SHOAL_BIN") or shutil.which("shoal")
    if not path:
        pytest.skip("no shoal binary: set SHOAL_BIN (cargo test sets it)")
    return path
