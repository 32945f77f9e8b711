"""One person's own demonstrations: a folder of their VR logs, segmented, each unusable trial named.

The folder has the VR dataset's layout for one participant (``DEMOS/sub_XX/trial_results.csv``
and a ``DEMOS/sub_XX/TYYY/`` folder per trial with its ``scene/`` layouts and ``movement/`` tracks
and interaction log; ``DEMOS/participant_list.csv`` gives the handedness, right-handed without it).
Structured (T010-T099) and unstructured (T100-T129) trials whose reach succeeded are learnt
from. A trial whose files are damaged, empty or missing, whose interaction log names an object its
layout lacks, that failed or that cannot be segmented is left out, with the file (and line) and why.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED
from hlp_drake.errors import DatasetError
from hlp_drake.segmentation.batch import demonstration_records, segment_dataset
from hlp_drake.segmentation.demonstration import Demonstration

LEARNT = (STRUCTURED, UNSTRUCTURED)
"""The trial categories a person's models are adapted on."""
LAYOUT = "one person's VR logs: sub_XX/trial_results.csv and a sub_XX/TYYY/ folder per trial; or a person file, .yaml"


@dataclass
class PersonDemonstrations:
    """The usable demonstrations of one person and what was left out.

    Attributes:
        person: the participant's folder name (``sub_XX``).
        demonstrations: the segmented trials, in trial order.
        left_out: one line per trial (or file) left out: ``PATH: why``.
    """

    person: str
    demonstrations: list[Demonstration] = field(default_factory=list)
    left_out: list[str] = field(default_factory=list)


def read_person(path: str | os.PathLike[str]) -> PersonDemonstrations:
    """The demonstrations in the folder ``path`` (see the module's docstring).

    Raises:
        DatasetError: ``path`` is not a folder of VR logs, or holds more than one person's.
    """
    folder = Path(path)
    if not folder.is_dir():
        reason = "no such folder" if not folder.exists() else "not a folder"
        raise DatasetError(f"{folder}: {reason} (expected {LAYOUT})")
    with tempfile.TemporaryDirectory() as cache:  # a person's few trials parse in moments
        dataset = Dataset(folder, cache_dir=cache, progress=False)
        return _demonstrations(folder, dataset)


def _demonstrations(folder: Path, dataset: Dataset) -> PersonDemonstrations:
    people = sorted({r.subject for r in dataset.records} | _named(dataset))
    if len(people) > 1:
        raise DatasetError(
            f"{folder}: trials of {len(people)} people ({', '.join(people)}); adapt to one person at a time"
        )
    if not people:
        lines = [f"{p['path']}: {p['reason']}" for p in dataset.problems]
        raise DatasetError(f"{folder}: no trials (expected {LAYOUT})", *lines)
    result = PersonDemonstrations(people[0])
    result.left_out += [f"{p['path']}: {p['reason']}" for p in dataset.problems]
    records = demonstration_records(dataset, categories=LEARNT)
    kept = {r.key for r in records}
    for record in dataset.records:
        if record.key in kept:
            continue
        where = folder / record.subject / record.key.split("/")[1]
        if record.category not in LEARNT:
            result.left_out.append(f"{where}: a {record.category} trial (learnt from: T010-T129)")
        else:
            result.left_out.append(f"{where}: the reach did not succeed (outcome {record.outcome!r})")
    segmented = segment_dataset(dataset, mode="fixed", records=records)
    for rejection in segmented.rejections:
        subject, trial = rejection.key.split("/")
        result.left_out.append(f"{folder / subject / trial}: cannot be segmented: {rejection.reason}")
    result.demonstrations = sorted(segmented.demonstrations, key=lambda d: d.key)
    return result


def _named(dataset: Dataset) -> set[str]:
    """The people whose trials the loader left out (so a folder of only damaged trials still names one)."""
    return {key.split("/")[0] for key in dataset.left_out()}
