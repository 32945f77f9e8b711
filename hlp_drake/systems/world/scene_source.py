"""Where planning blocks get the scene: one abstract ``scene`` input port, fed by ``SceneFromPlant``.

Every planning block that needs the scene (``HlpPlannerSystem``, the straight-line block,
``RobotPlanTransfer``, ``StochasticTrajectoryOptimiser``) takes it from its ``scene`` input port,
never from its constructor, so a diagram plans again when the scene changes. ``SceneFromPlant``
reads the scene from a plant's body poses; for a fixed scene, fix the port's value or use
Drake's ``ConstantValueSource``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context, InputPort, LeafSystem

from hlp_drake.scene.model import Scene, SceneObject, Table

SCENE_PORT = "scene"
MODEL_SCENE = Scene(
    Table(1.0, 1.0, 1.0), (0.0, 0.0), SceneObject("none", "cylinder", 0.5, 0.0, (0.1, 0.1, 0.1))
)
"""The ``scene`` ports' model value (a type for Drake, never planned on: an unconnected port is an error)."""
SAME_POSE = 1e-9
"""An object within this (m, rad) of its template pose keeps the template's numbers: the plant
stores orientations as quaternions, and a yaw's round trip through one is off by ~1e-16."""


def declare_scene_input_port(system: LeafSystem) -> InputPort:
    """Declare ``system``'s abstract ``scene`` input port (a ``Scene``)."""
    return system.DeclareAbstractInputPort(name=SCENE_PORT, model_value=AbstractValue.Make(MODEL_SCENE))


def scene_input(port: InputPort, context: Context) -> Scene:
    """The ``Scene`` on ``port``.

    Raises:
        RuntimeError: the port is neither connected nor fixed.
    """
    if not port.HasValue(context):
        system = port.get_system()
        raise RuntimeError(f"{system.get_name() or type(system).__name__}: connect or fix its 'scene' input")
    return port.Eval(context)


class SceneFromPlant(LeafSystem):
    """The scene as a plant's body poses show it: ``template`` with every object at its body's
    planar pose (the bodies are named after the objects, as ``add_scene`` names them).

    Input port ``body_poses`` (the plant's ``get_body_poses_output_port()``, a world's
    ``body_poses``); output port ``scene`` (abstract ``Scene``). Objects at their template poses
    (within ``SAME_POSE``) keep the template's numbers, so a resting scene reads back exactly.
    """

    def __init__(self, plant: MultibodyPlant, template: Scene) -> None:
        super().__init__()
        self._template = template
        self._bodies = {o.name: int(plant.GetBodyByName(o.name).index()) for o in template.objects}
        self._poses = self.DeclareAbstractInputPort(
            name="body_poses", model_value=AbstractValue.Make([RigidTransform()])
        )
        self._scene = self.DeclareAbstractOutputPort(
            name=SCENE_PORT,
            alloc=lambda: AbstractValue.Make(template),
            calc=self._calc_scene,
            prerequisites_of_calc={self.input_port_ticket(self._poses.get_index())},
        )

    def get_body_poses_input_port(self) -> InputPort:
        return self._poses

    def get_scene_output_port(self):
        return self._scene

    def _calc_scene(self, context: Context, output: AbstractValue) -> None:
        poses = self._poses.Eval(context)
        output.set_value(scene_at(self._template, {name: poses[i] for name, i in self._bodies.items()}))


def scene_at(template: Scene, poses: Mapping[str, RigidTransform]) -> Scene:
    """``template`` with every object at the planar part of its pose in ``poses`` (by name; world
    poses); objects within ``SAME_POSE`` of their template poses keep the template's numbers (and
    ``template`` itself comes back when all do)."""

    def placed(obj: SceneObject) -> SceneObject:
        pose = poses[obj.name]
        x, y, _ = pose.translation()
        rotation = pose.rotation().matrix()
        yaw = math.atan2(rotation[1, 0], rotation[0, 0])
        turn = math.remainder(yaw - obj.yaw, math.tau)
        if max(abs(x - obj.x), abs(y - obj.y), abs(turn)) <= SAME_POSE:
            return obj
        return obj.moved(float(x), float(y), float(yaw))

    target, obstacles = placed(template.target), tuple(placed(o) for o in template.obstacles)
    same = target is template.target and all(a is b for a, b in zip(obstacles, template.obstacles))
    return template if same else replace(template, target=target, obstacles=obstacles)
