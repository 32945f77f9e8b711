"""Training-scene augmentation for the row-choice classifier: a row seen in a mirror.

A scene reflected across the table's centre line (y -> -y) asks the same question with left and
right swapped: its gaps and obstacles come in the opposite order and every lateral quantity that
keeps a side changes sign. Every other feature of ``ROW_CONTEXT_FEATURES`` is a length, an angle's
size or a free fraction (of the mean of all eight direction blocks, or the lesser of the two
sideways ones) and stays as it is. So a candidate's mirror image is its features with the signed
columns negated (``mirror_features``), and the person's choice stays the label: a person who took
the gap on the left takes the mirrored gap on the right.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hlp_drake.features.row_choice import ROW_CONTEXT_FEATURES
from hlp_drake.scene.model import Scene, SceneObject
from hlp_drake.taskspace import TaskSpace

SIGNED_FEATURES = ("signed_offset", "target_offset")
"""The row-choice features that keep a side (positive: to the left), negated in a mirror."""
SIGNED_COLUMNS = tuple(ROW_CONTEXT_FEATURES.index(name) for name in SIGNED_FEATURES)


def mirror_features(X: np.ndarray) -> np.ndarray:
    """The row-choice features ``X`` (n, k) of the candidates seen in a mirror (a copy)."""
    mirrored = np.array(X, dtype=float, copy=True)
    mirrored[:, list(SIGNED_COLUMNS)] *= -1.0
    return mirrored


def mirror_scene(scene: Scene) -> Scene:
    """``scene`` reflected across the table's centre line (y -> -y; yaws negated)."""

    def reflected(o: SceneObject) -> SceneObject:
        return replace(o, y=-o.y, yaw=-o.yaw)

    return replace(
        scene,
        start=(scene.start[0], -scene.start[1]),
        start_yaw=-scene.start_yaw,
        target=reflected(scene.target),
        obstacles=tuple(reflected(o) for o in scene.obstacles),
    )


def mirrored_rows(X: np.ndarray, y: np.ndarray, *rest: np.ndarray) -> tuple[np.ndarray, ...]:
    """The rows ``X`` with their labels ``y`` and any per-row arrays ``rest`` (subjects, keys,
    weights), followed by the same rows in a mirror (same labels, same subjects)."""
    return (
        np.vstack([X, mirror_features(X)]),
        np.concatenate([y, y]),
        *(np.concatenate([r, r]) for r in rest),
    )


def perturbed_scene(
    scene: Scene, rng: np.random.Generator, *, position: float = 0.01, size: float = 0.1
) -> Scene:
    """``scene`` with every obstacle moved by up to ``position`` (m, each axis, uniform) and its
    footprint scaled by up to ``size`` (a share, each side, uniform); the start, the target and
    the table as they were."""
    shift = rng.uniform(-position, position, (len(scene.obstacles), 2))
    scale = 1.0 + rng.uniform(-size, size, (len(scene.obstacles), 2))
    return replace(
        scene,
        obstacles=tuple(
            replace(
                o,
                x=o.x + dx,
                y=o.y + dy,
                size=(o.size[0] * sx, o.size[1] * sy, o.size[2])
                if o.shape == "box"
                else (o.size[0] * sx, o.size[1] * sx, o.size[2]),
            )
            for o, (dx, dy), (sx, sy) in zip(scene.obstacles, shift, scale)
        ),
    )


def same_layout(a: TaskSpace, b: TaskSpace) -> bool:
    """Whether two task spaces have the same rows with the same members in the same order and the
    same number of gaps in each: a person's decisions (a gap by its index, an obstacle by its
    name) mean the same in both."""
    return [r.members for r in a.rows] == [r.members for r in b.rows] and [len(g) for g in a.gaps] == [
        len(g) for g in b.gaps
    ]
