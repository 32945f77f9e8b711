"""Segment many trials of the VR dataset: the kept demonstrations and the rejections with reasons."""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field

from tqdm import tqdm

from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, TrialRecord, category_of
from hlp_drake.runtime.terminal import bars_disabled
from hlp_drake.segmentation.demonstration import NONE, OBJECT, Demonstration, Rejection
from hlp_drake.segmentation.modes import DEFAULT_MODE, Mode, check_mode
from hlp_drake.segmentation.segment import Rejected, segment_trial
from hlp_drake.taskspace import TaskSpace


@dataclass
class SegmentationResult:
    """Kept demonstrations (in record order) and rejected trials."""

    mode: Mode
    demonstrations: list[Demonstration] = field(default_factory=list)
    rejections: list[Rejection] = field(default_factory=list)

    def reasons(self) -> Counter[str]:
        """How many trials were rejected for each reason (numbers and names folded into a pattern)."""
        return Counter(_reason_kind(r.reason) for r in self.rejections)

    def flag_counts(self) -> Counter[tuple[int, ...]]:
        return Counter(d.flags for d in self.demonstrations)


def _reason_kind(reason: str) -> str:
    reason = re.sub(r"FailOnTouchObstacle\S+", "<obstacle>", reason)
    return re.sub(r"\d+", "N", reason)


def demonstration_records(
    dataset: Dataset, subjects: Iterable[str] | None = None, categories: Iterable[str] = (STRUCTURED,)
) -> list[TrialRecord]:
    """The trials the method learns from: the successful trials of ``categories`` (default: the
    structured trials T010-T099)."""
    categories = tuple(categories)
    return [r for r in dataset.select(success=True, subjects=subjects) if r.category in categories]


def segment_dataset(
    dataset: Dataset,
    *,
    mode: Mode = DEFAULT_MODE,
    records: list[TrialRecord] | None = None,
    categories: Iterable[str] = (STRUCTURED,),
    progress: bool = False,
) -> SegmentationResult:
    """Segment ``records`` (default: all successful trials of ``categories``) of ``dataset``.

    Trials of those categories the dataset loader already left out (unreadable or invalid files)
    are reported as rejections too, with the loader's reason.
    """
    result = SegmentationResult(check_mode(mode))
    if records is None:
        categories = tuple(categories)
        records = demonstration_records(dataset, categories=categories)
        for key, problem in dataset.left_out().items():
            if category_of(int(key[-3:])) in categories:
                result.rejections.append(Rejection(key, f"unreadable data: {problem['reason']}"))
    for record in tqdm(records, desc=f"segmenting ({mode})", unit="trial", disable=bars_disabled(progress)):
        trial = dataset.trial(record.key)
        try:
            result.demonstrations.append(segment_trial(trial, mode=mode))
        except Rejected as rejected:
            result.rejections.append(Rejection(record.key, rejected.reason))
    return result


def log_agreement(dataset: Dataset, result: SegmentationResult) -> float:
    """Share of the decided rows whose decision and element match the interaction log: a row with a
    PickedUp obstacle (the first one picked up there) is "move" that obstacle, one without is a gap
    (rows the hand never crossed have no decision and do not count)."""
    agree = total = 0
    for demo in result.demonstrations:
        row_of = {n: row.index for row in TaskSpace(demo.scene).rows for n in row.members}
        first: dict[int, str] = {}
        for event in dataset.trial(demo.key).interactions:
            if event.kind == "PickedUp" and event.non_dominant in row_of:
                first.setdefault(row_of[event.non_dominant], event.non_dominant)
        for d in demo.decisions:
            if d.decision == NONE:
                continue
            total += 1
            agree += (d.decision == OBJECT) == (d.row in first) and (
                d.row not in first or first[d.row] == d.obstacle
            )
    return agree / max(total, 1)
