"""The five training sets (state-action pairs) of the decision learners, from segmented demonstrations."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from hlp_drake.features.arm import ARM_FEATURES, arm_features
from hlp_drake.features.direction import DIRECTION_FEATURES, direction_features, direction_index
from hlp_drake.features.row_choice import (
    HUMAN_HAND_WIDTH,
    ROW_CONTEXT_FEATURES,
    RowCandidates,
    RowChoiceScene,
)
from hlp_drake.features.scene_features import GAP_FEATURES, OBJECT_FEATURES, gap_features, object_features
from hlp_drake.features.segment import SEGMENT_FEATURES, segment_feature_matrix
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT, Demonstration, RowDecision
from hlp_drake.segmentation.modes import Mode, check_mode, is_faithful
from hlp_drake.taskspace import DIRECTIONS, Node, TaskSpace
from hlp_drake.taskspace.relocation import relocated_array


@dataclass
class LabelledSet:
    """Features ``X`` (n, k), labels ``y`` (n,) or (n, 2), and the subject and trial of each row."""

    columns: tuple[str, ...]
    X: np.ndarray
    y: np.ndarray
    subjects: np.ndarray
    keys: np.ndarray
    original: np.ndarray  # bool per row: part of the original's training set (see ``training_data``)

    def __len__(self) -> int:
        return len(self.y)

    def rows(self, mask: np.ndarray) -> LabelledSet:
        return LabelledSet(
            self.columns,
            self.X[mask],
            self.y[mask],
            self.subjects[mask],
            self.keys[mask],
            self.original[mask],
        )

    def subset(self, subjects: Iterable[str]) -> LabelledSet:
        """The rows of the given subjects."""
        return self.rows(np.isin(self.subjects, list(subjects)))

    def original_rows(self) -> LabelledSet:
        """Only the rows the original code trained on."""
        return self.rows(self.original)


SETS = ("gap", "object", "direction", "segment", "arm", "people", "row")


@dataclass
class TrainingData:
    """Gap (Xg), object (Xo), direction (Xd), segment (Xc), arm (Xa) and row-choice (Xr) training sets."""

    mode: Mode
    gap: LabelledSet
    object: LabelledSet
    direction: LabelledSet
    segment: LabelledSet
    arm: LabelledSet
    people: LabelledSet  # per demonstration: X = (upper arm, forearm) lengths, y = start (q1, q2)
    row: LabelledSet  # per candidate of every scored row (fixed mode only)

    def subset(self, subjects: Iterable[str]) -> TrainingData:
        subjects = list(subjects)
        return TrainingData(self.mode, *(getattr(self, n).subset(subjects) for n in SETS))

    def where(self, keep) -> TrainingData:
        """The rows of the trials (keys) ``keep(key)`` accepts."""
        return TrainingData(
            self.mode,
            *(
                getattr(self, n).rows(
                    np.array([bool(keep(k)) for k in getattr(self, n).keys], dtype=bool).reshape(-1)
                )
                for n in SETS
            ),
        )


class _Builder:
    """Accumulates the rows of one labelled set."""

    def __init__(self, columns: tuple[str, ...]) -> None:
        self.columns, self.X, self.y, self.keys, self.original = columns, [], [], [], []

    def add(self, key: str, X: np.ndarray, y: np.ndarray, original: bool = True) -> None:
        X = np.atleast_2d(X)
        self.X.append(X)
        self.y.append(np.asarray(y, dtype=float).reshape(len(X), -1))
        self.keys += [key] * len(X)
        self.original += [original] * len(X)

    def build(self) -> LabelledSet:
        width = len(self.columns)
        X = np.vstack(self.X) if self.X else np.zeros((0, width))
        y = np.vstack(self.y) if self.y else np.zeros((0, 1))
        y = y[:, 0] if y.shape[1] == 1 else y
        keys = np.array(self.keys, dtype=object)
        subjects = np.array([k.split("/")[0] for k in self.keys], dtype=object)
        return LabelledSet(self.columns, X, y, subjects, keys, np.array(self.original, dtype=bool))


def _chosen(node: Node, decision) -> bool:
    if node.kind == GAP:
        return decision.decision == GAP and node.gap == decision.gap
    return decision.decision == OBJECT and node.obstacle == decision.obstacle


def _segment_labels(
    space: TaskSpace, demo: Demonstration, row: int, near: list[Node], far: list[Node], *, faithful: bool
) -> np.ndarray:
    """(len(near), len(far)) 0/1 matrix with a 1 at the pair of nodes the demonstrator used."""
    labels = np.zeros((len(near), len(far)))
    d_near, d_far = demo.decisions[row - 1], demo.decisions[row]
    if faithful and d_near.decision == OBJECT and d_far.decision == GAP:
        # Bug B2: the cell is transposed: (near gap with the far gap's index, far obstacle with the
        # near obstacle's position in its row).
        near_gaps = [n for n in near if n.kind == GAP]
        near_objects = [n for n in near if n.kind == OBJECT]
        far_objects = [n for n in far if n.kind == OBJECT]
        i = d_far.gap - 1
        j = [n.obstacle for n in near_objects].index(d_near.obstacle)
        if i < len(near_gaps) and j < len(far_objects):
            labels[near.index(near_gaps[i]), far.index(far_objects[j])] = 1.0
        return labels
    i = next(k for k, n in enumerate(near) if _chosen(n, d_near))
    j = next(k for k, n in enumerate(far) if _chosen(n, d_far))
    labels[i, j] = 1.0
    return labels


def gap_labels(demo: Demonstration, space: TaskSpace, *, faithful: bool) -> list[float]:
    """Per gap (rows in order, left to right): 1 for the gap the hand went through, 0 elsewhere and
    in rows where an obstacle was moved (or that the hand never crossed). Faithful: the raw
    passage flags of gap rows."""
    labels: list[float] = []
    for decision, row_flags, gaps in zip(demo.decisions, demo.gap_flags, space.gaps):
        if decision.decision != GAP:
            labels += [0.0] * len(gaps)
        elif faithful:
            labels += [float(f) for f in row_flags]
        else:
            labels += [float(g.index == decision.gap) for g in gaps]
    return labels


def object_labels(demo: Demonstration, space: TaskSpace) -> list[float]:
    """Per obstacle (scene order): 1 for each row's moved obstacle."""
    moved = {d.obstacle for d in demo.decisions if d.decision == OBJECT}
    return [float(n in moved) for n in space.obstacle_names]


