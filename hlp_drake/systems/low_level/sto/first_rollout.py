"""The STO's starting point on a scenario: ``initial_sequence`` (the initialiser's trajectory as the
STO commands it) and ``first_rollout`` (its rollout, the optimiser's first)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from hlp_drake.errors import HlpError
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.low_level.sto.pool import SceneRollouts
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.world.scene_source import SCENE_PORT

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels
    from hlp_drake.systems.low_level.outcome import RolloutOutcome
    from hlp_drake.systems.scenario import Scenario


def sto_config(scenario: Scenario) -> StoConfig:
    """``scenario``'s low-level settings, which must be the STO's.

    Raises:
        HlpError: its low-level planner is another.
    """
    if not isinstance(scenario.low_level, StoConfig):
        raise HlpError(f"this needs the STO as the low-level planner, not {scenario.low_level.kind!r}")
    return scenario.low_level


def initial_sequence(scenario: Scenario, *, models: DecisionModels | None = None) -> ControlSequence | None:
    """The initialiser's (IK) control sequence on ``scenario``'s scene, the STO's starting point; None
    if there is no trajectory at all (a keypoint whose IK failed is skipped, as the trajectory does)."""
    diagram = make_planning_diagram(scenario, models=models)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort(SCENE_PORT).FixValue(context, scenario.scene)
    trajectory = diagram.GetOutputPort("trajectory").Eval(context)
    if trajectory.get_number_of_segments() == 0:
        return None
    return ControlSequence.from_trajectory(trajectory, sto_config(scenario).step_duration)


def first_rollout(scenario: Scenario, *, models: DecisionModels | None = None) -> RolloutOutcome | None:
    """The rollout of ``initial_sequence``, as the optimiser's first one (``SceneRollouts``: the
    reduced model if the STO's ``reduced_model``); None if there is no initial sequence."""
    sequence = initial_sequence(scenario, models=models)
    if sequence is None:
        return None
    return SceneRollouts(RolloutSpec.of(scenario)).rollout(sequence)


__all__ = ["first_rollout", "initial_sequence", "sto_config"]
