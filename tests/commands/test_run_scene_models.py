"""``run_scene --models DIR [--models-sha256 HEX]``: the scenario plans with them, tampered files refused."""

from __future__ import annotations

import shutil

from conftest import run_module

from hlp_drake.commands.run_scene import _parser, _scenario
from hlp_drake.learners.bundled import BUNDLED_DIRECTORY, BUNDLED_SHA256
from hlp_drake.systems.planning.diagram import scenario_models


def _copy(tmp_path):
    folder = tmp_path / "models"
    shutil.copytree(BUNDLED_DIRECTORY, folder)
    return folder


def test_the_models_given_are_the_scenarios_pinned(tmp_path):
    folder = _copy(tmp_path)
    args = _parser().parse_args(["--models", str(folder), "--models-sha256", BUNDLED_SHA256])
    scenario = _scenario(args)
    assert scenario.planner.models == str(folder) and scenario.planner.models_sha256 == BUNDLED_SHA256
    assert scenario_models(scenario).subjects_  # loaded from the folder


def test_a_tampered_model_file_is_refused_before_the_run(tmp_path):
    folder = _copy(tmp_path)
    meta = folder / "models.json"
    meta.write_text(meta.read_text().replace('"n_estimators": 150', '"n_estimators": 151'))
    result = run_module("hlp_drake.run_scene", "--models", str(folder), "--models-sha256", BUNDLED_SHA256)
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.startswith(f"error: {meta}: SHA-256 ") and result.stderr.endswith(
        "(these are not the trusted models)\n"
    )
    (folder / "models.npz").write_bytes(b"not an npz")
    unpinned = run_module("hlp_drake.run_scene", "--models", str(folder))
    assert unpinned.returncode == 2 and unpinned.stdout == ""
    assert unpinned.stderr == (
        f"error: {folder / 'models.npz'}: checksum mismatch (the file was modified or damaged)\n"
    )


def test_a_pin_without_models_is_a_usage_error():
    result = run_module("hlp_drake.run_scene", "--models-sha256", BUNDLED_SHA256)
    assert result.returncode == 2
    assert result.stderr == (
        "error: --models-sha256 pins the models of --models DIR: give --models too "
        "(see python -m hlp_drake.run_scene --help)\n"
    )
