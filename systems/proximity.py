"""``ProximityContext``: a world's SceneGraph in a context of its own that checks only some pairs.

The checks of a rollout (``sleep_schedule``, ``rollout_sampler``) ask which bodies come near which:
the robot and the objects. Their distance queries need neither the table nor the objects' support
spheres (each lies inside its object's shape, so the shape is never farther than a sphere is) nor
the robot's own links, and SceneGraph's collision filters, in a context apart from the simulation's,
leave those out: the query returns one pair per body pair near each other rather than dozens.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet

from hlp_drake.systems.scene_models import is_support_geometry

if TYPE_CHECKING:
    from pydrake.systems.framework import Diagram

    from hlp_drake.systems.rollout_world import RolloutWorld


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
