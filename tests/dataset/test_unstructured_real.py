"""The unstructured trials (T100-T129, part 1) on the real data: loading, the stale start, segmentation."""

from __future__ import annotations

import csv
import io
import tarfile
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from conftest import missing

from hlp_drake.dataset import UNSTRUCTURED, category_of
from hlp_drake.segmentation import segment_dataset
from hlp_drake.segmentation.batch import log_agreement
from hlp_drake.taskspace import TaskSpace

pytestmark = pytest.mark.dataset
PART1 = "hlp-vr-unstructured-part1.tar.xz"


@pytest.fixture(scope="module")
def segmented(unstructured):
    return segment_dataset(unstructured, mode="fixed", categories=(UNSTRUCTURED,))


def part1_archive(dataset) -> Path | None:
    """The part 1 archive among the dataset's parts (found where HLP_DATASET or ../shared/data put
    it), None if the trials come from elsewhere (e.g. an unpacked folder)."""
    return next((part.path for part in dataset.source.parts if part.path.name == PART1), None)


def _start_positions(archive_path: Path) -> dict[str, float]:
    """trial_results.csv's start_pos_x of every trial in part 1, read straight from the archive."""
    starts = {}
    with tarfile.open(archive_path) as archive:
        for member in archive:
            if member.name.endswith("/trial_results.csv"):
                subject = member.name.split("/")[-2]
                for row in csv.DictReader(io.TextIOWrapper(archive.extractfile(member), "utf-8")):
                    starts[f"{subject}/T{int(row['trial_num']):03d}"] = float(row["start_pos_x"])
    return starts


def test_part1_counts(unstructured):
    records = unstructured.select(category=UNSTRUCTURED)
    assert (len(records), sum(r.success for r in records)) == (360, 323)
    assert len({r.subject for r in records}) == 12
    assert unstructured.problems == []


def test_the_stale_start_of_t100_is_replaced_by_trial_results(unstructured):
    archive = part1_archive(unstructured)
    if archive is None:
        missing(f"{PART1} is not among the dataset's parts (the test reads its trial_results.csv)")
    starts = _start_positions(archive)
    # Every participant's T100 scene file keeps x = 0: one note each, naming the file and both values.
    noted = sorted(n["path"].split(":")[-1].split("/scene")[0] for n in unstructured.notes)
    assert noted == sorted(
        f"{s}/T100" for s in {r.subject for r in unstructured.select(category=UNSTRUCTURED)}
    )
    assert all("StartPoint x 0.0000 is stale" in n["reason"] for n in unstructured.notes)
    for record in unstructured.select(category=UNSTRUCTURED):
        trial = unstructured.trial(record.key)
        # World y is minus Unity x (the table is centred on x = 0); the hand starts there too.
        assert trial.scene.start[1] == pytest.approx(-starts[record.key], abs=1e-6)
        assert abs(trial.trackers["hand"].position[0, 1] - trial.scene.start[1]) < 0.035


def test_segmentation_keeps_every_successful_trial_with_any_number_of_rows(unstructured, segmented):
    assert len(segmented.demonstrations) == 323 and segmented.rejections == []
    rows = Counter(len(d.decisions) for d in segmented.demonstrations)
    assert set(rows) == {3, 4, 5, 6}
    decisions = Counter(x.decision for d in segmented.demonstrations for x in d.decisions)
    assert decisions["gap"] > 2 * decisions["object"] > 0  # people mostly went through gaps here
    for demo in segmented.demonstrations:
        space = TaskSpace(demo.scene)
        go = demo.hand_path
        for decision, row in zip(demo.decisions, space.rows):
            crossed = bool(np.any(go[:, 0] >= row.x))
            if decision.decision == "none":  # never crossed: beside the target, no element
                assert not crossed and decision.element == ""
                assert demo.scene.target.x - row.x < 0.045
            elif decision.decision == "gap":  # the gap holding the hand where it first crosses the row
                frame = int(np.flatnonzero(go[:, 0] >= row.x)[0])
                gap = space.gaps[row.index - 1][decision.gap - 1]
                assert gap.rect.y_min - 0.01 <= go[frame, 1] <= gap.rect.y_max + 0.01


def test_decisions_agree_with_the_interaction_log(unstructured, segmented):
    assert log_agreement(unstructured, segmented) >= 0.97


def test_categories_by_trial_number():
    assert [category_of(n) for n in (9, 10, 99, 100, 129)] == [
        "practice",
        "structured",
        "structured",
        "unstructured",
        "unstructured",
    ]
