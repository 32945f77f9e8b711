"""Segment a successful demonstration into per-row decisions and keypoints (reference section 3)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hlp_drake.dataset.records import Trial
from hlp_drake.scene.rows import Row
from hlp_drake.segmentation.arm import LinkLengths, arm_angles, link_lengths, medial_direction
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT, Demonstration, Keypoint, RowDecision
from hlp_drake.segmentation.modes import DEFAULT_MODE, Mode, is_faithful
from hlp_drake.segmentation.motion import first_moved_per_row, motion_period
from hlp_drake.taskspace import DIRECTIONS, Gap, Rect, TaskSpace, direction_blocks, direction_of

ARM_TRACKERS = ("hand", "elbow", "upper_arm")
SEGMENT_START_FALLBACK = 20  # frames before the approach when the previous keypoint is later (original)
ROUNDING = 0.01  # m, the original rounds the row-2 trajectory to 1 cm for gap directions


@dataclass(frozen=True)
class _Entry:
    """A keypoint before its angles are computed; ``origin`` is the frame its direction starts at."""

    kind: str
    row: int | None
    frame: int
    origin: int
    rounded: bool = False  # the original's 1-cm rounded path for row-2 gap directions


class Rejected(Exception):
    """Segmentation left the trial out; ``reason`` says why in one line."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def _checked_tracks(trial: Trial, names: list[str]) -> dict[str, np.ndarray]:
    """Planar positions of the arm trackers and the objects ``names``; reject bad or missing tracks."""
    tracks = {}
    for name in ARM_TRACKERS:
        if name not in trial.trackers:
            raise Rejected(f"no {name} track")
        tracks[name] = trial.trackers[name].position[:, :2]
    for name in names:
        if name not in trial.objects:
            raise Rejected(f"no movement track for {name}")
        tracks[name] = trial.objects[name].position[:, :2]
    frames = len(tracks["hand"])
    if frames < 2:
        raise Rejected(f"hand track truncated to {frames} frame(s)")
    for name, positions in tracks.items():
        if len(positions) != frames:
            raise Rejected(f"{name} track has {len(positions)} frames, hand track {frames}")
        if not np.all(np.isfinite(positions)):
            raise Rejected(f"{name} track contains NaN or infinite positions")
    return tracks


def _inside(points: np.ndarray, rect: Rect) -> np.ndarray:
    """Strictly inside (the original's test for gap passage)."""
    return (
        (points[:, 0] > rect.x_min)
        & (points[:, 0] < rect.x_max)
        & (points[:, 1] > rect.y_min)
        & (points[:, 1] < rect.y_max)
    )


def _crossing(go: np.ndarray, row: Row, gaps: list[Gap]) -> tuple[int, int] | None:
    """(frame, position in ``gaps``) where the hand first crosses the row's depth (its members'
    mean centre depth) and the gap whose lateral interval holds it there; None if it never does.

    Raises:
        Rejected: the hand crosses the row's depth over one of its obstacles.
    """
    frames = np.flatnonzero(go[:, 0] >= row.x)
    if len(frames) == 0:
        return None
    frame = int(frames[0])
    y = float(go[frame, 1])
    if frame > 0:  # the lateral position where the path reaches the depth, between two samples
        (x0, y0), (x1, y1) = go[frame - 1], go[frame]
        y = float(y0 + (y1 - y0) * (row.x - x0) / (x1 - x0))
    for index, gap in enumerate(gaps):
        if gap.rect.y_min <= y <= gap.rect.y_max:
            return frame, index
    raise Rejected(f"the hand crossed row {row.index} over an obstacle (y {y:+.3f} m) and moved none there")


def _moving_direction(
    space: TaskSpace, name: str, initial: np.ndarray, final: np.ndarray, *, faithful: bool
) -> str:
    """Direction class of a moved obstacle (reference 3.7; bug B9 in faithful mode)."""
    if faithful:
        # Largest overlap of the obstacle, placed at its pose at the end of the whole trial, with
        # the eight blocks around its initial footprint; no overlap at all -> FF (first class).
        rect = space.rects[name]
        dx, dy = final - np.asarray(rect.center)
        moved = Rect(rect.x_min + dx, rect.y_min + dy, rect.x_max + dx, rect.y_max + dy)
        overlaps = [block.overlap(moved) for block in direction_blocks(rect, space.alpha).values()]
        return DIRECTIONS[int(np.argmax(overlaps))]
    label = direction_of(*(final - initial))
    if label is None:
        raise Rejected(f"moved obstacle {name} is released where it started")
    return label


