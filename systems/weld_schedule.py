"""Which objects a reduced rollout keeps welded when: ``WeldSchedule`` (the commanded sweep) or ``FixedWelds``.

A reduced rollout starts with the objects welded that the robot's collision geometry, following the
commanded motion (``Sweep.approach_times``), does not come within ``optimiser.weld_clearance`` of in
the next ``optimiser.weld_lookahead`` seconds, and frees them as that changes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet

from hlp_drake.systems.control_sequence import ControlSequence

if TYPE_CHECKING:
    from hlp_drake.systems.rollout_world import RolloutWorld


@dataclass(frozen=True)
class FixedWelds:
    """The same objects welded throughout."""

    welded: frozenset[str]

    def welded_at(self, t: float) -> frozenset[str]:
        return self.welded


@dataclass(frozen=True)
class WeldSchedule:
    """The objects welded from time ``t`` on: those the commanded motion does not come near before
    ``t + lookahead`` (``approach``: the first time it comes near each, inf if never)."""

    approach: dict[str, float]
    lookahead: float

    def welded_at(self, t: float) -> frozenset[str]:
        return frozenset(name for name, first in self.approach.items() if first > t + self.lookahead)


class Sweep:
    """The robot's collision geometry following a commanded motion through a full world's scene, the
    objects at their scene poses, in a context of its own where SceneGraph checks robot-object pairs only."""

    def __init__(self, world: RolloutWorld) -> None:
        self._world = world
        context = world.diagram.CreateDefaultContext()
        scene_graph = world.world.GetSubsystemByName("scene_graph")
        geometries = {"robot": [], "objects": [], "table": []}
        for g, body in world.geometry_body.items():
            kind = (
                "robot"
                if body in world.robot_bodies
                else "objects"
                if body in world.object_bodies
                else "table"
            )
            geometries[kind].append(g)
        robot, objects, table = (GeometrySet(geometries[k]) for k in ("robot", "objects", "table"))
        scene_graph.collision_filter_manager(scene_graph.GetMyMutableContextFromRoot(context)).Apply(
            CollisionFilterDeclaration()
            .ExcludeWithin(robot)
            .ExcludeWithin(objects)
            .ExcludeBetween(robot, table)
            .ExcludeBetween(objects, table)
        )
        self._context = context

    def approach_times(self, sequence: ControlSequence, clearance: float) -> dict[str, float]:
        """Per object, the first time the robot's collision geometry comes within ``clearance`` of it
        when following ``sequence``'s commanded motion exactly, the objects at their scene poses
        (checked every sample period and at every knot; inf if never)."""
        world = self._world
        plant_context = world.plant.GetMyMutableContextFromRoot(self._context)
        world_context = world.world.GetMyContextFromRoot(self._context)
        query = world.world.GetOutputPort("query_object")
        trajectory = sequence.to_trajectory()
        names = {int(b.index()): b.name() for b in world.objects}
        first = {obj.name: math.inf for obj in world.scene.objects}
        period = world.scenario.optimiser.sample_period
        times = np.union1d(sequence.times, np.arange(0.0, sequence.duration, period))
        for t in times:
            world.plant.SetPositions(plant_context, world.robot, trajectory.value(t).ravel())
            for pair in query.Eval(world_context).ComputeSignedDistancePairwiseClosestPoints(clearance):
                for g in (pair.id_A, pair.id_B):
                    name = names.get(world.geometry_body[g])
                    if name is not None and first[name] == math.inf:
                        first[name] = float(t)
        return first
