"""``make_execution_diagram``: the world, the scene source, the planning diagram and what drives the
robot, built from one ``Scenario``, with named handles (``ExecutionDiagram``) for the run step.

The scene source feeds the planning diagram: ``SceneFromPlant`` on the world's body poses, or with
``perception.source: camera`` and a closed loop ``ScenePerception`` on the executed world's cameras.
Open loop with cameras, the planners plan on one frame perceived before the build
(``perceive_world``: the executed world renders nothing), given as ``planned_scene``; so they do under
model error without cameras (the scenario's scene, not the plant's). What drives the robot: open
loop a trajectory source (holding the start until the run gives it the optimised sequence), closed
loop (``scenario.closed_loop.enabled``) a ``RecedingHorizonController`` re-planning with the
low-level planner (one that ``replans``: the STO) on the measured state and the source's scene.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.framework import Diagram, DiagramBuilder

from hlp_drake.scene.model import Scene
from hlp_drake.systems.execution.receding_horizon import RecedingHorizonController
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.registry import check_closed_loop
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.perception.system import ScenePerception, add_scene_perception
from hlp_drake.systems.planning.diagram import ObservedScenePlanner, low_level_planner, make_planning_diagram
from hlp_drake.systems.world.scene_source import SCENE_PORT, SceneFromPlant
from hlp_drake.systems.world.uncertainty import sample_perturbation
from hlp_drake.systems.world.world import (
    add_position_trajectory,
    connect_robot_command,
    make_world_diagram,
    world_plant,
)

if TYPE_CHECKING:
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import ModelInstanceIndex
    from pydrake.systems.primitives import TrajectorySource

    from hlp_drake.learners.models import DecisionModels
    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.systems.world.uncertainty import WorldPerturbation


@dataclass(frozen=True)
class ExecutionDiagram:
    """The execution diagram and its parts, by name (``planned_scene``: what the planning diagram's
    ``scene`` input is fixed to, when it is not the source's; ``controller`` closed loop,
    ``trajectory_source`` open loop)."""

    diagram: Diagram
    world: Diagram
    plant: MultibodyPlant
    robot: ModelInstanceIndex
    planning: Diagram
    source: SceneFromPlant | ScenePerception
    planned_scene: Scene | None
    controller: RecedingHorizonController | None = None
    trajectory_source: TrajectorySource | None = None

    @property
    def execution(self) -> str:
        """``closed`` (a receding-horizon controller) or ``open`` (a trajectory)."""
        return "open" if self.controller is None else "closed"

    @property
    def watching(self) -> bool:
        """Whether the executed world's cameras feed the planners (closed loop, perceived scenes)."""
        return isinstance(self.source, ScenePerception)


def execution_model_error(scenario: Scenario) -> WorldPerturbation | None:
    """The executed world's seeded differences from ``scenario`` (``uncertainty``), if enabled."""
    return sample_perturbation(scenario.uncertainty, scenario.scene) if scenario.uncertainty.enabled else None


def make_execution_diagram(
    scenario: Scenario,
    *,
    pool: RolloutPool | None = None,
    models: DecisionModels | None = None,
    meshcat: Meshcat | None = None,
    contact_forces: bool = False,
    planned_scene: Scene | None = None,
) -> ExecutionDiagram:
    """The execution diagram of ``scenario`` (see the module's docstring); ``pool``: the rollout workers
    of a low-level planner that rolls out (the caller's); ``planned_scene``: the scene the planners
    plan on instead of the source's (a frame perceived before; under model error without cameras the
    scenario's scene is used anyway).

    Raises:
        HlpError: closed loop with a low-level planner that cannot re-plan.
    """
    closed = scenario.closed_loop.enabled
    check_closed_loop(scenario.low_level.kind, closed=closed)
    camera = scenario.perception.source == "camera"
    watching = camera and closed  # cameras in the executed world, re-perceived at re-plans
    error = execution_model_error(scenario)
    if planned_scene is None and error is not None and not camera:
        planned_scene = scenario.scene  # the scene the planners believe in
    builder = DiagramBuilder()
    world = builder.AddSystem(
        make_world_diagram(
            scenario, meshcat=meshcat, contact_forces=contact_forces, cameras=watching, model_error=error
        )
    )
    plant, robot = world_plant(world)
    planning = builder.AddNamedSystem("planning", make_planning_diagram(scenario, pool=pool, models=models))
    if watching:  # the planners see what the cameras see of the (true) world
        source = add_scene_perception(builder, world, template=scenario.scene, config=scenario.perception)
    else:  # the plant's poses (of the believed objects, under model error)
        source = builder.AddNamedSystem("scene_from_plant", SceneFromPlant(plant, scenario.scene))
        builder.Connect(world.GetOutputPort("body_poses"), source.get_body_poses_input_port())
    if planned_scene is None:
        builder.Connect(source.get_scene_output_port(), planning.GetInputPort(SCENE_PORT))
    controller = trajectory_source = None
    if closed:
        controller = _add_controller(builder, scenario, world, planning, source, models, camera=camera)
    else:  # holds the start until the run gives it the optimised sequence
        start = plant.GetPositions(plant.CreateDefaultContext(), robot)
        hold = ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start]))
        trajectory_source = add_position_trajectory(builder, world, hold.to_trajectory())
    return ExecutionDiagram(
        diagram=builder.Build(),
        world=world,
        plant=plant,
        robot=robot,
        planning=planning,
        source=source,
        planned_scene=planned_scene,
        controller=controller,
        trajectory_source=trajectory_source,
    )


def _add_controller(builder, scenario, world, planning, source, models, *, camera: bool):
    """A receding-horizon controller driving the robot from the planning diagram's low-level plan on,
    re-planning with its planner, observing the scene through ``source`` at every re-plan."""
    plant, _ = world_plant(world)
    planner = low_level_planner(planning)
    observed = make_planning_diagram(scenario, models=models)  # when objects have moved far
    controller = RecedingHorizonController(
        plant,
        planner=planner,
        closed_loop=scenario.closed_loop,
        robot=scenario.robot.name,
        objects=() if camera else tuple(o.name for o in scenario.scene.objects),
        initialiser=ObservedScenePlanner(observed, planner.as_commanded),
    )
    controller = builder.AddNamedSystem("controller", controller)
    builder.Connect(world.GetOutputPort("state"), controller.GetInputPort("state"))
    builder.Connect(source.get_scene_output_port(), controller.GetInputPort(SCENE_PORT))
    if camera:
        builder.Connect(source.get_perception_output_port(), controller.GetInputPort("perception"))
    builder.Connect(planning.GetOutputPort("optimisation"), controller.GetInputPort("initial"))
    connect_robot_command(
        builder, world, controller.GetOutputPort("desired_trajectory_state"), name="controller"
    )
    return controller