def _motion_periods(
    tracks: dict[str, np.ndarray], moved: dict[int, str], target_name: str, *, faithful: bool
) -> dict[str, tuple[int, int]]:
    """(approach, release) frames of the moved obstacles and the target (reference 3.5).

    Raises:
        Rejected: the original's rejection rules (3.8), checked in its order.
    """
    periods = {
        name: motion_period(tracks[name], faithful=faithful) for name in [*moved.values(), target_name]
    }
    moved_count = sum(p is not None for p in periods.values())
    if len(moved) >= 2 and moved_count < len(moved) + 1:
        raise Rejected(
            f"{len(moved)} rows with a moved obstacle but only {moved_count} objects moved (incl. target)"
        )
    if periods[target_name] is None:
        raise Rejected("the target never moved")
    if moved and moved_count < 2:
        raise Rejected("an obstacle was picked up or pushed but did not move")
    for name in moved.values():
        if periods[name] is None:
            raise Rejected(f"obstacle {name} was picked up or pushed but did not move")
    return periods  # type: ignore[return-value]  # every period is set once the rules pass


def _object_row(
    space: TaskSpace,
    row: Row,
    name: str,
    period: tuple[int, int],
    track: np.ndarray,
    previous: int,
    *,
    faithful: bool,
) -> tuple[list[_Entry], RowDecision]:
    """The approach and release keypoints and the decision of a row whose obstacle ``name`` moved
    during ``period``; ``previous`` is the frame of the previous row's last keypoint."""
    approach, release = period
    origin = 0 if row.index == 1 else previous
    if origin > approach:
        origin = max(approach - SEGMENT_START_FALLBACK, 0)
    entries = [
        _Entry("approach", row.index, approach, origin),
        _Entry("release", row.index, release, approach),
    ]
    initial = np.array(space.rects[name].center)
    final = track[-1] if faithful else track[release]
    direction = _moving_direction(space, name, initial, final, faithful=faithful)
    return entries, RowDecision(row.index, OBJECT, obstacle=name, direction=direction)


def _gap_passage(go: np.ndarray, row: Row, gaps: list[Gap], *, faithful: bool) -> tuple[int, int] | None:
    """(frame, position in ``gaps``) of the hand's passage through the row; None (fixed mode) if it
    never reaches the row's depth: a row beside the target, where no decision was made.

    Raises:
        Rejected: faithful mode, the hand passed no gap of the row; fixed mode, see ``_crossing``.
    """
    if not faithful:
        return _crossing(go, row, gaps)
    inside = [np.flatnonzero(_inside(go, gap.rect)) for gap in gaps]
    passed = [(frames[0], i) for i, frames in enumerate(inside) if len(frames)]
    if not passed:
        raise Rejected(f"the hand passed no gap of row {row.index} and moved no obstacle there")
    return passed[0]  # the original takes the leftmost flagged gap


def _gap_entry(
    space: TaskSpace, row: Row, go: np.ndarray, frame: int, previous: int, *, faithful: bool
) -> _Entry:
    """The keypoint of the hand's passage through a gap of ``row`` at ``frame``."""
    if faithful and row.index > 1:
        # Row 2's gap direction starts where the 1-cm-rounded path is nearest the previous row.
        rounded_depth = np.round(go[:, 0] / ROUNDING) * ROUNDING
        origin = int(np.argmin(np.abs(rounded_depth - space.rows[row.index - 2].x)))
        return _Entry("gap", row.index, frame, origin, rounded=True)
    return _Entry("gap", row.index, frame, 0 if row.index == 1 else previous)


def _row_entries(
    space: TaskSpace,
    moved: dict[int, str],
    periods: dict[str, tuple[int, int]],
    tracks: dict[str, np.ndarray],
    go: np.ndarray,
    *,
    faithful: bool,
) -> tuple[list[_Entry], list[RowDecision], int]:
    """The keypoint entries (reference 3.6) and the decision of every row, nearest first, and the
    frame of the last row's last keypoint."""
    entries: list[_Entry] = []
    decisions = []
    previous = 0  # frame of the previous row's last keypoint
    for row in space.rows:
        name = moved.get(row.index)
        if name is not None:
            row_entries, decision = _object_row(
                space, row, name, periods[name], tracks[name], previous, faithful=faithful
            )
            entries += row_entries
            decisions.append(decision)
            previous = row_entries[-1].frame
            continue
        gaps = space.gaps[row.index - 1]
        passage = _gap_passage(go, row, gaps, faithful=faithful)
        if passage is None:
            decisions.append(RowDecision(row.index, NONE))
            continue
        frame, index = passage
        entries.append(_gap_entry(space, row, go, frame, previous, faithful=faithful))
        decisions.append(RowDecision(row.index, GAP, gap=gaps[index].index))
        previous = frame
    return entries, decisions, previous


