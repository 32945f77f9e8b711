"""What the push transfer needs to know: its margins (a ``Scenario``'s ``transfer``) and the robot's sizes.

The sizes (the tcp's offset from the flange, how far the fingertips reach ahead of the tcp, the open
and the closed fingers' half-widths, the palm's, the wrist's radius) are read from the robot model's collision geometry, where
they live, and rounded up to ``SIZE_RESOLUTION`` (``hlp_drake.systems.planning.transfer.gripper_geometry``,
on the Drake side); ``push_rules`` combines them with the margins
into the clearances ``hlp_drake.transfer.push`` works with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Annotated

from hlp_drake.config.ranges import NonNegativeFloat, Positive, PositiveFloat

MIN_TRAVEL_STEP = 1e-4
"""m: the finest step pushes and ways are measured in (their samples grow as its inverse)."""
SIZE_RESOLUTION = 0.005
"""The robot's sizes are rounded up to this (m): the transfer's clearances are set to 5 mm."""


@dataclass(frozen=True)
class TransferConfig:
    """The push transfer's margins and rules (m, rad), beside the robot's sizes (``GripperGeometry``):
    every margin may be 0, every length must be > 0.

    Attributes:
        forward_margin: free approach between the fingertips and an obstacle's face at the start of
            a forward push (the arm comes down there from a transit waypoint, up to 20 degrees off level).
        sideways_margin: the same between the pushing hand's side and the face, sideways: the closed
            fingers', or the palm's where the palm overlaps the obstacle's depth.
        corridor_margin: a backward move (which the robot cannot push) becomes the sideways push
            leaving the least of the obstacle in the corridor along the start-target line, the
            pushing hand's half-width (``GripperGeometry.hand_half_width``) plus this to either side.
        min_push_travel: a push that would move its obstacle less than this is left out.
        edge_margin, object_margin: a push stops this short of the table's edge and the other objects.
        travel_step: pushes are measured in steps of this.
        transit_margin: transit waypoints lift the tcp this far plus the wrist's radius over the tallest
            object.
        wrist_shadow: how far the wrist reaches behind the flange along the approach axis, over the
            table at push height (with the tcp's offset the length of the ``arm_shadow``).
        shadow_margin: the arm's shadow is the wrist's radius or the palm's half-width, the wider,
            plus this to either side.
        path_clearance: a way whose tcp path passes this close to an object goes over it.
        approach_gap: the gripper slides onto the target from this far behind its back face ...
        approach_angle: ... where the way there would come in more than this off the approach axis.
        gripper_behind: the gripper's footprint at that waypoint reaches this far behind the tcp.
    """

    forward_margin: NonNegativeFloat = 0.03
    sideways_margin: NonNegativeFloat = 0.02
    corridor_margin: NonNegativeFloat = 0.025
    min_push_travel: PositiveFloat = 0.01
    edge_margin: NonNegativeFloat = 0.03
    object_margin: NonNegativeFloat = 0.01
    travel_step: Annotated[float, Positive(MIN_TRAVEL_STEP, 0.1)] = 0.005
    transit_margin: NonNegativeFloat = 0.025
    wrist_shadow: PositiveFloat = 0.21
    shadow_margin: NonNegativeFloat = 0.015
    path_clearance: PositiveFloat = 0.02
    approach_gap: PositiveFloat = 0.05
    approach_angle: Annotated[float, Positive()] = math.radians(15.0)
    gripper_behind: PositiveFloat = 0.05


@dataclass(frozen=True)
class GripperGeometry:
    """The robot's sizes the transfer uses, m (``gripper_geometry`` reads them from the model).

    The hand pushes closed (``MotionConfig.closed_among_obstacles``): in plan view, the approach axis
    along +x, it is the closed fingers, ``closed_half_width`` to either side from ``palm_front``
    behind the tcp to ``fingertip_reach`` ahead of it, and the palm, ``palm_half_width`` to either
    side from the flange (``tcp_offset`` behind the tcp) to ``palm_front`` behind it.

    Attributes:
        tcp_offset: the tcp's distance from the flange along the approach axis.
        fingertip_reach: how far the fingertips reach ahead of the tcp.
        finger_half_width: the open fingers' outer sides from the tcp, sideways (onto the target).
        wrist_radius: the radius of the wrist's links.
        closed_half_width: the closed fingers' outer sides from the tcp, sideways.
        palm_half_width: the palm's sides from the tcp, sideways.
        palm_front: how far behind the tcp the palm's front face lies.
    """

    tcp_offset: float
    fingertip_reach: float
    finger_half_width: float
    wrist_radius: float
    closed_half_width: float
    palm_half_width: float
    palm_front: float

    @property
    def hand_half_width(self) -> float:
        """The pushing hand's widest half: its closed fingers' or its palm's."""
        return max(self.closed_half_width, self.palm_half_width)


@dataclass(frozen=True)
class PushRules:
    """The clearances of the push transfer (m, rad): ``TransferConfig``'s margins on the robot's sizes.

    Attributes:
        forward_clearance, sideways_clearance: the tcp's distance from an obstacle's face at the
            start of a push along x, along y (the closed fingers' side); palm_sideways_clearance:
            along y beside an obstacle deeper than ``2 * palm_front`` (the palm's side).
        palm_front: how far behind the tcp the palm begins.
        hand: the pushing hand's footprint around the tcp (approach along +x), each part's (x_min,
            y_min, x_max, y_max): the closed fingers and the palm; a push stops ``object_margin``
            short of sweeping it into another object.
        corridor_half_width: the corridor along the start-target line a backward move should clear.
        transit_clearance: the tcp's height over the tallest object on transit waypoints.
        arm_shadow_length, arm_shadow_half_width: the table area under the gripper and wrist behind
            the tcp at push height; the arm only comes down where nothing lies there.
        gripper_ahead, gripper_half_width, gripper_behind: the gripper's footprint around the tcp.
        way_clearance: a push must not leave its obstacle this close to the way on to the target
            (the pushing hand's half-width).
        The rest: as in ``TransferConfig``.
    """

    forward_clearance: float
    sideways_clearance: float
    palm_sideways_clearance: float
    palm_front: float
    hand: tuple[tuple[float, float, float, float], ...]
    corridor_half_width: float
    transit_clearance: float
    arm_shadow_length: float
    arm_shadow_half_width: float
    gripper_ahead: float
    gripper_half_width: float
    gripper_behind: float
    way_clearance: float
    min_push_travel: float
    edge_margin: float
    object_margin: float
    travel_step: float
    path_clearance: float
    approach_gap: float
    approach_angle: float


def length(value: float) -> float:
    """``value`` rounded to the micrometre: sums of sizes and margins as the decimal numbers they are."""
    return round(value, 6)


def push_rules(config: TransferConfig, geometry: GripperGeometry, *, closed: bool = True) -> PushRules:
    """The clearances of ``config`` for a robot of ``geometry`` that pushes with its fingers
    ``closed`` (``MotionConfig.closed_among_obstacles``), or else open."""
    g = geometry if closed else replace(geometry, closed_half_width=geometry.finger_half_width)
    return PushRules(
        forward_clearance=length(g.fingertip_reach + config.forward_margin),
        sideways_clearance=length(g.closed_half_width + config.sideways_margin),
        palm_sideways_clearance=length(g.palm_half_width + config.sideways_margin),
        palm_front=g.palm_front,
        hand=(
            (-g.palm_front, -g.closed_half_width, g.fingertip_reach, g.closed_half_width),
            (-g.tcp_offset, -g.palm_half_width, -g.palm_front, g.palm_half_width),
        ),
        corridor_half_width=length(g.hand_half_width + config.corridor_margin),
        transit_clearance=length(g.wrist_radius + config.transit_margin),
        arm_shadow_length=length(g.tcp_offset + config.wrist_shadow),
        arm_shadow_half_width=length(max(g.wrist_radius, g.palm_half_width) + config.shadow_margin),
        gripper_ahead=g.fingertip_reach,
        gripper_half_width=g.finger_half_width,
        gripper_behind=config.gripper_behind,
        way_clearance=g.hand_half_width,
        min_push_travel=config.min_push_travel,
        edge_margin=config.edge_margin,
        object_margin=config.object_margin,
        travel_step=config.travel_step,
        path_clearance=config.path_clearance,
        approach_gap=config.approach_gap,
        approach_angle=config.approach_angle,
    )
