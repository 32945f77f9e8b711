"""A known scene for the perception's tests (``SCENE``, its camera ``CAMERA``, ``SCENARIO``) and
``ScenePerception`` on fixed frames (``perceive_fixed``) or on the frame a world renders
(``perceive_rendered``)."""

from __future__ import annotations

from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.systems.perception.cameras import CameraConfig, PerceptionConfig
from hlp_drake.systems.perception.system import ScenePerception
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.world import make_world_diagram

CAMERA = CameraConfig(width=320, height=240, depth_noise=0.001, dropout=0.01, seed=4)
SCENE = Scene(
    name="perceived",
    table=Table(length=0.8, width=0.9, height=0.75),
    start=(0.1, 0.0),
    target=SceneObject("Target", "cylinder", 0.6, 0.1, (0.066, 0.066, 0.12)),
    obstacles=(
        SceneObject("tilted_box", "box", 0.35, -0.2, (0.06, 0.15, 0.10), yaw=0.4),
        SceneObject("box", "box", 0.55, -0.15, (0.08, 0.05, 0.14)),
        SceneObject("can", "cylinder", 0.3, 0.2, (0.07, 0.07, 0.09)),
    ),
)
SCENARIO = Scenario(scene=SCENE, perception=PerceptionConfig(source="camera", cameras=(CAMERA,)))


def perceive_fixed(depth, labels, pose, scenario: Scenario = SCENARIO):
    """``ScenePerception``'s ``perception`` and ``scene`` outputs with its inputs fixed."""
    block = ScenePerception(template=scenario.scene, config=scenario.perception)
    context = block.CreateDefaultContext()
    name = scenario.perception.cameras[0].name
    block.GetInputPort(f"{name}.depth_image").FixValue(context, depth)
    block.GetInputPort(f"{name}.label_image").FixValue(context, labels)
    block.GetInputPort(f"{name}.camera_pose").FixValue(context, pose)
    return block.get_perception_output_port().Eval(context), block.get_scene_output_port().Eval(context)


def perceive_rendered(scenario: Scenario):
    """``perceive_fixed`` on the frame the world of ``scenario`` renders with its first camera."""
    context = (world := make_world_diagram(scenario)).CreateDefaultContext()
    name = scenario.perception.cameras[0].name
    ports = [
        world.GetOutputPort(f"{name}.{p}").Eval(context)
        for p in ("depth_image", "label_image", "camera_pose")
    ]
    return perceive_fixed(*ports, scenario)
