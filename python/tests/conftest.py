"""Fixtures: the repository, and the `host` binary the Python results are
compared with (``ZUMO_SWARM_HOST``, as ``scripts/test`` sets it to the
binary its ``cargo test`` built; else the workspace's debug build, brought
up to date by ``cargo build -p host`` first, which after a ``cargo test``
rebuilds it with other features and takes minutes)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def host() -> Path:
    given = os.environ.get("ZUMO_SWARM_HOST")
    if given:
        return Path(given)
    subprocess.run(["cargo", "build", "--quiet", "-p", "host"], cwd=REPO, check=True)
    return REPO / "target" / "debug" / "host"


def run_host(host: Path, *args: str) -> subprocess.CompletedProcess:
    """Runs ``host`` with ``args`` in the repository; fails the test on a non-zero exit."""
    result = subprocess.run([str(host), *args], cwd=REPO, capture_output=True, text=True)
    assert result.returncode == 0, f"host {' '.join(args)} failed:\n{result.stderr}"
    return result
