"""``KeypointIk`` on its own: the block on a scene with a scenario's sections (``ik_for``), its
keyframes solved directly (``solve``) and plans through the rows' gaps (``through_gaps``)."""

from __future__ import annotations

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.model import Scene
from hlp_drake.systems.planning.ik import KeypointIk
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.scenario import Scenario
from hlp_drake.taskspace import TaskSpace

CONFIG = Scenario()


def ik_for(scene: Scene, scenario: Scenario = CONFIG) -> KeypointIk:
    """``KeypointIk`` on ``scene`` with ``scenario``'s sections (alone: the block takes its own)."""
    return KeypointIk(scene, robot=scenario.robot, ik=scenario.ik, motion=scenario.motion)


def solve(system: KeypointIk, plan: HighLevelPlan) -> Keyframes:
    """The keyframes of ``plan``, solved directly (in a context of its own)."""
    solver = system.solver
    return solver.solve(solver.plant_context(solver.new_context()), plan)


def gap_centres(scene: Scene) -> list[tuple[float, float]]:
    """Per row, the centre of the gap nearest the table's centre line."""
    return [min(row, key=lambda gap: abs(gap.center[1])).center for row in TaskSpace(scene).gaps]


def through_gaps(scene: Scene, *, to_target: bool) -> HighLevelPlan:
    keypoints = [PlanKeypoint("start", scene.start)]
    keypoints += [
        PlanKeypoint("gap", centre, row=row, element="0") for row, centre in enumerate(gap_centres(scene))
    ]
    if to_target:
        keypoints.append(PlanKeypoint("target", scene.target.position, element=scene.target.name))
    return HighLevelPlan(scene=scene.name, keypoints=tuple(keypoints))
