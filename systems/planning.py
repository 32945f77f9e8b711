"""The planning diagram: a planner block (HLP or the straight-line baseline) feeding KeypointIk."""

from __future__ import annotations

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem

from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan, PlanKeypoint
from hlp_drake.planner.transfer import robot_alternatives, robot_plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.hlp_planner_system import HlpPlannerSystem
from hlp_drake.systems.keypoint_ik import KeypointIk
from hlp_drake.systems.rollout import RolloutOutcome, SceneRollouts
from hlp_drake.systems.rollout_pool import RolloutPool
from hlp_drake.systems.sto import StochasticTrajectoryOptimiser
from hlp_drake.systems.world_config import WorldConfig

PLANNERS = ("hlp", "sto")


def straight_line_plan(scene: Scene) -> HighLevelPlan:
    """The baseline's initial plan: from the start straight to the target."""
    return HighLevelPlan(scene.name, (
        PlanKeypoint("start", (float(scene.start[0]), float(scene.start[1]))),
        PlanKeypoint("target", (float(scene.target.x), float(scene.target.y)), None, scene.target.name),
    ))


class StraightLinePlanSystem(LeafSystem):
    """The straight-line baseline's planner block: same ports as ``HlpPlannerSystem``.

    Input port ``scene`` (abstract Scene); output port ``plan`` (abstract HighLevelPlan).
    """

    def __init__(self) -> None:
        super().__init__()
        self._scene_port = self.DeclareAbstractInputPort(name="scene", model_value=AbstractValue.Make(generate_scene("vr", 0)))
        self._plan_port = self.DeclareAbstractOutputPort(
            name="plan", alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=lambda context, output: output.set_value(straight_line_plan(self._scene_port.Eval(context))),
            prerequisites_of_calc={self.all_input_ports_ticket()})

    def get_scene_input_port(self):
        return self._scene_port

    def get_plan_output_port(self):
        return self._plan_port


class RobotPlanTransfer(LeafSystem):
    """Turns a human-like plan into the pushing robot's waypoints (``hlp_drake.planner.transfer``).

    Input port ``plan`` (abstract HighLevelPlan). Output ports ``robot_plan`` (abstract
    HighLevelPlan) and ``robot_alternatives`` (abstract tuple of HighLevelPlan: the robot plans of
    at most ``alternatives`` of the plan's other candidates, ``robot_alternatives``; computed only
    when evaluated).
    """

    def __init__(self, scene: Scene, *, alternatives: int = 0) -> None:
        super().__init__()
        self._scene = scene
        self._plan_port = self.DeclareAbstractInputPort(name="plan", model_value=AbstractValue.Make(HighLevelPlan("", ())))
        self._out_port = self.DeclareAbstractOutputPort(
            name="robot_plan", alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=lambda context, output: output.set_value(robot_plan(self._plan_port.Eval(context), self._scene)),
            prerequisites_of_calc={self.all_input_ports_ticket()})
        self._alternatives_port = self.DeclareAbstractOutputPort(
            name="robot_alternatives", alloc=lambda: AbstractValue.Make(()),
            calc=lambda context, output: output.set_value(
                robot_alternatives(self._plan_port.Eval(context), self._scene, alternatives)),
            prerequisites_of_calc={self.all_input_ports_ticket()})

    def get_plan_input_port(self):
        return self._plan_port

    def get_robot_plan_output_port(self):
        return self._out_port

    def get_robot_alternatives_output_port(self):
        return self._alternatives_port


