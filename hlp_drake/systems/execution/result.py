"""What a run ran and what came of it: ``what_ran``, ``ExecutionResult`` (with the plan named by the
true objects when it was planned on a perceived scene: ``true_names``, ``named_plan``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from hlp_drake.config.what_ran import Labels, WhatRan
from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.perception.accuracy import match_objects
from hlp_drake.systems.planning.initialisers import planner_label
from hlp_drake.systems.planning.keyframes import Keyframes

if TYPE_CHECKING:
    from hlp_drake.systems.perception.perception import Perception
    from hlp_drake.systems.scenario import Scenario


def labels_of(scenario: Scenario) -> Labels:
    """What a run of ``scenario`` is called in rows and headers: its robot, initialiser, low-level
    planner (and their pair's name), execution mode, perception source and model error's seed."""
    initial, low_level = scenario.planner.initial, scenario.low_level.kind
    return Labels(
        robot=scenario.robot.name,
        initial=initial,
        low_level=low_level,
        planner=planner_label(initial, low_level),
        execution="closed" if scenario.closed_loop.enabled else "open",
        perception=scenario.perception.source,
        model_error=scenario.uncertainty.seed if scenario.uncertainty.enabled else None,
        world=scenario.world.kind,
    )


def what_ran(scenario: Scenario, scenario_file: str | None = None) -> WhatRan:
    """What a run of ``scenario`` (read from ``scenario_file``; None: the built-in default) runs
    (``labels_of``)."""
    return WhatRan.of([labels_of(scenario)], scenario_file=scenario_file)


@dataclass
class ExecutionResult:
    """Outcome of planning and executing one scene (``planner``: the pair's name, ``planner_label``
    of the ``initial`` initialiser and the ``low_level`` planner; ``reach_reused``: the execution
    started where the low-level planner's accepted rollout on the execution model ended, rather than
    simulating the reach
    again; see ``verified_reach``; ``true_names``: planned on a perceived scene, per perceived
    object's name the true object's it was matched to, None if none; ``actuated_dofs``: the robot's
    actuated joints, base, arm and gripper).

    ``success`` is the paper's reach success in the ``world`` the motion was executed in
    (``reference`` or the planner's own ``model``), ``model_success`` the low-level planner's verdict
    in its own model (it accepted a motion; None: it did not run); ``grasp_held`` is reported
    beside it and is not part of it (``grasp_failure``: why the grasp's simulation stopped, if it
    failed; the reach's verdict stands).
    """

    planner: str
    scene: Scene
    plan: HighLevelPlan
    keyframes: Keyframes
    robot_plan: HighLevelPlan | None = None
    success: bool = False
    failure_reason: str | None = None
    timings: dict[str, float] = field(default_factory=dict)
    objects_moved: list[str] = field(default_factory=list)
    objects_dropped: list[str] = field(default_factory=list)
    target_distance: float | None = None
    simulated_s: float = 0.0
    iterations: int = 0
    rollouts: int = 0
    optimisation: dict[str, Any] = field(default_factory=dict)
    grasp_held: bool | None = None
    grasp_failure: str | None = None
    perception: dict[str, Any] | None = None
    execution: str = "open"
    closed_loop: dict[str, Any] = field(default_factory=dict)
    reach_reused: bool = False
    true_names: dict[str, str | None] | None = None
    actuated_dofs: int = 0
    initial: str = "hlp"
    low_level: str = "sto"
    world: str = "reference"
    model_success: bool | None = None

    @property
    def false_accept(self) -> bool:
        """The low-level planner accepted the motion in its model, and the world failed it."""
        return bool(self.model_success) and not self.success

    def to_dict(self) -> dict[str, Any]:
        return {
            "planner": self.planner,
            "initial": self.initial,
            "low_level": self.low_level,
            "scene": self.scene.name,
            "world": self.world,
            "success": self.success,
            "model_success": self.model_success,
            "false_accept": self.false_accept,
            "failure_reason": self.failure_reason,
            "plan": named_plan(self.plan.to_dict(), self.true_names),
            "ik": {
                "ok": self.keyframes.ok,
                "failures": self.keyframes.failures,
                "skipped": self.keyframes.skipped,
                "candidate": self.keyframes.candidate,
                "replaced": list(self.keyframes.replaced),
            },
            "robot_actuated_dofs": self.actuated_dofs,
            "timings": self.timings,
            "objects_moved": self.objects_moved,
            "objects_dropped": self.objects_dropped,
            "target_distance": self.target_distance,
            "simulated_s": self.simulated_s,
            "iterations": self.iterations,
            "rollouts": self.rollouts,
            "optimisation": self.optimisation,
            "grasp_held": self.grasp_held,
            "grasp_failure": self.grasp_failure,
            **({} if self.perception is None else {"perception": self.perception}),
            "execution": self.execution,
            "closed_loop": self.closed_loop,
            "reach_reused": self.reach_reused,
        }


def true_names(scene: Scene, perception: Perception) -> dict[str, str | None]:
    """Per object of the ``perception``'s scene, the name of the object of the true ``scene`` it was
    matched to (``match_objects``), None for an object matched to none."""
    if not perception.ok:
        return {}
    matched = {seen: true for true, seen in match_objects(scene, perception.scene).items()}
    return {o.name: matched.get(o.name) for o in perception.scene.objects}


def named_plan(plan: dict[str, Any], names: dict[str, str | None] | None) -> dict[str, Any]:
    """A plan's JSON (``HighLevelPlan.to_dict``) whose keypoints name the true objects (``names``:
    perceived -> true, None: planned on the true scene), each perceived name beside as ``perceived_as``."""
    if names is None:
        return plan
    keypoints = []
    for keypoint in plan["keypoints"]:
        element = keypoint["element"]
        if keypoint["action"] != "gap" and element is not None:
            keypoint = {**keypoint, "element": names.get(element), "perceived_as": element}
        keypoints.append(keypoint)
    return {**plan, "keypoints": keypoints}