def row_choice_rows(
    demo: Demonstration,
    space: TaskSpace,
    *,
    hand_width: float = HUMAN_HAND_WIDTH,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per row the person crossed: the row's candidates' Xr and 0/1 labels (1: the person's).

    The hand goes from row to row as the planner's does (``row_situations``).
    """
    return [
        (candidates.X, (np.arange(len(candidates)) == k).astype(float))
        for _, candidates, k in row_situations(demo, space, hand_width=hand_width, mirror=demo.left_handed)
    ]


def row_situations(
    demo: Demonstration,
    space: TaskSpace,
    *,
    hand_width: float = HUMAN_HAND_WIDTH,
    mirror: bool = False,
) -> list[tuple[RowDecision, RowCandidates, int]]:
    """Per row the person crossed: the decision, the row's candidates as the person met them, and
    the position of the person's choice among them.

    The hand goes from row to row as the planner's does: from the start to the passage point of
    the person's gap, or to where the person's obstacle is released (the centre of its relocated
    region in the person's direction), which then no longer stands in its row. A row whose
    obstacle was moved already (a second move in a row) is left out.

    Args:
        mirror: describe the rows as a left arm sees them (``RowChoiceScene.candidates``).
    """
    features = RowChoiceScene(space, hand_width)
    hand = np.asarray(demo.scene.start, float)
    previous, came_by = hand, "start"
    removed: set[int] = set()
    rows = []
    for decision in demo.decisions:
        if decision.decision == NONE:
            continue
        (candidates,) = features.candidates(
            decision.row, hand, [removed], mirror=mirror, previous=previous, came_by=[came_by]
        )
        names = space.obstacle_names
        chosen = [
            k
            for k in range(len(candidates))
            if candidates.kinds[k] == decision.decision and candidates.element(k, names) == decision.element
        ]
        if len(chosen) != 1:
            continue  # the person's obstacle was moved already (a second move in a row is not learnt)
        k = chosen[0]
        rows.append((decision, candidates, k))
        if decision.decision == OBJECT:
            obstacle = int(candidates.obstacles[k])
            region = relocated_array(space.obstacle_bounds[[obstacle]], space.alpha)[
                0, DIRECTIONS.index(decision.direction)
            ]
            previous, came_by = candidates.points[k], "release"
            hand = np.array([(region[0] + region[2]) / 2.0, (region[1] + region[3]) / 2.0])
            removed.add(obstacle)
        else:
            previous, came_by = hand, "gap"
            hand = candidates.points[k]
    return rows


def _add_row_choice(builder: _Builder, demo: Demonstration, space: TaskSpace) -> None:
    for X, y in row_choice_rows(demo, space):
        builder.add(demo.key, X, y)


def row_choice_set(demonstrations: Iterable[Demonstration]) -> LabelledSet:
    """The row-choice examples (``row_choice_rows``) of fixed-mode demonstrations."""
    builder = _Builder(ROW_CONTEXT_FEATURES)
    for demo in demonstrations:
        _add_row_choice(builder, demo, TaskSpace(demo.scene))
    return builder.build()


def training_data(demonstrations: Iterable[Demonstration], *, mode: Mode | None = None) -> TrainingData:
    """Build the five training sets from demonstrations segmented in ``mode``.

    - gap: every gap of every trial (label: the gap passed; 0 in rows where an obstacle was
      moved); the original uses only trials that used at least one gap (``original`` rows);
    - object: every obstacle of every trial (label: the row's moved obstacle); the original uses
      only trials that moved at least one obstacle (``original`` rows);
    - direction: one row per moved obstacle (label: direction class index);
    - segment: every (node of row r, node of row r+1) pair (label: the pair the hand used);
    - arm: consecutive keypoints (label: the next keypoint's (q1, q2));
    - row (fixed mode): every candidate of every row the person crossed (``row_choice_rows``).
    """
    gap, obj, row_set = _Builder(GAP_FEATURES), _Builder(OBJECT_FEATURES), _Builder(ROW_CONTEXT_FEATURES)
    direction, segment, arm = _Builder(DIRECTION_FEATURES), _Builder(SEGMENT_FEATURES), _Builder(ARM_FEATURES)
    people = _Builder(("upper_arm", "forearm"))
    for demo in demonstrations:
        mode = check_mode(mode or demo.mode)
        if demo.mode != mode:
            raise ValueError(f"{demo.key} was segmented in {demo.mode} mode, not {mode}")
        faithful = is_faithful(mode)
        space = TaskSpace(demo.scene)
        flags = demo.flags
        if not faithful:
            _add_row_choice(row_set, demo, space)
        gap.add(demo.key, gap_features(space), gap_labels(demo, space, faithful=faithful), not all(flags))
        obj.add(demo.key, object_features(space), object_labels(demo, space), any(flags))
        for k, keypoint in enumerate(demo.keypoints):
            if keypoint.kind != "approach":
                continue
            decision = demo.decisions[keypoint.row - 1]
            features = direction_features(
                space,
                decision.obstacle,
                hand=demo.keypoints[k - 1].position,
                mode=mode,
                training=True,
                hand_to_object=keypoint.direction,
            )
            direction.add(demo.key, features, [direction_index(decision.direction)])
        for row in range(1, len(space.rows)):
            if NONE in (demo.decisions[row - 1].decision, demo.decisions[row].decision):
                continue  # a row beside the target: no segment was chosen into or out of it
            near, far = space.nodes(row), space.nodes(row + 1)
            labels = _segment_labels(space, demo, row, near, far, faithful=faithful)
            features = segment_feature_matrix(space, near, far, mode=mode, training=True)
            segment.add(demo.key, features, labels.reshape(-1))
        people.add(
            demo.key,
            np.array([demo.link_lengths.upper_arm, demo.link_lengths.forearm]),
            [demo.keypoints[0].arm],
        )
        scale = demo.link_lengths.total if faithful else 1.0  # bug B4: divided by the arm length twice
        mirror = demo.left_handed and not faithful
        for before, after in zip(demo.keypoints, demo.keypoints[1:]):
            displacement = np.asarray(after.displacement) / scale
            arm.add(
                demo.key, arm_features(before.arm, displacement, after.direction, mirror=mirror), [after.arm]
            )
    return TrainingData(
        mode or "fixed",
        gap.build(),
        obj.build(),
        direction.build(),
        segment.build(),
        arm.build(),
        people.build(),
        row_set.build(),
    )
