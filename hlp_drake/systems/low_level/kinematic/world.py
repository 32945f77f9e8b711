"""``KinematicWorld``: the robot, the table and the scene's objects welded in place, for collision
checking (Drake's ``SceneGraphCollisionChecker``) and minimum-distance constraints.

The robot may touch the ``allowed`` objects (what the plan pushes): their collision pairs with the
robot are filtered out in the model's SceneGraph, so the checker, the distance constraints and the
clearance queries all treat them as free space. Every other object and the table are obstacles,
unless a leg of the path lets the robot touch it (``touching``: the target on the leg onto it).
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import cached_property

import numpy as np
from pydrake.common import Parallelism
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet
from pydrake.planning import RobotDiagramBuilder, SceneGraphCollisionChecker

from hlp_drake.scene.model import Scene
from hlp_drake.systems.world.model import WorldModel
from hlp_drake.systems.world.robot import add_robot, robot_joint_limits
from hlp_drake.systems.world.scene_models import add_scene


class KinematicWorld:
    """``scene``'s table and objects (welded) and ``model``'s robot; the robot may touch ``allowed``.

    Args:
        scene: the scene as the planner sees it.
        model: the robot and how the scene becomes bodies.
        allowed: names of the objects the robot may touch throughout (unknown names and the
            target's are ignored: see ``touching``).
        edge_step: the checker's step along a straight motion, rad or m of the positions.
        padding: clearance the checker adds around the obstacles, m.
    """

    def __init__(
        self,
        scene: Scene,
        model: WorldModel,
        allowed: Iterable[str] = (),
        *,
        edge_step: float = 0.02,
        padding: float = 0.0,
    ) -> None:
        builder = RobotDiagramBuilder(time_step=0.0)
        plant = builder.plant()
        self.robot = add_robot(plant, model.robot)
        self.scene_models = add_scene(
            plant, scene, contact=model.contact, bodies=model.bodies, weld_objects=True
        )
        plant.Finalize()
        self.allowed = frozenset(
            name for name in allowed if name in self.scene_models.objects and name != scene.target.name
        )
        robot_geometries = self._geometries(plant, [self.robot])
        allowed_geometries = self._geometries(plant, [self.scene_models.objects[n] for n in self.allowed])
        if allowed_geometries:
            builder.scene_graph().collision_filter_manager().Apply(
                CollisionFilterDeclaration().ExcludeBetween(
                    GeometrySet(robot_geometries), GeometrySet(allowed_geometries)
                )
            )
        self.diagram = builder.Build()
        self.plant = self.diagram.plant()
        self.checker = SceneGraphCollisionChecker(
            model=self.diagram,
            robot_model_instances=[self.robot],
            edge_step_size=edge_step,
            env_collision_padding=padding,
            self_collision_padding=0.0,
            implicit_context_parallelism=Parallelism(1),
        )
        self.description = model.robot
        self._robot_geometries = GeometrySet(robot_geometries)
        self._robot_bodies = [self.plant.get_body(b) for b in self.plant.GetBodyIndices(self.robot)]
        self._others = {
            name: (
                [self.plant.get_body(b) for b in self.plant.GetBodyIndices(instance)],
                GeometrySet(self._geometries(self.plant, [instance])),
            )
            for name, instance in self.scene_models.objects.items()
            if name not in self.allowed
        }
        self._touched: set[str] = set()
        self._filters = np.array(self.checker.GetFilteredCollisionMatrix())
        self._robot_indices = [int(body.index()) for body in self._robot_bodies]
        self._diagram_context = self.diagram.CreateDefaultContext()
        self.plant_context = self.plant.GetMyContextFromRoot(self._diagram_context)
        """A context of the plant in its diagram (with the SceneGraph's): for distance constraints."""

    def touching(self, names: Iterable[str] = ()) -> None:
        """Let the robot touch the objects ``names`` besides ``allowed`` from now on (and no others)."""
        names = {name for name in names if name in self._others}
        changed, self._touched = names ^ self._touched, names  # only what changes is filtered anew
        scene_graph = self.diagram.scene_graph()
        manager = scene_graph.collision_filter_manager(
            scene_graph.GetMyMutableContextFromRoot(self._diagram_context)
        )
        if not changed:
            return
        matrix = self._filters.copy()  # the checker's: one update, not one per pair of bodies
        for name in names:
            for body in self._others[name][0]:
                matrix[self._robot_indices, int(body.index())] = 1
                matrix[int(body.index()), self._robot_indices] = 1
        self.checker.SetCollisionFilterMatrix(matrix)
        for name in changed:
            declaration = CollisionFilterDeclaration()
            if name in names:
                declaration.ExcludeBetween(self._robot_geometries, self._others[name][1])
            else:
                declaration.AllowBetween(self._robot_geometries, self._others[name][1])
            manager.Apply(declaration)

    @staticmethod
    def _geometries(plant, instances) -> list:
        return [
            geometry
            for instance in instances
            for body in plant.GetBodyIndices(instance)
            for geometry in plant.GetCollisionGeometriesForBody(plant.get_body(body))
        ]

    @cached_property
    def planned_columns(self) -> np.ndarray:
        """Columns of the robot's positions a path plans (all but the fingers, which it carries)."""
        fingers = set(self.description.finger_columns)
        return np.array([i for i in range(len(self.description.position_names)) if i not in fingers])

    @cached_property
    def limits(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lower, upper, velocity) limits of the robot's positions (the mimic fingers as the driven one)."""
        limits = robot_joint_limits(self.plant, self.robot)
        mimics = len(self.description.mimic_joints)
        return tuple(np.concatenate([a, np.repeat(a[-1:], mimics)]) for a in limits)

    def free(self, q: np.ndarray) -> bool:
        """Whether the robot at ``q`` touches no obstacle."""
        return bool(self.checker.CheckConfigCollisionFree(q))

    def edge_free(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the straight motion from ``a`` to ``b`` touches no obstacle (checked at ``edge_step``)."""
        return bool(self.checker.CheckEdgeCollisionFree(a, b))

    def contacts(self, q: np.ndarray, influence: float = 0.02) -> list[tuple[str, float]]:
        """The obstacles the robot at ``q`` touches (name, signed distance < 0), nearest first."""
        report = self.checker.CalcRobotClearance(q, influence)
        found: dict[str, float] = {}
        for distance, other in zip(report.distances(), report.other_indices()):
            if distance < 0:
                name = self.plant.get_body(other).name()
                found[name] = min(distance, found.get(name, 0.0))
        return sorted(found.items(), key=lambda item: item[1])

    def clearance(self, q: np.ndarray, influence: float = 0.05) -> float:
        """The robot's smallest signed distance to an obstacle at ``q`` (``influence`` if none is nearer)."""
        distances = self.checker.CalcRobotClearance(q, influence).distances()
        return float(np.min(distances)) if len(distances) else influence

    def tcp(self, q: np.ndarray) -> np.ndarray:
        """The tcp's position in the world at ``q``."""
        context = self.plant_context
        self.plant.SetPositions(context, self.robot, np.asarray(q, dtype=float))
        frame = self.plant.GetFrameByName(self.description.tcp_frame, self.robot)
        return frame.CalcPoseInWorld(context).translation()


__all__ = ["KinematicWorld"]
