"""Damaged model files and interaction logs: refused in one line, or their trials left out with a warning."""

from __future__ import annotations

import hashlib
import io
import json
import pathlib

import numpy as np
import pytest
from fault_support import warnings
from synthetic_dataset import write_dataset

from hlp_drake.commands.parsing import run_cli
from hlp_drake.errors import ModelError
from hlp_drake.learners.bundled import BUNDLED_DIRECTORY
from hlp_drake.learners.models import VERSION, DecisionModels
from hlp_drake.learners.svm import RbfSvmClassifier


def models_copy(folder: pathlib.Path, *, meta=None, arrays=None) -> pathlib.Path:
    """The bundled models copied to ``folder``, ``meta`` (models.json's dict) and ``arrays`` (the
    npz's dict) changed in place by the given functions, the checksum recomputed to match."""
    described = json.loads((BUNDLED_DIRECTORY / "models.json").read_text())
    with np.load(BUNDLED_DIRECTORY / "models.npz") as npz:
        stored = {name: npz[name] for name in npz.files}
    if arrays is not None:
        arrays(stored)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **stored)
    folder.mkdir()
    (folder / "models.npz").write_bytes(buffer.getvalue())
    described["sha256"] = hashlib.sha256(buffer.getvalue()).hexdigest()
    if meta is not None:
        meta(described)
    (folder / "models.json").write_text(json.dumps(described))
    return folder


def test_models_of_a_newer_format_are_refused_in_one_line(tmp_path, capsys):
    from hlp_drake.commands.run_scene import main

    newer = models_copy(tmp_path / "newer", meta=lambda m: m.update(version=VERSION + 1))
    expected = f"{newer / 'models.json'}: written by a newer hlp_drake: format {VERSION + 1}, this release reads {VERSION}"
    with pytest.raises(ModelError) as refused:
        DecisionModels.load(newer)
    assert refused.value.problems == (expected,)
    config = tmp_path / "scenario.yaml"
    config.write_text(f"planner: {{models: {newer}}}\n")
    assert run_cli(main, ["--config", str(config), "--workers", "1", "--quiet"]) == 2
    assert capsys.readouterr().err == f"error: {expected}\n"


def fewer_trees(arrays: dict) -> None:
    for name in ("feature", "threshold", "left", "right", "value"):
        arrays[f"row.learner.{name}"] = arrays[f"row.learner.{name}"][:10]


def more_arm_samples(arrays: dict) -> None:
    arrays["arm.train"] = np.concatenate([arrays["arm.train"], arrays["arm.train"][:100]])
    arrays["arm.alpha"] = np.concatenate([arrays["arm.alpha"], arrays["arm.alpha"][:, :100]], axis=1)


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        (fewer_trees, "array 'row.learner.feature' holds 10 trees, the settings declare n_estimators 150"),
        (
            more_arm_samples,
            "array 'arm.train' holds 1600 samples, more than its learner settings allow (1500)",
        ),
    ],
)
def test_arrays_that_disagree_with_the_declared_settings_are_refused(tmp_path, change, reason):
    damaged = models_copy(tmp_path / "damaged", arrays=change)  # each array's shape fits the format
    with pytest.raises(ModelError) as refused:
        DecisionModels.load(damaged)
    assert refused.value.problems == (f"{damaged / 'models.npz'}: {reason}",)


def log_of(folder: pathlib.Path, trial: int) -> pathlib.Path:
    """The synthetic dataset's interaction log of ``trial``."""
    return folder / "sub_01" / f"T{trial:03d}" / "movement" / f"interaction_log_T{trial:03d}.csv"


def damage_logs(folder: pathlib.Path) -> dict[pathlib.Path, str]:
    """Damage the interaction logs of the synthetic dataset's 3 trials: the expected reason by path."""
    text = log_of(folder, 5).read_text()
    log_of(folder, 5).write_text(text[: len(text) - 9])  # cut short in its last line
    log_of(folder, 10).write_text(text.replace(",FailOnTouchObstacleMed,", ",FailOnTouchObstacleHuge,"))
    log_of(folder, 11).write_text(text.replace("PickedUp\n", "Pick\n"))  # cut, then a line end added
    return {
        log_of(folder, 5): "truncated: the last line has no line end",
        log_of(
            folder, 10
        ): "line 2: names 'FailOnTouchObstacleHuge', which the scene does not have: trial skipped",
        log_of(
            folder, 11
        ): "line 3: unknown interaction 'Pick' (expected one of LeftGate, RightGate, PickedUp, "
        "Pushed; the file may be cut short)",
    }


