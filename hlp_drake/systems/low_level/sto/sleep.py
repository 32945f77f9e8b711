"""When a rollout's objects sleep: ``SleepSchedule`` (from the commanded sweep) or ``AWAKE`` (never).

A rollout starts with the objects asleep (their joints locked) that the robot's collision geometry,
following the commanded motion (``Sweep.approach_times``), does not come within
``planner.low_level.weld_clearance`` of in the next ``planner.low_level.weld_lookahead`` seconds, and wakes each
that long before the motion comes near it. Between, ``rollout_sampler`` wakes an object anything
comes near and puts objects that have come to rest back to sleep.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.world.scene_models import is_support_geometry

if TYPE_CHECKING:
    from pydrake.systems.framework import Diagram

    from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld


@dataclass(frozen=True)
class SleepSchedule:
    """The objects' first approach by the commanded motion (``approach``: s, inf if never) and how
    long before it an object is woken (``lookahead``); ``sleeping``: whether objects sleep at all."""

    approach: dict[str, float]
    lookahead: float
    sleeping: bool = True

    def initially_asleep(self) -> frozenset[str]:
        return frozenset(n for n, first in self.approach.items() if self.sleeping and first > self.lookahead)

    def due(self, t: float) -> frozenset[str]:
        """The objects to be awake by ``t`` (their approach is at most ``lookahead`` away)."""
        return frozenset(n for n, first in self.approach.items() if first <= t + self.lookahead)

    def approaching(self, t: float) -> frozenset[str]:
        """The objects not to put to sleep at ``t``: the motion comes near them within ``lookahead``."""
        return frozenset(n for n, first in self.approach.items() if t <= first <= t + self.lookahead)


AWAKE = SleepSchedule({}, 0.0, sleeping=False)
"""Every object awake throughout (the full model)."""


class Sweep:
    """The robot's collision geometry following a commanded motion through a full world's scene, the
    objects at their scene poses, in a ``ProximityContext`` of its own checking robot-object pairs only."""

    def __init__(self, world: RolloutWorld) -> None:
        self._world = world
        self._proximity = ProximityContext(world, objects_apart=True)

    def approach_times(
        self, sequence: ControlSequence, clearance: float, states: dict[str, np.ndarray] | None = None
    ) -> dict[str, float]:
        """Per object, the first time the robot's collision geometry comes within ``clearance`` of it
        when following ``sequence``'s commanded motion exactly, the objects at their scene poses or
        as ``states`` has them (a ``RolloutStart``'s; checked every sample period and at every knot;
        inf if never)."""
        world, proximity = self._world, self._proximity
        for body in world.objects:
            x = None if states is None else states.get(body.name())
            instance = body.model_instance()
            q = (
                world.plant.GetDefaultPositions(instance)
                if x is None
                else x[: world.plant.num_positions(instance)]
            )
            proximity.set_instance_positions(instance, q)
        trajectory = sequence.to_trajectory()
        names = {int(b.index()): b.name() for b in world.objects}
        first = {obj.name: math.inf for obj in world.scene.objects}
        period = world.spec.sto.sample_period
        times = np.union1d(sequence.times, np.arange(0.0, sequence.duration, period))
        for t in times:
            proximity.set_instance_positions(world.robot, trajectory.value(t).ravel())
            for pair in proximity.close_pairs(clearance):
                for body in pair[:2]:
                    name = names.get(body)
                    if name is not None and first[name] == math.inf:
                        first[name] = float(t)
        return first


# ``ProximityContext``: a world's SceneGraph in a context of its own that checks only some pairs.
#
# The checks of a rollout (``sleep_schedule``, ``rollout_sampler``) ask which bodies come near which:
# the robot and the objects. Their distance queries need neither the table nor the objects' support
# spheres (each lies inside its object's shape, so the shape is never farther than a sphere is) nor
# the robot's own links, and SceneGraph's collision filters, in a context apart from the simulation's,
# leave those out: the query returns one pair per body pair near each other rather than dozens.
class WorldGeometries(NamedTuple):
    """A world's proximity geometries by kind."""

    robot: GeometrySet
    objects: GeometrySet
    """The objects' shapes (their support spheres left out)."""
    supports: GeometrySet
    """The objects' support spheres."""
    table: GeometrySet


def world_geometries(world: RolloutWorld) -> WorldGeometries:
    """``world``'s proximity geometries by kind."""
    inspector = world.world.GetSubsystemByName("scene_graph").model_inspector()
    kinds: dict[str, list] = {kind: [] for kind in WorldGeometries._fields}
    for g, body in world.geometry_body.items():
        if body in world.robot_bodies:
            kinds["robot"].append(g)
        elif body in world.object_bodies:
            kinds["supports" if is_support_geometry(inspector, g) else "objects"].append(g)
        else:
            kinds["table"].append(g)
    return WorldGeometries(**{kind: GeometrySet(ids) for kind, ids in kinds.items()})


class ProximityContext:
    """``world``'s diagram in a context of its own, its SceneGraph checking only the robot-object and
    object-object pairs (the objects' shapes; with ``objects_apart``, robot-object pairs only).

    The plant's positions are set with ``set_positions``; the context holds nothing else."""

    def __init__(self, world: RolloutWorld, *, objects_apart: bool = False) -> None:
        geometries = world_geometries(world)
        diagram: Diagram = world.diagram
        self._context = diagram.CreateDefaultContext()
        self._plant = world.plant
        self._plant_context = world.plant.GetMyMutableContextFromRoot(self._context)
        scene_graph = world.world.GetSubsystemByName("scene_graph")
        everything = GeometrySet(list(world.geometry_body))
        declaration = (
            CollisionFilterDeclaration()
            .ExcludeWithin(geometries.robot)
            .ExcludeBetween(geometries.table, everything)
            .ExcludeBetween(geometries.supports, everything)
        )
        if objects_apart:
            declaration.ExcludeWithin(geometries.objects)
        scene_graph.collision_filter_manager(scene_graph.GetMyMutableContextFromRoot(self._context)).Apply(
            declaration
        )
        self._world_context = world.world.GetMyContextFromRoot(self._context)
        self._query = world.world.GetOutputPort("query_object")
        self._geometry_body = world.geometry_body

    def set_positions(self, q: np.ndarray) -> None:
        """Set the whole plant's positions (``MultibodyPlant.GetPositions``' order)."""
        self._plant.SetPositions(self._plant_context, q)

    def set_instance_positions(self, instance, q: np.ndarray) -> None:
        """Set one model instance's positions."""
        self._plant.SetPositions(self._plant_context, instance, q)

    def close_pairs(self, threshold: float) -> list[tuple[int, int, float]]:
        """(body, body, distance) of the checked geometry pairs within ``threshold`` (m) of each other."""
        pairs = self._query.Eval(self._world_context).ComputeSignedDistancePairwiseClosestPoints(threshold)
        body = self._geometry_body
        return [(body[p.id_A], body[p.id_B], p.distance) for p in pairs]
