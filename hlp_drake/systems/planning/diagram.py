"""``make_planning_diagram``: scene -> planner block -> push transfer -> KeypointIk (-> optimiser).

The diagram's one input is ``scene``: fix it, or feed it from a plant's body poses through
``SceneFromPlant`` (as ``plan_and_execute`` does), and the diagram plans again when the scene changes.
Its planner blocks are here too: ``HlpPlannerSystem`` (the human-like planner) and
``StraightLinePlanSystem`` (the baseline's straight line), and ``ObservedScenePlanner``, which runs the
same planning again on a measured scene for the receding-horizon controller.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Context, Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantValueSource

from hlp_drake.learners.bundled import default_models
from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan, PlanKeypoint, PlannerConfig, plan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.cost import RolloutOutcome
from hlp_drake.systems.low_level.sto.pool import RolloutPool, SceneRollouts
from hlp_drake.systems.low_level.sto.system import StochasticTrajectoryOptimiser
from hlp_drake.systems.planning.ik import KeypointIk
from hlp_drake.systems.planning.transfer import RobotPlanTransfer
from hlp_drake.systems.world.scene_source import SCENE_PORT, declare_scene_input_port, scene_input

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene
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
    """``scene`` input -> planner block -> push transfer -> KeypointIk -> StochasticTrajectoryOptimiser.

    The planner block is ``scenario.planner.kind``'s: "hlp" (``HlpPlannerSystem``) or "sto" (the
    straight line, ``StraightLinePlanSystem``); the rest is the same for both. Outputs ``plan`` (the
    planner's), ``robot_plan`` (its pushing-robot waypoints), ``keyframes``, ``trajectory`` (the
    initial joint trajectory through the keyframes) and, with a ``pool``, ``optimised_trajectory``
    and ``optimisation`` (the optimiser's ``StoResult``; evaluating them runs the optimiser). The
    transfer's ``robot_alternatives`` (``optimiser.alternatives`` of the plan's next candidates) go
    through KeypointIk's ``alternatives`` to the optimiser, which evaluates them only when the
    initial trajectory's rollout fails.

    Args:
        pool: the optimiser's rollout workers (the caller's); without one, no optimiser.
        models: the decision models (default: ``scenario_models(scenario)``).
        plan: a person's plan to use instead of the planner block's (written out, or planned
            elsewhere): a constant source feeds it to the transfer, whatever the scene.
    """
    kind = "given" if plan is not None else scenario.planner.kind
    builder = DiagramBuilder()
    transfer = builder.AddNamedSystem("robot_plan_transfer", RobotPlanTransfer(scenario))
    if plan is not None:
        source = ConstantValueSource(AbstractValue.Make(plan))
        plan_port = builder.AddNamedSystem("given_plan", source).get_output_port()
        builder.ExportInput(transfer.get_scene_input_port(), SCENE_PORT)
    else:
        if kind == "hlp":
            block = HlpPlannerSystem(models=models or scenario_models(scenario), config=scenario.planner.hlp)
        else:
            block = StraightLinePlanSystem()
        builder.AddNamedSystem(f"{kind}_planner", block)
        plan_port = block.get_plan_output_port()
        builder.ExportInput(block.get_scene_input_port(), SCENE_PORT)
        builder.ConnectToSame(block.get_scene_input_port(), transfer.get_scene_input_port())
    ik = builder.AddNamedSystem("keypoint_ik", KeypointIk(scenario))
    builder.Connect(plan_port, transfer.get_plan_input_port())
    builder.Connect(transfer.get_robot_plan_output_port(), ik.get_plan_input_port())
    builder.Connect(transfer.get_robot_alternatives_output_port(), ik.get_alternatives_input_port())
    builder.ExportOutput(plan_port, "plan")
    builder.ExportOutput(transfer.get_robot_plan_output_port(), "robot_plan")
    builder.ExportOutput(ik.get_keyframes_output_port(), "keyframes")
    builder.ExportOutput(ik.get_trajectory_output_port(), "trajectory")
    if pool is not None:
        optimiser = builder.AddNamedSystem("optimiser", StochasticTrajectoryOptimiser(scenario, pool))
        builder.ConnectToSame(transfer.get_scene_input_port(), optimiser.get_scene_input_port())
        builder.Connect(ik.get_trajectory_output_port(), optimiser.get_initial_trajectory_input_port())
        builder.Connect(
            ik.get_alternative_trajectories_output_port(), optimiser.get_alternatives_input_port()
        )
        builder.ExportOutput(optimiser.get_trajectory_output_port(), "optimised_trajectory")
        builder.ExportOutput(optimiser.get_result_output_port(), "optimisation")
    diagram = builder.Build()
    diagram.set_name(f"{kind}_planning")
    return diagram


def initial_sequence(scenario: Scenario, *, models: DecisionModels | None = None) -> ControlSequence | None:
    """The planner's initial (IK) control sequence on ``scenario``'s scene, the optimiser's starting
    point; None if there is no trajectory at all (a keypoint whose IK failed is skipped, as the
    trajectory does)."""
    diagram = make_planning_diagram(scenario, models=models)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort(SCENE_PORT).FixValue(context, scenario.scene)
    trajectory = diagram.GetOutputPort("trajectory").Eval(context)
    if trajectory.get_number_of_segments() == 0:
        return None
    return ControlSequence.from_trajectory(trajectory, scenario.optimiser.step_duration)


def first_rollout(scenario: Scenario, *, models: DecisionModels | None = None) -> RolloutOutcome | None:
    """The rollout of ``initial_sequence``, as the optimiser's first one (``SceneRollouts``: the
    reduced model if ``optimiser.reduced_model``, at the rollout time step); None if there is no
    initial sequence."""
    sequence = initial_sequence(scenario, models=models)
    return None if sequence is None else SceneRollouts(scenario).rollout(sequence)


# ``ObservedScenePlanner``: the planner's initial sequence again, on the scene as measured.
#
# The receding-horizon controller's ``initialiser`` (``RecedingHorizonController``): on the observed
# scene (its ``scene`` input: the plant's poses or the cameras' perception) it runs the planning
# diagram's planner and push transfer, and solves the plan's keypoints from the robot's measured
# positions on (``KeypointSolver.solve(start=...)``).
class ObservedScenePlanner:
    """The planner's initial sequence on an observed scene, from the robot's measured state (its 11
    positions then velocities; None when there is no plan or a keypoint's IK fails)."""

    def __init__(self, scenario: Scenario, *, models: DecisionModels | None = None) -> None:
        self._scenario = scenario
        self._diagram = make_planning_diagram(scenario, models=models)
        self._solver = self._diagram.GetSubsystemByName("keypoint_ik").solver

    def __call__(self, scene: Scene, robot: np.ndarray) -> ControlSequence | None:
        context = self._diagram.CreateDefaultContext()
        self._diagram.GetInputPort(SCENE_PORT).FixValue(context, scene)
        plan = self._diagram.GetOutputPort("robot_plan").Eval(context)
        plant_context = self._solver.plant_context(self._solver.new_context())
        keyframes = self._solver.solve(plant_context, plan, start=robot[: len(robot) // 2])
        if not keyframes.ok:
            return None
        trajectory = self._solver.trajectory(plant_context, keyframes)
        return ControlSequence.from_trajectory(trajectory, self._scenario.optimiser.step_duration)


__all__ = ["ObservedScenePlanner"]


# ``HlpPlannerSystem``: the human-like planner as a Drake LeafSystem (scene in, HighLevelPlan out).
class HlpPlannerSystem(LeafSystem):
    """Plans with the human-like planner (``hlp_drake.planner.plan``).

    Input port ``scene`` (abstract ``Scene``; from ``SceneFromPlant`` to plan on a plant's body
    poses). Output port ``plan`` (abstract ``HighLevelPlan``), in Drake's cache: planned again only
    when the scene changes (to plan at a fixed rate in a simulation, put Drake's ``ZeroOrderHold``
    on the scene).

    Args:
        models: decision models (default: the bundled ones).
        config: planner settings (default: the models' mode).
    """

    def __init__(self, *, models: DecisionModels | None = None, config: PlannerConfig | None = None) -> None:
        super().__init__()
        self._models = models or default_models()
        self._config = config or PlannerConfig(mode=self._models.mode_)
        self._scene_port = declare_scene_input_port(self)
        self._plan_port = self.DeclareAbstractOutputPort(
            name="plan",
            alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=self._calc_plan,
            prerequisites_of_calc={self.all_input_ports_ticket()},
        )

    def get_scene_input_port(self):
        return self._scene_port

    def get_plan_output_port(self):
        return self._plan_port

    def _calc_plan(self, context: Context, output: AbstractValue) -> None:
        output.set_value(plan(scene_input(self._scene_port, context), self._models, self._config))


# The straight-line baseline's planner block: from the start straight to the target.
def straight_line_plan(scene: Scene) -> HighLevelPlan:
    """The baseline's initial plan: from the start straight to the target."""
    return HighLevelPlan(
        scene.name,
        (
            PlanKeypoint("start", (float(scene.start[0]), float(scene.start[1]))),
            PlanKeypoint("target", (float(scene.target.x), float(scene.target.y)), None, scene.target.name),
        ),
    )


class StraightLinePlanSystem(LeafSystem):
    """The straight-line baseline's planner block, with ``HlpPlannerSystem``'s ports: input ``scene``
    (abstract ``Scene``), output ``plan`` (abstract ``HighLevelPlan``)."""

    def __init__(self) -> None:
        super().__init__()
        self._scene_port = declare_scene_input_port(self)
        self._plan_port = self.DeclareAbstractOutputPort(
            name="plan",
            alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=lambda context, output: output.set_value(
                straight_line_plan(scene_input(self._scene_port, context))
            ),
            prerequisites_of_calc={self.all_input_ports_ticket()},
        )

    def get_scene_input_port(self):
        return self._scene_port

    def get_plan_output_port(self):
        return self._plan_port
