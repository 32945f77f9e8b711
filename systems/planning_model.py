"""``PlanningModel``: the robot and the table (and the scene's objects, welded), for kinematics."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.systems.robot import add_robot
from hlp_drake.systems.scene_models import SceneModels, add_scene

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


class PlanningModel:
    """Robot + table (+ the objects welded at their scene poses), for kinematics (IK, distance queries).

    A continuous plant (no dynamics) with its SceneGraph in a Diagram; it holds no context (make one
    with ``diagram.CreateDefaultContext()``).

    Attributes:
        diagram, plant, scene_graph: the model.
        robot: the robot's model instance.
        scene_models: the table's and objects' model instances.
    """

    def __init__(self, scenario: Scenario, *, with_objects: bool = True) -> None:
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
        self.robot = add_robot(plant)
        self.scene_models: SceneModels = add_scene(
            plant,
            scenario.scene,
            contact=scenario.contact,
            bodies=scenario.bodies,
            weld_objects=True,
            with_objects=with_objects,
        )
        plant.Finalize()
        self.diagram = builder.Build()
        self.diagram.set_name("planning_model")
        self.plant: MultibodyPlant = plant
        self.scene_graph: SceneGraph = scene_graph

    def robot_geometries(self) -> list:
        return [
            geometry
            for body in self.plant.GetBodyIndices(self.robot)
            for geometry in self.plant.GetCollisionGeometriesForBody(self.plant.get_body(body))
        ]

    def object_geometries(self) -> list:
        return [
            geometry
            for instance in self.scene_models.objects.values()
            for body in self.plant.GetBodyIndices(instance)
            for geometry in self.plant.GetCollisionGeometriesForBody(self.plant.get_body(body))
        ]
