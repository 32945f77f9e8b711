"""The loader on the real VR dataset (../shared/data or HLP_DATASET): counts, frame and alignment."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import run_module

from hlp_drake.dataset import PRACTICE, STRUCTURED
from hlp_drake.scene import find_rows

pytestmark = pytest.mark.dataset


def test_counts_match_the_reference(dataset):
    assert dataset.problems == []
    assert len(dataset.subjects) == 24
    assert "sub_05" not in dataset.subjects and "sub_10" not in dataset.subjects
    practice = dataset.select(category=PRACTICE)
    structured = dataset.select(category=STRUCTURED)
    assert (len(practice), sum(r.success for r in practice)) == (216, 155)
    assert (len(structured), sum(r.success for r in structured)) == (2160, 1805)


def test_left_handed_subjects(dataset):
    left = {r.subject for r in dataset.records if r.handedness == "left"}
    assert left == {"sub_02", "sub_20"}
    assert {r.handedness for r in dataset.records} == {"left", "right"}


def test_a_known_trial_in_the_world_frame(dataset):
    trial = dataset.trial("sub_01/T050")
    assert trial.record.outcome == "Success" and trial.record.trial_name == "centre_free_first_row_2"
    scene = trial.scene
    # grid_objects_layout_T050.csv: FailOnTouchObstacleMed at Unity x 0.2575, z -0.105, width 0.10
    med = scene.obstacle("FailOnTouchObstacleMed")
    assert (med.x, med.y) == pytest.approx((0.245, -0.2575))
    assert med.size[:2] == pytest.approx((0.05, 0.10), abs=1e-6)
    assert scene.start == pytest.approx((0.10, 0.0))
    assert scene.target.position == pytest.approx((0.525, 0.0))
    assert scene.table.height == pytest.approx(0.73)
    rows = find_rows(scene)
    assert [r.x for r in rows] == pytest.approx([0.245, 0.405])
    assert all(len(r.members) == 3 for r in rows)
    hand = trial.trackers["hand"]
    # The hand moves away from the start (+x) above the table top (z up).
    assert hand.position[0, 0] == pytest.approx(0.1087, abs=1e-4)
    assert np.nanmax(hand.position[:, 0]) > 0.45
    assert 0.73 < np.median(hand.position[:, 2]) < 0.85


def test_structured_rows_and_track_alignment(dataset):
    structured = dataset.select(category=STRUCTURED, success=True)
    misaligned = 0
    for trial in dataset.trials(structured[::10]):
        names = {o.name: o for o in trial.scene.obstacles}
        assert {round(o.x, 3) for n, o in names.items() if not n.endswith("-1")} == {0.245}
        assert {round(o.x, 3) for n, o in names.items() if n.endswith("-1")} == {0.405}
        time = trial.trackers["hand"].time
        assert all(np.array_equal(t.time, time) for t in trial.trackers.values())
        misaligned += not np.array_equal(trial.objects["Target"].time, time)
    assert misaligned == 0


def test_summary_cli_on_the_real_dataset(dataset_path, tmp_path):
    out = tmp_path / "summary.json"
    result = run_module("hlp_drake.dataset", "summary", "--dataset", str(dataset_path), "--json", str(out))
    assert result.returncode == 0, result.stderr
    assert "24 subjects" in result.stdout
    summary = json.loads(out.read_text())
    assert summary["subjects"] == 24
    assert summary["categories"]["practice"] == {"trials": 216, "successes": 155}
    assert summary["categories"]["structured"] == {"trials": 2160, "successes": 1805}


def test_task_space_gaps_match_the_reference_statistics(dataset):
    """Reference 2.2, measured over the 8 gaps of all successful structured trials."""
    from hlp_drake.taskspace import TaskSpace

    widths = []
    for record in dataset.select(category=STRUCTURED, success=True):
        space = TaskSpace(dataset.scene(record.key))
        assert [len(g) for g in space.gaps] == [4, 4]
        widths += [g.width for gaps in space.gaps for g in gaps]
    widths = np.array(widths)
    assert len(widths) == 8 * 1805
    assert widths.min() == pytest.approx(0.005, abs=1e-4)
    assert np.median(widths) == pytest.approx(0.090, abs=1e-3)
    assert widths.max() == pytest.approx(0.378, abs=1e-3)
    assert np.mean(widths < 0.05) == pytest.approx(0.193, abs=0.002)
    assert np.mean(widths < 0.075) == pytest.approx(0.384, abs=0.002)
