"""The receding-horizon controller in a world: the tests' harness (``run_controller``)."""

from __future__ import annotations

from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.systems.execution.receding_horizon import RecedingHorizonController
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.result import LowLevelResult
from hlp_drake.systems.low_level.sto.planner import StoPlanner
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.perception.system import add_scene_perception
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.scene_source import SceneFromPlant
from hlp_drake.systems.world.world import connect_robot_command, make_world_diagram, world_plant


def run_controller(
    scenario: Scenario, sequence: ControlSequence, until: float, *, outcome=None, initialiser=None
):
    """Simulate the world driven by the controller (its initial optimisation ``sequence``, whose
    rollout had ``outcome``) to ``until``; the controller observes the scene through the
    scenario's source (``SceneFromPlant``, or ``ScenePerception`` on the world's cameras).
    Returns the controller's record, its command at ``until`` and the robot's positions."""
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scenario))
    plant, robot = world_plant(world)
    with RolloutPool(1) as pool:
        controller = builder.AddNamedSystem("controller", controller_of(scenario, plant, pool, initialiser))
        if scenario.perception.source == "camera":
            source = add_scene_perception(builder, world, template=scenario.scene, config=scenario.perception)
            builder.Connect(source.get_perception_output_port(), controller.GetInputPort("perception"))
        else:
            source = builder.AddNamedSystem("scene_from_plant", SceneFromPlant(plant, scenario.scene))
            builder.Connect(world.GetOutputPort("body_poses"), source.get_body_poses_input_port())
        builder.Connect(world.GetOutputPort("state"), controller.GetInputPort("state"))
        builder.Connect(source.get_scene_output_port(), controller.GetInputPort("scene"))
        connect_robot_command(builder, world, controller.GetOutputPort("desired_trajectory_state"), name="c")
        simulator = Simulator(builder.Build())
        context = simulator.get_mutable_context()
        controller.GetInputPort("initial").FixValue(
            controller.GetMyMutableContextFromRoot(context), LowLevelResult(sequence, outcome, True, None)
        )
        simulator.AdvanceTo(until)
        record = controller.record(context)
        desired = controller.GetOutputPort("desired_trajectory_state").Eval(
            controller.GetMyContextFromRoot(context)
        )
        q = plant.GetPositions(plant.GetMyContextFromRoot(context), robot)
    return record, desired, q


def controller_of(
    scenario: Scenario, plant, pool: RolloutPool, initialiser=None
) -> RecedingHorizonController:
    """The receding-horizon controller of ``scenario`` (its STO, closed loop, robot and measured
    objects: all of them unless the cameras see the scene)."""
    camera = scenario.perception.source == "camera"
    planner = StoPlanner.of(
        scenario.low_level, pool=pool, model=scenario.world_model, perceived=camera, success=scenario.success
    )
    return RecedingHorizonController(
        plant,
        planner=planner,
        closed_loop=scenario.closed_loop,
        robot=scenario.robot.name,
        objects=() if camera else tuple(o.name for o in scenario.scene.objects),
        initialiser=initialiser,
    )
