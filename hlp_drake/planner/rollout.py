"""Steps 4-5 of the planner: each path's keypoints, the arm configurations along them and the
arm's expected collision.

Paths share prefixes (the same first rows), and everything at a keypoint depends on its prefix
only, so arms and arm sweeps are computed once per distinct prefix (a node of the ``PrefixTree``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.features import DIRECTION_FEATURES, direction_index
from hlp_drake.features.direction import DirectionTable
from hlp_drake.features.segment import path_occluders
from hlp_drake.planner.human_arm import arm_joints, sweep_collision
from hlp_drake.planner.plan import PlanKeypoint
from hlp_drake.segmentation.modes import Mode
from hlp_drake.taskspace import DIRECTIONS, Node, TaskSpace, direction_of
from hlp_drake.taskspace.relocation import relocated_array

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels


def path_keypoints(
    space: TaskSpace,
    models: DecisionModels,
    candidates: list[list[Node]],
    paths: list[tuple[int, ...]],
    mode: Mode,
) -> list[list[PlanKeypoint]]:
    """Each path's keypoints: start, per row its gap or its obstacle's move and release (the
    direction by Cd from the hand's previous keypoint), target.

    Cd is asked once for every candidate obstacle and approach direction class; equal keypoints
    are one shared object.
    """
    first = PlanKeypoint("start", tuple(float(v) for v in space.scene.start))
    last = PlanKeypoint("target", space.target.center, None, space.scene.target.name)
    names = list(dict.fromkeys(n.obstacle for nodes in candidates for n in nodes if n.kind == "object"))
    if names:
        table = DirectionTable(space, names, mode=mode)
        hands = np.arange(-1, len(DIRECTIONS))  # every approach class, undefined (-1) first
        X = table.features(np.arange(len(names))[:, None], hands[None, :]).reshape(
            -1, len(DIRECTION_FEATURES)
        )
        labels = models.direction.predict(X).reshape(len(names), len(hands)).tolist()
        index = {name: k for k, name in enumerate(names)}
        regions = relocated_array(
            space.obstacle_bounds[[space.obstacle_index[n] for n in names]], space.alpha
        )
        releases = np.stack(
            [(regions[..., 0] + regions[..., 2]) / 2.0, (regions[..., 1] + regions[..., 3]) / 2.0], axis=-1
        ).tolist()

    @cache
    def gap(node: Node) -> PlanKeypoint:
        return PlanKeypoint("gap", node.center, node.row, node.element)

    @cache
    def move(node: Node, hand: tuple[float, float]) -> tuple[PlanKeypoint, PlanKeypoint]:
        k = index[node.obstacle]
        direction = DIRECTIONS[int(labels[k][direction_index(table.hand_direction(k, hand)) + 1])]
        release = tuple(releases[k][DIRECTIONS.index(direction)])
        return (
            PlanKeypoint("move", node.center, node.row, node.obstacle, direction),
            PlanKeypoint("release", release, node.row, node.obstacle, direction),
        )

    result = []
    for path in paths:
        keypoints = [first]
        for nodes, i in zip(candidates, path):
            node = nodes[i]
            if node.kind == "gap":
                keypoints.append(gap(node))
            else:
                keypoints += move(node, keypoints[-1].position)
        keypoints.append(last)
        result.append(keypoints)
    return result


@dataclass
class PrefixTree:
    """The distinct keypoint prefixes of paths that all begin with the same start keypoint.

    Attributes:
        keypoints: each node's last keypoint (node 0: the start); parents come before children.
        parent: each node's parent (-1 for node 0).
        paths: per path, its nodes after the start, in order.
    """

    keypoints: list[PlanKeypoint]
    parent: list[int]
    paths: list[list[int]]

    @classmethod
    def of(cls, keypoints: list[list[PlanKeypoint]]) -> PrefixTree:
        """The tree of ``keypoints`` (equal keypoints are shared objects, so identity decides)."""
        tree = cls([keypoints[0][0]], [-1], [])
        children: dict[tuple[int, int], int] = {}
        for path in keypoints:
            node, nodes = 0, []
            for keypoint in path[1:]:
                key = (node, id(keypoint))
                if key not in children:
                    children[key] = len(tree.parent)
                    tree.keypoints.append(keypoint)
                    tree.parent.append(node)
                node = children[key]
                nodes.append(node)
            tree.paths.append(nodes)
        return tree

    @cached_property
    def hands(self) -> np.ndarray:
        """(nodes, 2) each node's hand position."""
        return np.array([k.position for k in self.keypoints], dtype=float).reshape(-1, 2)


def arm_configurations(
    models: DecisionModels, tree: PrefixTree, q0: np.ndarray, arm_total: float, faithful: bool
) -> np.ndarray:
    """(nodes, 2) the arm (q1, q2) at each node's keypoint by Ra, from ``q0`` at the start."""
    hands = tree.hands
    step_class = cache(
        lambda a, b: direction_index(direction_of(b[0] - a[0], b[1] - a[1], faithful=faithful))
    )
    classes = [0] + [
        step_class(tree.keypoints[p].position, k.position)
        for p, k in zip(tree.parent[1:], tree.keypoints[1:])
    ]
    steps = (hands - hands[np.maximum(tree.parent, 0)]) / arm_total
    return models.arm.rollout(q0, tree.parent, np.column_stack([steps, classes]), limits=(0.0, np.pi))


def expected_collisions(
    space: TaskSpace,
    tree: PrefixTree,
    arms: np.ndarray,
    links: tuple[float, float],
    band: float,
    faithful: bool,
) -> list[float]:
    """Each path's expected arm collision: the summed sweeps of its motions; an obstacle it moves
    no longer counts from the motion reaching it on."""
    if len(tree.paths) == 1 and faithful:
        return [0.0]
    joints = arm_joints(tree.hands, arms, *links)
    occluders = path_occluders(space, faithful=faithful)
    mask = np.ones((len(tree.parent), len(occluders)), dtype=bool)
    gone: list[tuple[int, ...]] = [()]
    for node in range(1, len(tree.parent)):
        keypoint = tree.keypoints[node]
        moved = (space.obstacle_index[keypoint.element],) if keypoint.action == "move" else ()
        gone.append(gone[tree.parent[node]] + moved)
        mask[node, list(gone[node])] = False
    motion = sweep_collision(
        joints[tree.parent[1:]], joints[1:], occluders, mask[1:], band=band, faithful=faithful
    ).tolist()
    costs = []
    for nodes in tree.paths:
        cost = 0.0
        for node in nodes:
            cost += motion[node - 1]
        costs.append(cost)
    return costs