def test_damaged_interaction_logs_are_reported_per_trial_and_left_out(tmp_path, monkeypatch, capsys):
    from hlp_drake.commands.dataset import main as dataset_main
    from hlp_drake.commands.segment import main as segment_main

    folder = write_dataset(tmp_path / "dataset")
    expected = damage_logs(folder)
    monkeypatch.setenv("HLP_CACHE", str(tmp_path / "cache"))
    summary_json = tmp_path / "summary.json"
    assert run_cli(dataset_main, ["summary", "--dataset", str(folder), "--json", str(summary_json)]) == 0
    assert sorted(warnings(capsys.readouterr().err)) == sorted(
        f"warning: {path}: {reason}" for path, reason in expected.items()
    )
    counts = json.loads(summary_json.read_text())["categories"]
    assert counts["structured"]["trials"] == counts["practice"]["trials"] == 0
    argv = ["--dataset", str(folder), "--out", str(tmp_path / "d.csv"), "--json", str(tmp_path / "d.json")]
    assert run_cli(segment_main, [*argv, "--quiet"]) == 0
    rejections = json.loads((tmp_path / "d.json").read_text())["rejections"]
    assert sorted(rejections, key=lambda r: r["trial"]) == [
        {"trial": f"sub_01/T{n:03d}", "reason": f"unreadable data: {expected[log_of(folder, n)]}"}
        for n in (10, 11)  # the structured ones
    ]
    trial = ["--dataset", str(folder), "--trial", "sub_01/T010", "--png", str(tmp_path / "t.png")]
    capsys.readouterr()
    assert run_cli(segment_main, trial) == 2
    assert capsys.readouterr().err == (
        f"error: sub_01/T010 was left out of the dataset: {log_of(folder, 10)}: {expected[log_of(folder, 10)]}\n"
    )


def paper_arrays(arrays: dict) -> None:
    """The bundled rows models' arrays made a paper planner's: small SVMs for Cg, Co and Cc."""
    from hlp_drake.learners.model_format import FIXED

    for name in [n for n in arrays if n.startswith("row.")]:
        del arrays[name]
    for learner in ("gap", "object", "segment"):
        features = FIXED[f"{learner}.n_features"]
        arrays |= {
            f"{learner}.classes": np.array([0.0, 1.0]),
            f"{learner}.mean": np.zeros(features),
            f"{learner}.scale": np.ones(features),
            f"{learner}.gamma": np.array(1.0),
            f"{learner}.support_vectors": np.linspace(-1.0, 1.0, 4 * features).reshape(4, features),
            f"{learner}.dual_coef": np.array([1.0, -1.0, 0.5, -0.5]),
            f"{learner}.intercept": np.array(0.0),
        }


def as_paper(meta: dict) -> None:
    meta["settings"]["planner"] = "paper"


@pytest.mark.parametrize(
    ("array", "value", "expected"),
    [
        ("gap.support_vectors", np.array([1.0, 2.0, 3.0]), "(n_support, n_features=5)"),
        ("segment.dual_coef", np.ones((4, 2)), "(n_support=4,)"),
        ("arm.alpha", np.ones(3), "(n_outputs=2, n_samples="),
    ],
)
def test_an_array_not_of_its_learners_declared_shape_is_refused_naming_both_shapes(
    tmp_path, capsys, array, value, expected
):
    from hlp_drake.commands.run_scene import main

    DecisionModels.load(models_copy(tmp_path / "paper", meta=as_paper, arrays=paper_arrays))  # loads
    assert RbfSvmClassifier.STATE["support_vectors"] == ("float64", ("n_support", "n_features"))

    def damaged(arrays: dict) -> None:
        paper_arrays(arrays)
        arrays[array] = value

    folder = models_copy(tmp_path / "damaged", meta=as_paper, arrays=damaged)  # re-signed: checksum fits
    with pytest.raises(ModelError) as refused:
        DecisionModels.load(folder)
    (problem,) = refused.value.problems
    assert problem.startswith(f"{folder / 'models.npz'}: array '{array}' has shape {value.shape}, expected ")
    assert expected in problem
    config = tmp_path / "scenario.yaml"
    config.write_text(f"planner: {{models: {folder}}}\n")
    assert run_cli(main, ["--config", str(config), "--workers", "1", "--quiet"]) == 2
    assert capsys.readouterr().err == f"error: {problem}\n"
