"""``make_planning_diagram``: scene -> initialiser -> push transfer -> KeypointIk -> low-level planner.

The diagram's one input is ``scene``: fix it, or feed it from a plant's body poses through
``SceneFromPlant`` (as ``plan_and_execute`` does), and the diagram plans again when the scene changes.
The initialiser is the scenario's ``planner.initial`` (``INITIALISERS``), the low-level planner its
``planner.low_level`` (``LOW_LEVEL_PLANNERS``). ``ObservedScenePlanner`` runs the same planning again
on a measured scene for the receding-horizon controller.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantValueSource

from hlp_drake.learners.bundled import default_models
from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan
from hlp_drake.systems.low_level.protocol import LowLevelContext
from hlp_drake.systems.low_level.registry import low_level_entry
from hlp_drake.systems.low_level.system import LowLevelPlannerSystem
from hlp_drake.systems.planning.ik import KeypointIk
from hlp_drake.systems.planning.initialisers import INITIALISERS
from hlp_drake.systems.planning.transfer import RobotPlanTransfer
from hlp_drake.systems.world.scene_source import SCENE_PORT

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.low_level.control_sequence import ControlSequence
    from hlp_drake.systems.low_level.sto.pool import RolloutPool
    from hlp_drake.systems.scenario import Scenario


@cache
def _models_in(directory: str, sha256: str) -> DecisionModels:
    return DecisionModels.load(Path(directory), sha256=sha256 or None)


def scenario_models(scenario: Scenario) -> DecisionModels:
    """The decision models ``scenario.planner.models`` names (the bundled ones for ""), loaded once,
    pinned to ``scenario.planner.models_sha256`` where it is given."""
    settings = scenario.planner
    return _models_in(settings.models, settings.models_sha256) if settings.models else default_models()


def make_planning_diagram(
    scenario: Scenario,
    *,
    pool: RolloutPool | None = None,
    models: DecisionModels | None = None,
    plan: HighLevelPlan | None = None,
) -> Diagram:
    """``scene`` input -> initialiser -> push transfer -> KeypointIk -> low-level planner.

    The initialiser block is ``scenario.planner.initial``'s: "hlp" (``HlpPlannerSystem``) or "line"
    (the straight line, ``StraightLinePlanSystem``); the rest is the same for both. Outputs ``plan``
    (the initialiser's), ``robot_plan`` (its pushing-robot waypoints), ``keyframes``,
    ``trajectory`` (the initial joint trajectory through the keyframes) and, from the low-level
    planner, ``optimised_trajectory`` and ``optimisation`` (its ``LowLevelResult``; evaluating them
    runs it). The transfer's ``robot_alternatives`` (``planner.alternatives`` of the plan's next
    candidates) go through KeypointIk's ``alternatives`` to the low-level planner, which
    evaluates them only if it needs them.

    Args:
        pool: the rollout workers (the caller's) of a low-level planner that rolls out; without one,
            such a planner is left out (the outputs stop at ``trajectory``).
        models: the decision models (default: ``scenario_models(scenario)``).
        plan: a person's plan to use instead of the initialiser's (written out, or planned
            elsewhere): a constant source feeds it to the transfer, whatever the scene.
    """
    builder = DiagramBuilder()
    transfer = builder.AddNamedSystem(
        "robot_plan_transfer",
        RobotPlanTransfer(
            robot=scenario.robot,
            transfer=scenario.transfer,
            alternatives=scenario.planner.alternatives,
            pushes_closed=scenario.motion.closed_among_obstacles,
        ),
    )
    kind = "given" if plan is not None else scenario.planner.initial
    if plan is not None:
        plan_port = builder.AddNamedSystem("given_plan", ConstantValueSource(AbstractValue.Make(plan)))
        plan_port = plan_port.get_output_port()
        builder.ExportInput(transfer.get_scene_input_port(), SCENE_PORT)
    else:
        block = builder.AddNamedSystem(f"{kind}_planner", _initialiser(scenario, models))
        plan_port = block.get_plan_output_port()
        builder.ExportInput(block.get_scene_input_port(), SCENE_PORT)
        builder.ConnectToSame(block.get_scene_input_port(), transfer.get_scene_input_port())
    ik = builder.AddNamedSystem(
        "keypoint_ik",
        KeypointIk(
            scenario.scene,
            robot=scenario.robot,
            ik=scenario.ik,
            motion=scenario.motion,
            contact=scenario.contact,
            bodies=scenario.bodies,
        ),
    )
    builder.Connect(plan_port, transfer.get_plan_input_port())
    builder.Connect(transfer.get_robot_plan_output_port(), ik.get_plan_input_port())
    builder.Connect(transfer.get_robot_alternatives_output_port(), ik.get_alternatives_input_port())
    builder.ExportOutput(plan_port, "plan")
    builder.ExportOutput(transfer.get_robot_plan_output_port(), "robot_plan")
    builder.ExportOutput(ik.get_keyframes_output_port(), "keyframes")
    builder.ExportOutput(ik.get_trajectory_output_port(), "trajectory")
    entry = low_level_entry(scenario.low_level.kind)
    if pool is not None or not entry.rolls_out:
        perceived = scenario.perception.source == "camera"
        context = LowLevelContext(scenario.world_model, pool, perceived, scenario.success)
        planner = entry.make(scenario.low_level, context)
        low_level = builder.AddNamedSystem("optimiser", LowLevelPlannerSystem(planner))
        builder.ConnectToSame(transfer.get_scene_input_port(), low_level.get_scene_input_port())
        builder.Connect(ik.get_keyframes_output_port(), low_level.get_keyframes_input_port())
        builder.Connect(ik.get_trajectory_output_port(), low_level.get_initial_trajectory_input_port())
        builder.Connect(
            ik.get_alternative_trajectories_output_port(), low_level.get_alternatives_input_port()
        )
        builder.ExportOutput(low_level.get_trajectory_output_port(), "optimised_trajectory")
        builder.ExportOutput(low_level.get_result_output_port(), "optimisation")
    diagram = builder.Build()
    diagram.set_name(f"{kind}_planning")
    return diagram


def _initialiser(scenario: Scenario, models: DecisionModels | None):
    """The block of ``scenario``'s initialiser (with the decision models, if it uses them)."""
    entry = INITIALISERS[scenario.planner.initial]
    if entry.uses_models:
        return entry.block_class()(models=models or scenario_models(scenario), config=scenario.planner.hlp)
    return entry.block_class()()


def low_level_planner(diagram: Diagram):
    """The low-level planner of a planning diagram (None if it has none)."""
    if not diagram.HasSubsystemNamed("optimiser"):
        return None
    return diagram.GetSubsystemByName("optimiser").planner


# ``ObservedScenePlanner``: the initialiser's start again, on the scene as measured.
#
# The receding-horizon controller's ``initialiser`` (``RecedingHorizonController``): on the observed
# scene (its ``scene`` input: the plant's poses or the cameras' perception) it runs the planning
# diagram's initialiser and push transfer, and solves the plan's keypoints from the robot's measured
# positions on (``KeypointSolver.solve(start=...)``).
class ObservedScenePlanner:
    """The initial sequence of ``planning`` (a planning diagram) on an observed scene, from the robot's
    measured state (its positions then velocities), as ``as_commanded`` commands a trajectory
    (the low-level planner's); None when there is no plan or a keypoint's IK fails."""

    def __init__(
        self, planning: Diagram, as_commanded: Callable[[PiecewisePolynomial], ControlSequence]
    ) -> None:
        self._diagram = planning
        self._as_commanded = as_commanded
        self._solver = planning.GetSubsystemByName("keypoint_ik").solver

    def __call__(self, scene: Scene, robot: np.ndarray) -> ControlSequence | None:
        context = self._diagram.CreateDefaultContext()
        self._diagram.GetInputPort(SCENE_PORT).FixValue(context, scene)
        plan = self._diagram.GetOutputPort("robot_plan").Eval(context)
        plant_context = self._solver.plant_context(self._solver.new_context())
        keyframes = self._solver.solve(plant_context, plan, start=robot[: len(robot) // 2])
        if not keyframes.ok:
            return None
        return self._as_commanded(self._solver.trajectory(plant_context, keyframes))


__all__ = ["ObservedScenePlanner", "low_level_planner", "make_planning_diagram", "scenario_models"]
