"""One person's choices written by hand: a small YAML file of scenes and the way the person took.

For people recorded without the VR rig. The file names the person and, per trial, a scene file
(the project's scene format, a path relative to this file) and the person's choices in the order
the hand met them, each either a gap, by the obstacles on either side of it (``edge`` for the
table's edge; left, then right, as seen from the start), or an obstacle moved, with its direction
(``FF`` forwards, ``BB`` back, ``LL`` left, ``RR`` right, ``FL``, ``FR``, ``BL``, ``BR``)::

    person: alice            # letters, digits, '_' or '-'
    left_handed: false       # optional (default false)
    trials:
      - scene: scenes/table1.yaml
        choices:
          - gap: [edge, box_1]       # between the table's left edge and box_1
          - move: box_4              # box_4 moved out of the way...
            direction: LL            # ...to the left
      - scene: scenes/table2.yaml
        choices:
          - gap: [box_2, box_3]

Each choice falls in the row (of the scene's qualitative model, as the planner forms them) of the
obstacles it names. A trial whose scene cannot be read, or whose choices name an obstacle the scene
lacks, a gap that is not there, a direction that is not one of the eight or two choices in one row,
is left out with the file, its line and why; the others are learnt from.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from hlp_drake.errors import DatasetError, HlpError
from hlp_drake.files.documents import brief, parse_yaml, read_document
from hlp_drake.scene.io import load_scene
from hlp_drake.scene.model import Scene
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT, RowDecision
from hlp_drake.segmentation.person import PersonDemonstrations
from hlp_drake.taskspace import DIRECTIONS, TaskSpace

EDGE = "edge"
"""How a choice names the table's edge beside a gap."""
SUFFIXES = (".yaml", ".yml")
MAX_TRIALS = 10_000
_NAME = re.compile(r"[A-Za-z0-9_-]{1,64}")


@dataclass(frozen=True)
class StatedTrial:
    """A trial of a person file: the scene and the person's decision in each of its rows.

    Attributes:
        key: "PERSON/T001" (the trial's place in the file, from 1).
        scene: the trial's scene.
        left_handed: the person's handedness.
        decisions: one per row of the scene's task space, nearest the start first ("none" for a
            row the file gives no choice in).
    """

    key: str
    scene: Scene
    left_handed: bool
    decisions: tuple[RowDecision, ...]

    @property
    def subject(self) -> str:
        return self.key.split("/")[0]


def is_person_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a person file (a YAML file) rather than a folder of VR logs."""
    return Path(path).suffix.lower() in SUFFIXES


def read_person_file(path: str | os.PathLike[str]) -> PersonDemonstrations:
    """The trials of the person file ``path`` (see the module's docstring), each unusable one named.

    Raises:
        DatasetError: the file is missing, unreadable or not YAML, or its person, handedness or
            list of trials is malformed (one line each).
    """
    path = Path(path)
    text = read_document(path, DatasetError)
    data = parse_yaml(text, str(path), DatasetError)
    if not isinstance(data, dict):
        raise DatasetError(f"{path}: expected a mapping with person and trials, got {brief(data)}")
    problems = [
        f"{path}: unknown field {key!r}" for key in data if key not in ("person", "left_handed", "trials")
    ]
    person, left_handed, trials = data.get("person"), data.get("left_handed", False), data.get("trials")
    if not isinstance(person, str) or not _NAME.fullmatch(person):
        problems.append(
            f"{path}: person: expected a name of letters, digits, '_' or '-', got {brief(person)}"
        )
    if not isinstance(left_handed, bool):
        problems.append(f"{path}: left_handed: expected true or false, got {brief(left_handed)}")
    if not isinstance(trials, list) or not trials:
        problems.append(f"{path}: trials: expected a list of trials, got {brief(trials)}")
    elif len(trials) > MAX_TRIALS:
        problems.append(f"{path}: trials: more than {MAX_TRIALS:,}")
    if problems:
        raise DatasetError(*problems)
    result = PersonDemonstrations(person)
    lines = _trial_lines(text)
    for index, trial in enumerate(trials):
        where = (
            f"{path}: line {lines[index]}: trials[{index}]"
            if index < len(lines)
            else f"{path}: trials[{index}]"
        )
        try:
            result.demonstrations.append(
                _trial(trial, f"{person}/T{index + 1:03d}", left_handed, path.parent)
            )
        except HlpError as error:  # the trial's first problem (a scene file's names that file)
            result.left_out.append(f"{where}: {error.problems[0]}")
    return result


def _trial_lines(text: str) -> list[int]:
    """The line (from 1) where each trial of the (already checked) document starts."""
    root = yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    for key, value in root.value if isinstance(root, yaml.MappingNode) else []:
        if key.value == "trials" and isinstance(value, yaml.SequenceNode):
            return [item.start_mark.line + 1 for item in value.value]
    return []


def _trial(trial: Any, key: str, left_handed: bool, folder: Path) -> StatedTrial:
    if not isinstance(trial, dict) or set(trial) - {"scene", "choices"}:
        raise HlpError("expected a mapping of scene and choices")
    scene_path, choices = trial.get("scene"), trial.get("choices")
    if not isinstance(scene_path, str) or not scene_path:
        raise HlpError(f"scene: expected a scene file's path, got {brief(scene_path)}")
    if not isinstance(choices, list) or not choices:
        raise HlpError(f"choices: expected a list of the person's choices, got {brief(choices)}")
    scene = load_scene(folder / scene_path)  # a SceneError names the scene file
    space = TaskSpace(scene)
    decided: dict[int, RowDecision] = {}
    for number, choice in enumerate(choices):
        decision = _decision(choice, space)
        if isinstance(decision, str):
            raise HlpError(f"choices[{number}]: {decision}")
        if decision.row in decided:
            raise HlpError(f"choices[{number}]: a second choice in row {decision.row}")
        decided[decision.row] = decision
    decisions = tuple(decided.get(row.index, RowDecision(row.index, NONE)) for row in space.rows)
    return StatedTrial(key, scene, left_handed, decisions)


def _decision(choice: Any, space: TaskSpace) -> RowDecision | str:
    """The row decision ``choice`` states in ``space``, or why it cannot be one."""
    if not isinstance(choice, dict):
        return f"expected a mapping (gap: [left, right], or move: NAME and direction), got {brief(choice)}"
    names = set(space.obstacle_names)
    if set(choice) == {"gap"}:
        pair = choice["gap"]
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(n, str) for n in pair)):
            return f"gap: expected [left, right], two obstacle names or {EDGE!r}, got {brief(pair)}"
        for name in pair:
            if name != EDGE and name not in names:
                return f"gap: names {name!r}, which the scene does not have"
        left, right = (None if n == EDGE else n for n in pair)
        for row in space.gaps:
            for gap in row:
                if (gap.left, gap.right) == (left, right):
                    return RowDecision(gap.row, GAP, gap=gap.index)
        return f"gap: no gap between {pair[0]} and {pair[1]} (left, then right, as seen from the start)"
    if set(choice) == {"move", "direction"}:
        name, direction = choice["move"], choice["direction"]
        if not isinstance(name, str) or name not in names:
            return f"move: names {brief(name)}, which the scene does not have"
        if direction not in DIRECTIONS:
            return f"direction: expected one of {', '.join(DIRECTIONS)}, got {brief(direction)}"
        rows = [r.index for r in space.rows if name in r.members]
        if not rows:
            return f"move: {name} stands in no row between the start and the target"
        return RowDecision(rows[0], OBJECT, obstacle=name, direction=direction)
    return f"expected gap: [left, right], or move: NAME and direction: DIR, got fields {sorted(map(str, choice))}"
