"""Shared fixtures: the real VR dataset (../shared/data or HLP_DATASET) and a tiny synthetic one."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest

pytest_plugins = ("sto_support",)  # the optimiser's tests' fixtures

REPO = Path(__file__).resolve().parents[1]
DEFAULT_DATA = REPO.parent / "shared" / "data"  # the structured archive and the unstructured part 1 beside it
DEFAULT_ARCHIVE = DEFAULT_DATA / "hlp-vr-dataset.tar.xz"


@pytest.fixture(autouse=True)
def _ctrl_c_delivered():
    """Every test starts with Ctrl-C delivered to this process as a KeyboardInterrupt: not held back
    (a blocked SIGINT is inherited by the processes a test starts) and not ignored, whatever an
    earlier test in this worker process left."""
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    signal.signal(signal.SIGINT, signal.default_int_handler)
    yield


@pytest.fixture(scope="session", autouse=True)
def offline_drake(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Let Drake's Parser start under DRAKE_ALLOW_NETWORK=none without ever providing drake_models.

    Drake's default PackageMap registers the remote package ``drake_models`` and, when networking is
    disabled, refuses to construct unless that package sits in Drake's download cache. The tests get
    a private cache (``TEST_TMPDIR``, which Drake reads first) holding an *empty* ``drake_models``
    package, so any model that really uses ``package://drake_models/...`` still fails to load.
    """
    import pydrake

    root = tmp_path_factory.mktemp("drake_cache")
    params_file = Path(pydrake.__file__).parent / "share/drake/multibody/parsing/drake_models.json"
    params = json.loads(params_file.read_text())
    names = [params["sha256"]]
    if params.get("strip_prefix"):
        names.append(f"{params['sha256']}-{hashlib.sha256(params['strip_prefix'].encode()).hexdigest()}")
    manifest = (
        '<?xml version="1.0"?>\n<package format="2"><name>drake_models</name><version>0.0.0</version>'
        "<description>empty offline stand-in for tests</description>"
        '<maintainer email="none@example.org">none</maintainer><license>MIT</license></package>\n'
    )
    for name in names:
        package = root / ".cache" / "drake" / "package_map" / name
        package.mkdir(parents=True)
        (package / "package.xml").write_text(manifest)
    os.environ["TEST_TMPDIR"] = str(root)
    return root


def real_dataset_path() -> Path | None:
    """HLP_DATASET if set, else ../shared/data (its archives laid over each other), else None."""
    if os.environ.get("HLP_DATASET"):
        return Path(os.environ["HLP_DATASET"])
    return DEFAULT_DATA if DEFAULT_ARCHIVE.exists() else None


def missing(message: str) -> None:
    """Skip the test for missing data, or fail it under CI=true (where the data must be there)."""
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"{message}; it is required under CI")
    pytest.skip(message)


@pytest.fixture(scope="session")
def dataset_path() -> Path:
    path = real_dataset_path()
    if path is None or not path.exists():
        missing(f"VR dataset not found (set HLP_DATASET or place it at {DEFAULT_ARCHIVE})")
    return path


@pytest.fixture(scope="session")
def dataset(dataset_path: Path):
    from hlp_drake.dataset import Dataset

    return Dataset(dataset_path, progress=False)


@pytest.fixture(scope="session")
def unstructured(dataset):
    """The dataset, which must hold unstructured trials (``hlp-vr-unstructured-part1.tar.xz``)."""
    from hlp_drake.dataset import UNSTRUCTURED

    if not dataset.select(category=UNSTRUCTURED):
        missing(
            f"no unstructured trials in the dataset (place hlp-vr-unstructured-part1.tar.xz in {DEFAULT_DATA})"
        )
    return dataset


def run_module(
    module: str, *args: str, cwd: Path | None = None, env: dict | None = None
) -> subprocess.CompletedProcess:
    """Run ``python -m module args`` in a subprocess and capture its output."""
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        capture_output=True,
        text=True,
        check=False,
        cwd=cwd,
        env={**os.environ, **(env or {})},
        timeout=600,
    )


@pytest.fixture(scope="session")
def paper_models(dataset):
    """Paper-preset models (Algorithm 1: Cg, Co, Cc, Cd, Ra) fitted on every structured demonstration."""
    from hlp_drake.features import training_data
    from hlp_drake.learners import PRESETS, DecisionModels
    from hlp_drake.segmentation import segment_dataset

    demonstrations = segment_dataset(dataset, mode="fixed").demonstrations
    return DecisionModels(PRESETS["paper"]).fit(training_data(demonstrations, mode="fixed"))


def pytest_terminal_summary(terminalreporter) -> None:
    """What the fuzz suite's checks saw (``fuzz_support.STATS``), when any fuzz test ran."""
    stats = sys.modules.get("fuzz_support")
    if stats is not None and stats.STATS:
        counts = ", ".join(f"{name} {count}" for name, count in sorted(stats.STATS.items()))
        terminalreporter.write_line(f"fuzz: {counts}")


@pytest.fixture
def char_device(tmp_path) -> Path:
    """A character device to refuse as an output: a null device made in ``tmp_path`` (root), else
    ``/dev/null`` (which a user other than root cannot replace, so a regression cannot harm it)."""
    device = tmp_path / "null"
    try:
        os.mknod(device, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    except PermissionError:
        if os.geteuid() == 0:
            pytest.skip("cannot make a device here, and /dev/null must not be risked as root")
        return Path("/dev/null")
    return device