def _keypoint_direction(entries: list[_Entry], k: int, hand: np.ndarray, *, faithful: bool) -> str | None:
    """Direction class of the hand's move to keypoint ``k`` (k > 0): from the previous keypoint,
    or in faithful mode from the entry's origin (on the 1-cm-rounded path if it says so)."""
    entry, before = entries[k], entries[k - 1].frame
    if not faithful:
        return direction_of(*(hand[entry.frame] - hand[before]))
    if entry.rounded:
        a, b = (np.round(hand[f] / ROUNDING) * ROUNDING for f in (entry.origin, entry.frame))
        return direction_of(*(b - a), faithful=True)
    return direction_of(*(hand[entry.frame] - hand[entry.origin]), faithful=True)


def _keypoints(
    entries: list[_Entry],
    tracks: dict[str, np.ndarray],
    lengths: LinkLengths,
    medial: np.ndarray,
    goal: int,
    *,
    faithful: bool,
) -> list[Keypoint]:
    """The keypoints of ``entries``: hand position, direction, arm angles and the hand's
    displacement from the previous keypoint in arm lengths."""
    hand, elbow, shoulder = tracks["hand"], tracks["elbow"], tracks["upper_arm"]
    keypoints = []
    for k, entry in enumerate(entries):
        frame = entry.frame
        if k == 0:
            direction, displacement = None, (0.0, 0.0)
        else:
            direction = _keypoint_direction(entries, k, hand, faithful=faithful)
            # The original's last displacement ends at the goal frame, not the target keypoint.
            end = goal if (faithful and entry.kind == "target") else frame
            step = (hand[end] - hand[entries[k - 1].frame]) / lengths.total
            displacement = (float(step[0]), float(step[1]))
        q = arm_angles(shoulder[frame], elbow[frame], hand[frame], medial)
        keypoints.append(
            Keypoint(
                entry.kind,
                entry.row,
                frame,
                (float(hand[frame, 0]), float(hand[frame, 1])),
                direction,
                (float(q[0]), float(q[1])),
                displacement,
            )
        )
    return keypoints


def segment_trial(
    trial: Trial, *, mode: Mode = DEFAULT_MODE, space: TaskSpace | None = None
) -> Demonstration:
    """Segment one successful demonstration.

    Args:
        trial: a loaded trial.
        mode: "fixed" (the paper's intent) or "faithful" (the released code, bugs included).
        space: the task space of ``trial.scene`` if already built.

    Raises:
        Rejected: the trial cannot be segmented (bad tracks, or the original's rejection rules).
    """
    faithful = is_faithful(mode)
    space = space or TaskSpace(trial.scene)
    target_name = trial.scene.target.name
    row_of = {name: row.index for row in space.rows for name in row.members}
    moved = first_moved_per_row(trial.interactions, row_of, faithful=faithful)
    tracks = _checked_tracks(trial, [*moved.values(), target_name])
    hand = tracks["hand"]

    # 3.1 go part: up to the closest approach to the target.
    target_xy = np.array([trial.scene.target.x, trial.scene.target.y])
    goal = int(np.argmin(np.sum((hand - target_xy) ** 2, axis=1)))
    go = hand[: goal + 1]

    # 3.3 gap passage flags.
    gap_flags = tuple(tuple(bool(_inside(go, gap.rect).any()) for gap in gaps) for gaps in space.gaps)

    periods = _motion_periods(tracks, moved, target_name, faithful=faithful)
    lengths = link_lengths(tracks["upper_arm"], tracks["elbow"], hand)
    row_entries, decisions, previous = _row_entries(space, moved, periods, tracks, go, faithful=faithful)
    target = _Entry("target", None, min(periods[target_name][0], goal), previous)
    entries = [_Entry("start", None, 0, 0), *row_entries, target]

    # Directions, arm angles and normalised displacements.
    medial = medial_direction(trial.record.handedness == "left", faithful=faithful)
    keypoints = _keypoints(entries, tracks, lengths, medial, goal, faithful=faithful)
    return Demonstration(
        key=trial.key,
        mode=mode,
        scene=trial.scene,
        left_handed=trial.record.handedness == "left",
        decisions=tuple(decisions),
        keypoints=tuple(keypoints),
        gap_flags=gap_flags,
        link_lengths=lengths,
        goal_frame=goal,
        hand_path=go.copy(),
    )