def make_planning_diagram(scene: Scene, *, planner: str = "hlp", models: DecisionModels | None = None,
                          config: WorldConfig | None = None, pool: RolloutPool | None = None) -> Diagram:
    """``scene`` input -> planner block -> push transfer -> KeypointIk -> StochasticTrajectoryOptimiser.

    Outputs ``plan`` (the planner's), ``robot_plan`` (its pushing-robot waypoints), ``keyframes``,
    ``trajectory`` (the initial joint trajectory through the keyframes), ``optimised_trajectory``
    and ``optimisation`` (the optimiser's ``StoResult``). Evaluating the last two runs the optimiser.
    The transfer's ``robot_alternatives`` (the plan's next candidates, ``config.sto.alternatives``
    of them) go through KeypointIk's ``alternatives`` to the optimiser, which evaluates them only
    when the initial trajectory's rollout fails.

    Args:
        planner: "hlp" (the human-like planner) or "sto" (the straight line of the baseline); the
            only difference is the planner block: the optimiser and its settings are the same (the
            straight line has no alternatives).
        pool: the optimiser's rollout workers (an in-process pool by default).
    """
    if planner not in PLANNERS:
        raise ValueError(f"unknown planner {planner!r}; choose one of {', '.join(PLANNERS)}")
    builder = DiagramBuilder()
    block = HlpPlannerSystem(models=models) if planner == "hlp" else StraightLinePlanSystem()
    block.set_name(f"{planner}_planner")
    builder.AddSystem(block)
    config = WorldConfig() if config is None else config
    transfer = builder.AddNamedSystem("robot_plan_transfer",
                                      RobotPlanTransfer(scene, alternatives=config.sto.alternatives))
    ik = builder.AddNamedSystem("keypoint_ik", KeypointIk(scene, config))
    builder.Connect(block.get_plan_output_port(), transfer.get_plan_input_port())
    optimiser = builder.AddNamedSystem("optimiser", StochasticTrajectoryOptimiser(scene, config, pool=pool))
    builder.Connect(transfer.get_robot_plan_output_port(), ik.get_plan_input_port())
    builder.Connect(ik.get_trajectory_output_port(), optimiser.get_initial_trajectory_input_port())
    builder.Connect(transfer.get_robot_alternatives_output_port(), ik.get_alternatives_input_port())
    builder.Connect(ik.get_alternative_trajectories_output_port(), optimiser.get_alternatives_input_port())
    builder.ExportInput(block.get_scene_input_port(), "scene")
    builder.ExportOutput(block.get_plan_output_port(), "plan")
    builder.ExportOutput(transfer.get_robot_plan_output_port(), "robot_plan")
    builder.ExportOutput(ik.get_keyframes_output_port(), "keyframes")
    builder.ExportOutput(ik.get_trajectory_output_port(), "trajectory")
    builder.ExportOutput(optimiser.get_trajectory_output_port(), "optimised_trajectory")
    builder.ExportOutput(optimiser.get_result_output_port(), "optimisation")
    diagram = builder.Build()
    diagram.set_name(f"{planner}_planning")
    return diagram


def initial_sequence(scene: Scene, *, planner: str = "hlp", models: DecisionModels | None = None,
                     config: WorldConfig | None = None) -> ControlSequence | None:
    """``planner``'s initial (IK) control sequence on ``scene``, the optimiser's starting point;
    None if there is no trajectory at all (a keypoint whose IK failed is skipped, as the trajectory
    does)."""
    config = WorldConfig() if config is None else config
    diagram = make_planning_diagram(scene, planner=planner, models=models, config=config)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("scene").FixValue(context, scene)
    trajectory = diagram.GetOutputPort("trajectory").Eval(context)
    if trajectory.get_number_of_segments() == 0:
        return None
    return ControlSequence.from_trajectory(trajectory, config.sto.step_duration)


def first_rollout(scene: Scene, *, planner: str = "hlp", models: DecisionModels | None = None,
                  config: WorldConfig | None = None) -> RolloutOutcome | None:
    """The rollout of ``initial_sequence`` on ``scene``, as the optimiser's first one
    (``SceneRollouts``: the reduced model if ``config.sto.reduced_model``, at the rollout time step);
    None if there is no initial sequence."""
    config = WorldConfig() if config is None else config
    sequence = initial_sequence(scene, planner=planner, models=models, config=config)
    return None if sequence is None else SceneRollouts(scene, config).rollout(sequence)
