"""People's plans written out, for tests of the blocks downstream of the planner (transfer, IK, optimiser).

``human_plan`` lays a list of decisions out as the planners do: a gap at its centre, a move at the
obstacle's centre and its release at the centre of its relocated region, then the target. The
plans below are the ones the bundled models of the previous release made for those scenes; a test
that pins them tests its block, whatever the planner now makes of the scene.
"""

from __future__ import annotations

from hlp_drake.planner import HighLevelPlan, PlanCandidate, PlanKeypoint
from hlp_drake.scene.model import Scene
from hlp_drake.taskspace import TaskSpace
from hlp_drake.taskspace.relocation import relocated

Step = tuple[str, str | int, str | None]  # ("gap", row, gap index) or ("move", obstacle, direction)


def keypoints(scene: Scene, steps: list[Step]) -> tuple[PlanKeypoint, ...]:
    space = TaskSpace(scene)
    row_of = {n: row.index for row in space.rows for n in row.members}
    out = [PlanKeypoint("start", (float(scene.start[0]), float(scene.start[1])))]
    for kind, what, how in steps:
        if kind == "gap":
            gap = space.gaps[int(what) - 1][int(how) - 1]
            out.append(PlanKeypoint("gap", gap.center, int(what), str(how)))
        else:
            rect, row = space.rects[what], row_of[what]
            out += [
                PlanKeypoint("move", rect.center, row, what, how),
                PlanKeypoint("release", relocated(rect, how, space.alpha).center, row, what, how),
            ]
    out.append(PlanKeypoint("target", space.target.center, None, scene.target.name))
    return tuple(out)


def human_plan(scene: Scene, steps: list[Step], alternatives: list[list[Step]] = ()) -> HighLevelPlan:
    """The plan of ``steps`` (and its next candidates ``alternatives``, best first)."""
    return HighLevelPlan(
        scene.name,
        keypoints(scene, steps),
        alternatives=tuple(PlanCandidate(keypoints(scene, a), 0.0) for a in alternatives),
    )


# gen1 seed 27: a backward move with no room for the robot's sideways push, then a push to the right.
GEN1_27 = [("move", "FailOnTouchObstacleMed", "BL"), ("move", "FailOnTouchObstacleLong-1", "RR")]
# gen1 seed 19: through gap 2, then FailOnTouchObstacleLong-1 forwards, over the table.
GEN1_19 = [("gap", 1, 2), ("move", "FailOnTouchObstacleLong-1", "FF")]
# gen2 seed 12, 9 objects.
GEN2_9_12 = [
    ("move", "obstacle_4", "BL"),
    ("gap", 2, 2),
    ("move", "obstacle_1", "RR"),
    ("gap", 4, 3),
    ("gap", 5, 2),
]
# gen2 seed 39, 9 objects, and its next four candidates.
# gen2 seed 30, 9 objects, as the bundled models laid it out (every keypoint where they put it):
# the robot's way to the row-4 push knocks the target off the table at the first rollout; its
# first next candidate passes.
GEN2_9_30 = (
    ("start", (0.0, 0.0807), None, None, None),
    ("gap", (0.2275, 0.16699), 1, "1", None),
    ("move", (0.3573, 0.3417), 2, "obstacle_2", "BB"),
    ("release", (0.25655, 0.3775), 2, "obstacle_2", "BB"),
    ("gap", (0.4103, 0.354), 3, "1", None),
    ("move", (0.5545, 0.4071), 4, "obstacle_9", "LL"),
    ("release", (0.56782, 0.64085), 4, "obstacle_9", "LL"),
    ("target", (0.6314, 0.3202), None, "Target", None),
)
GEN2_9_30_NEXT = (
    (
        ("start", (0.0, 0.0807), None, None, None),
        ("gap", (0.2275, 0.16699), 1, "1", None),
        ("gap", (0.33533, 0.2079), 2, "2", None),
        ("gap", (0.4103, 0.23633), 3, "1", None),
        ("move", (0.5545, 0.4071), 4, "obstacle_9", "BB"),
        ("release", (0.47125, 0.4445), 4, "obstacle_9", "BB"),
        ("target", (0.6314, 0.3202), None, "Target", None),
    ),
    (
        ("start", (0.0, 0.0807), None, None, None),
        ("gap", (0.2275, 0.16699), 1, "1", None),
        ("gap", (0.33533, 0.2079), 2, "2", None),
        ("gap", (0.4103, 0.23633), 3, "1", None),
        ("move", (0.5162, 0.1165), 4, "obstacle_5", "FF"),
        ("release", (0.5897, 0.15496), 4, "obstacle_5", "FF"),
        ("target", (0.6314, 0.3202), None, "Target", None),
    ),
)


def laid_out_plan(scene: Scene, keypoints, alternatives=()) -> HighLevelPlan:
    """The plan of ``keypoints`` (action, position, row, element, direction), each where it is given,
    and its next candidates ``alternatives``, best first."""
    return HighLevelPlan(
        scene.name,
        tuple(PlanKeypoint(*k) for k in keypoints),
        alternatives=tuple(PlanCandidate(tuple(PlanKeypoint(*k) for k in a), 0.0) for a in alternatives),
    )


GEN2_9_39 = [
    ("move", "obstacle_1", "FF"),
    ("move", "obstacle_9", "LL"),
    ("move", "obstacle_6", "FF"),
    ("move", "obstacle_3", "LL"),
    ("gap", 5, 1),
]
GEN2_9_39_NEXT = [
    [
        ("gap", 1, 3),
        ("move", "obstacle_9", "LL"),
        ("move", "obstacle_6", "FF"),
        ("move", "obstacle_3", "LL"),
        ("gap", 5, 1),
    ],
    [("gap", 1, 3), ("move", "obstacle_9", "LL"), ("gap", 3, 2), ("move", "obstacle_3", "LL"), ("gap", 5, 1)],
    [
        ("move", "obstacle_1", "FF"),
        ("move", "obstacle_9", "LL"),
        ("gap", 3, 2),
        ("move", "obstacle_3", "LL"),
        ("gap", 5, 1),
    ],
    [
        ("gap", 1, 3),
        ("move", "obstacle_9", "LL"),
        ("move", "obstacle_6", "FF"),
        ("gap", 4, 2),
        ("move", "obstacle_5", "LL"),
    ],
]
# gen1 seed 15: both moves; on the way to the first push start open fingers straddle a small obstacle.
# gen1 seed 25: a push to the right in row 1, then a backward move in row 2.
GEN1_25 = [("move", "FailOnTouchObstacleMed", "RR"), ("move", "FailOnTouchObstacleMed-1", "BB")]
# gen1 seed 32: a backward move in row 1, then a forward-left one in row 2.
GEN1_32 = [("move", "FailOnTouchObstacleLong", "BL"), ("move", "FailOnTouchObstacleShort-1", "FL")]


def chain_first_rollout(scenario, human: HighLevelPlan):
    """The optimiser's first rollout of the initial trajectory of ``human``'s robot plan."""
    from hlp_drake.systems import make_planning_diagram
    from hlp_drake.systems.low_level.control_sequence import ControlSequence
    from hlp_drake.systems.low_level.sto.pool import SceneRollouts
    from hlp_drake.systems.low_level.sto.spec import RolloutSpec

    diagram = make_planning_diagram(scenario, plan=human)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("scene").FixValue(context, scenario.scene)
    trajectory = diagram.GetOutputPort("trajectory").Eval(context)
    sequence = ControlSequence.from_trajectory(trajectory, scenario.low_level.step_duration)
    return SceneRollouts(RolloutSpec.of(scenario)).rollout(sequence)
