"""Shared fixtures: the real VR dataset (../shared/data or HLP_DATASET) and a tiny synthetic one."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ARCHIVE = REPO.parent / "shared" / "data" / "hlp-vr-dataset.tar.xz"


def real_dataset_path() -> Path | None:
    """HLP_DATASET if set, else the archive in ../shared/data, else None."""
    if os.environ.get("HLP_DATASET"):
        return Path(os.environ["HLP_DATASET"])
    return DEFAULT_ARCHIVE if DEFAULT_ARCHIVE.exists() else None


@pytest.fixture(scope="session")
def dataset_path() -> Path:
    path = real_dataset_path()
    if path is None or not path.exists():
        message = f"VR dataset not found (set HLP_DATASET or place it at {DEFAULT_ARCHIVE})"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{message}; it is required under CI")
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def dataset(dataset_path: Path):
    from hlp_drake.dataset import Dataset

    return Dataset(dataset_path, progress=False)


def run_module(module: str, *args: str, cwd: Path | None = None, env: dict | None = None) -> subprocess.CompletedProcess:
    """Run ``python -m module args`` in a subprocess and capture its output."""
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={**os.environ, **(env or {})},
        timeout=600,
    )
