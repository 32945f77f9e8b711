"""The pushing hand the transfer plans with: the robot model's sizes (closed fingers, palm) and the
clearances it takes from them."""

from __future__ import annotations

import dataclasses

import pytest
from human_plans import GEN1_25, human_plan

from hlp_drake.systems.planning.transfer import gripper_geometry
from hlp_drake.taskspace import TaskSpace
from hlp_drake.transfer.rules import TransferConfig, push_rules

RULES = push_rules(TransferConfig(), gripper_geometry())


def test_the_transfers_clearances_are_the_robot_models_sizes_plus_the_margins():
    geometry = gripper_geometry()  # the tcp 14 cm ahead of the flange, the fingertips 2 cm ahead of it
    sizes = {"tcp_offset": 0.14, "fingertip_reach": 0.02, "finger_half_width": 0.055, "wrist_radius": 0.045}
    hand = {"closed_half_width": 0.015, "palm_half_width": 0.065, "palm_front": 0.035}  # it pushes closed
    assert dataclasses.asdict(geometry) == {**sizes, **hand}
    clearances = {
        "forward_clearance": 0.05,
        "sideways_clearance": 0.035,  # the closed fingers' side 2 cm from the face
        "palm_sideways_clearance": 0.085,  # beside an obstacle deeper than 7 cm, the palm's
        "corridor_half_width": 0.09,  # the hand's widest, the palm's, plus 2.5 cm
        "way_clearance": 0.065,
        "transit_clearance": 0.07,
        "arm_shadow_length": 0.35,
        "arm_shadow_half_width": 0.08,
        "hand": ((-0.035, -0.015, 0.02, 0.015), (-0.14, -0.065, -0.035, 0.065)),
    }
    assert {name: getattr(RULES, name) for name in clearances} == clearances
    wider = push_rules(TransferConfig(sideways_margin=0.03), geometry)
    assert wider.sideways_clearance == 0.045 and wider.forward_clearance == RULES.forward_clearance


@pytest.mark.parametrize("name", ["mobile_ur5", "panda", "iiwa14"])
def test_every_robot_pushes_with_its_closed_fingers_and_palm_as_its_model_has_them(name):
    """Push starts are spaced for the closed fingers the hand pushes with (the palm's side beside a
    deep obstacle), and a push stops before the palm, trailing behind the fingers, sweeps into an
    object behind the pushed one (the Panda's Gen I seed 34: its 0.20 m palm swept a box into row 2)."""
    from hlp_drake.scene.model import Scene, SceneObject, Table
    from hlp_drake.systems.world.robot_description import load_robot
    from hlp_drake.transfer.push import robot_push

    geometry = gripper_geometry(load_robot(name))
    assert geometry.closed_half_width < geometry.finger_half_width  # it pushes closed
    assert geometry.palm_half_width > geometry.closed_half_width and geometry.palm_front > 0.0
    rules = push_rules(TransferConfig(), geometry)
    margin = TransferConfig().sideways_margin

    def scene(depth: float, behind: tuple[float, float] | None) -> Scene:
        pushed = SceneObject("pushed", "box", 0.40, 0.0, (depth, 0.10, 0.12))
        others = () if behind is None else (SceneObject("behind", "box", *behind, (0.04, 0.05, 0.12)),)
        target = SceneObject("Target", "cylinder", 0.70, 0.0, (0.06, 0.06, 0.12))
        return Scene(Table(0.8, 0.9, 0.75), (0.1, 0.0), target, (pushed, *others), name="push")

    shallow = scene(0.05, None)
    push = robot_push(rules, TaskSpace(shallow), shallow, "pushed", "LL", TaskSpace(shallow).rects)
    assert push.start[1] == pytest.approx(-0.05 - geometry.closed_half_width - margin)
    deep = scene(2 * geometry.palm_front + 0.02, None)
    push = robot_push(rules, TaskSpace(deep), deep, "pushed", "LL", TaskSpace(deep).rects)
    assert push.start[1] == pytest.approx(-0.05 - geometry.palm_half_width - margin)

    palm_x = 0.40 - (geometry.tcp_offset + geometry.palm_front) / 2.0  # under the palm, behind the box
    behind = scene(0.05, (palm_x, 0.12))
    space = TaskSpace(behind)
    free = robot_push(rules, space, shallow, "pushed", "LL", TaskSpace(shallow).rects)
    swept = robot_push(rules, space, behind, "pushed", "LL", space.rects)
    assert swept.start == free.start and 0.0 < swept.travel < free.travel
    palm_side = swept.end[1] + geometry.palm_half_width
    assert palm_side <= space.rects["behind"].y_min - rules.object_margin + 1e-9  # stopped short of it
    assert (
        palm_side + rules.travel_step >= space.rects["behind"].y_min - rules.object_margin - 1e-9
    )  # not sooner


def test_a_hand_that_pushes_open_is_spaced_for_its_open_fingers_in_the_block_too():
    """``motion.closed_among_obstacles: false``: the pushes are made with the fingers open, and the
    push starts (``push_rules(closed=False)``, the transfer block of such a scenario) are spaced
    for the open fingers."""
    from hlp_drake.scene.generators import generate_scene
    from hlp_drake.systems.planning.diagram import make_planning_diagram
    from hlp_drake.systems.scenario import Scenario

    geometry = gripper_geometry()
    opened = push_rules(TransferConfig(), geometry, closed=False)
    margin = TransferConfig().sideways_margin
    assert opened.sideways_clearance == pytest.approx(geometry.finger_half_width + margin)
    assert RULES.sideways_clearance == pytest.approx(geometry.closed_half_width + margin)
    assert (
        opened.hand[0][3] == geometry.finger_half_width
        and opened.palm_sideways_clearance == RULES.palm_sideways_clearance
    )

    scene = generate_scene("gen1", 25)  # a push to the right first
    starts = {}
    for closed in (True, False):
        scenario = Scenario(scene=scene).updated(f"motion: {{closed_among_obstacles: {str(closed).lower()}}}")
        transfer = make_planning_diagram(scenario).GetSubsystemByName("robot_plan_transfer")
        context = transfer.CreateDefaultContext()
        transfer.GetInputPort("scene").FixValue(context, scene)
        transfer.GetInputPort("plan").FixValue(context, human_plan(scene, GEN1_25))
        plan = transfer.GetOutputPort("robot_plan").Eval(context)
        starts[closed] = [k.position for k in plan.keypoints if k.action == "move"]
    assert starts[True] and starts[True] != starts[False]
