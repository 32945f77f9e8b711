"""``ScenePerception``: depth images and camera poses in, the ``Scene`` out; a drop-in alternative to
``SceneFromPlant`` as the planning blocks' scene source.

How a frame becomes a scene: ``hlp_drake.systems.perception.perception``. ``add_scene_perception`` wires the
block to a world's cameras.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.perception import BaseField, Fields, PointCloud
from pydrake.systems.framework import Context, Diagram, DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.sensors import ImageDepth32F, ImageLabel16I

from hlp_drake.scene.model import Scene
from hlp_drake.systems.perception.cameras import PerceptionConfig, camera_info
from hlp_drake.systems.perception.depth_points import CameraView
from hlp_drake.systems.perception.perception import Perception, perceive, unperceived_scene
from hlp_drake.systems.world.scene_source import MODEL_SCENE, SCENE_PORT
from hlp_drake.systems.world.world import make_world_diagram

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.systems.world.uncertainty import WorldPerturbation

CAMERA_PORTS = ("depth_image", "label_image", "camera_pose")
CLASS_COLOURS = np.array([[150, 150, 150], [230, 120, 20], [20, 20, 20], [60, 60, 200]], dtype=np.uint8)
"""The point cloud's colours by class: table, objects, stray points above the table, the rest."""


def perception_cloud(perception: Perception) -> PointCloud:
    """The frame's world points as a Drake ``PointCloud`` coloured by class (``CLASS_COLOURS``)."""
    cloud = PointCloud(len(perception.cloud), Fields(BaseField.kXYZs | BaseField.kRGBs))
    cloud.mutable_xyzs()[:] = perception.cloud.T
    cloud.mutable_rgbs()[:] = CLASS_COLOURS[perception.cloud_class].T
    return cloud


class ScenePerception(LeafSystem):
    """The scene from the cameras of ``config`` (see ``hlp_drake.systems.perception.perception``).

    Input ports, per camera N of ``config.cameras`` (the world's ports of the same names):
    ``N.depth_image`` (``ImageDepth32F``), ``N.label_image`` (``ImageLabel16I``), ``N.camera_pose``
    (``RigidTransform``). Output ports: ``scene`` (abstract ``Scene``, for the planning blocks),
    ``perception`` (abstract ``Perception``: the objects, the reason of a failure, the time) and
    ``point_cloud`` (a Drake ``PointCloud`` of the frame, coloured by class). Evaluated on demand
    and cached until an input changes.

    Args:
        template: of this scene only the start, start heading and name are used (the robot's own);
            its target's name names the perceived target.
        config: the cameras and the perception's settings (a ``Scenario``'s ``perception``).
    """

    def __init__(self, *, template: Scene, config: PerceptionConfig | None = None) -> None:
        super().__init__()
        self._config = config or PerceptionConfig()
        self._template = template
        self._cameras = self._config.cameras
        self._info = [camera_info(c) for c in self._cameras]
        self._inputs = []
        for camera in self._cameras:
            models = (
                ImageDepth32F(camera.width, camera.height),
                ImageLabel16I(camera.width, camera.height),
                RigidTransform(),
            )
            self._inputs.append(
                [
                    self.DeclareAbstractInputPort(
                        name=f"{camera.name}.{port}", model_value=AbstractValue.Make(model)
                    )
                    for port, model in zip(CAMERA_PORTS, models)
                ]
            )
        ticket = {self.all_input_ports_ticket()}
        self._perception = self.DeclareAbstractOutputPort(
            name="perception",
            alloc=lambda: AbstractValue.Make(Perception(None, "not perceived yet")),
            calc=self._calc_perception,
            prerequisites_of_calc=ticket,
        )
        self._scene = self.DeclareAbstractOutputPort(
            name=SCENE_PORT,
            alloc=lambda: AbstractValue.Make(MODEL_SCENE),
            calc=lambda context, output: output.set_value(self._perception.Eval(context).scene),
            prerequisites_of_calc=ticket,
        )
        self._cloud = self.DeclareAbstractOutputPort(
            name="point_cloud",
            alloc=lambda: AbstractValue.Make(PointCloud()),
            calc=lambda context, output: output.set_value(perception_cloud(self._perception.Eval(context))),
            prerequisites_of_calc=ticket,
        )

    def get_scene_output_port(self) -> OutputPort:
        return self._scene

    def get_perception_output_port(self) -> OutputPort:
        return self._perception

    def get_point_cloud_output_port(self) -> OutputPort:
        return self._cloud

    def _views(self, context: Context) -> list[CameraView] | str:
        """The cameras' frames, or why one cannot be read (an image of the wrong size).

        Raises:
            RuntimeError: an input is neither connected nor fixed (a wiring error).
        """
        views = []
        for camera, info, ports in zip(self._cameras, self._info, self._inputs):
            for port in ports:
                if not port.HasValue(context):
                    raise RuntimeError(
                        f"{self.get_name() or 'ScenePerception'}: connect or fix {port.get_name()}"
                    )
            depth, labels, pose = (port.Eval(context) for port in ports)
            size = (camera.width, camera.height)
            for what, image in (("depth", depth), ("label", labels)):
                if (image.width(), image.height()) != size:
                    return (
                        f"camera {camera.name}: its {what} image is {image.width()} x {image.height()}, "
                        f"its settings say {size[0]} x {size[1]}"
                    )
            views.append(
                CameraView(np.asarray(depth.data)[:, :, 0], np.asarray(labels.data)[:, :, 0], pose, info)
            )
        return views

    def _calc_perception(self, context: Context, output: AbstractValue) -> None:
        views = self._views(context)
        if isinstance(views, str):
            output.set_value(Perception(unperceived_scene(self._template), views))
            return
        output.set_value(perceive(views, self._config, self._template))


def add_scene_perception(
    builder: DiagramBuilder, world: Diagram, *, template: Scene, config: PerceptionConfig
) -> ScenePerception:
    """Add a ``ScenePerception(template=template, config=config)`` named ``scene_perception`` fed by
    ``world``'s cameras (the world must have ``config.cameras``, e.g. ``make_world_diagram(...,
    cameras=True)``, and be in ``builder`` already)."""
    block = builder.AddNamedSystem("scene_perception", ScenePerception(template=template, config=config))
    for camera in config.cameras:
        for port in CAMERA_PORTS:
            name = f"{camera.name}.{port}"
            builder.Connect(world.GetOutputPort(name), block.GetInputPort(name))
    return block


def perceive_world(
    scenario: Scenario, *, model_error: WorldPerturbation | None = None
) -> tuple[Perception, float]:
    """One frame of ``scenario``'s cameras on its world at the start (``model_error``: the world's
    own differences from the scenario) and the seconds its rendering and perception took; the
    world is built for this frame only, so a world executed open loop need not carry the cameras."""
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scenario, cameras=True, model_error=model_error))
    block = add_scene_perception(builder, world, template=scenario.scene, config=scenario.perception)
    context = builder.Build().CreateDefaultContext()
    started = time.perf_counter()
    perception = block.get_perception_output_port().Eval(block.GetMyContextFromRoot(context))
    return perception, time.perf_counter() - started


__all__ = ["CAMERA_PORTS", "ScenePerception", "add_scene_perception", "perceive_world", "perception_cloud"]
