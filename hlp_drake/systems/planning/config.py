"""The settings of keypoint IK and of the trajectory's timing (a ``Scenario``'s ``ik`` and ``motion``):
plain dataclasses, no Drake (the world's start pose reads ``IkConfig`` too)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated

from hlp_drake.config.ranges import MAX_DURATION, Count, NonNegativeFloat, Positive, PositiveFloat

DEFAULT_ALTERNATIVES = 3
"""The initialiser's alternatives by default (a ``Scenario``'s ``planner.alternatives``)."""
MIN_SPEED = 0.01
"""m/s: the slowest tcp speed (with MAX_DURATION per segment, a run's trajectory stays bounded)."""
SPEED = Positive(MIN_SPEED, 10.0)


@dataclass(frozen=True)
class IkConfig:
    """Keypoint inverse kinematics (``KeypointIk`` and the start configuration).

    The gripper approaches horizontally along world +x (tcp +z), its fingers opening sideways (tcp +y
    horizontal), with the tcp ``height`` above the table top at every keypoint.

    Attributes:
        height: tcp height above the table top at the keypoints, m (below the objects' tops, so the
            fingers can close round the target and push obstacles).
        position_tolerance: half-width of the box the tcp must reach around a keypoint, m.
        approach_tolerance: largest angle between the approach axis (tcp +z) and world +x, rad.
        roll_tolerance: largest angle between the finger axis (tcp +y) and the horizontal plane, rad.
        table_clearance: smallest distance between the robot and the table top (and between the
            robot's own links), m. Contact with objects is allowed (they may be pushed).
        base_under_table: how far the base's front may go under the table top past its front edge, m
            (the table has no legs and the deck is lower than the table top, but the riser under the
            arm, 0.015 m behind the base's front and as high as the table, must stay in front of it).
        base_lateral_margin: the base's centre stays within the table's width plus this on each side, m.
        base_max_yaw: largest turn of the base away from facing +x, rad.
        start_reach: horizontal distance from the base's centre to the tcp at the start, m.
        start_base_clearance: smallest gap between the base's front and the table edge at the start, m.
        max_iterations: SNOPT major-iteration limit per solve (minor iterations: 50 times it). A
            solve that stops at the limit counts when its iterate meets every constraint: SNOPT
            often lingers at a converged point of the clearance constraint, so 100 gives the keyframes
            500 gives (308 of 310 Gen I/II scenes the same within 1e-4) in 0.42 of the IK time.
        attempts: solves per keypoint (the previous keyframe, then seeds with the base shifted, then
            a continuation along the tcp's straight line).
    """

    height: PositiveFloat = 0.06
    position_tolerance: PositiveFloat = 0.001
    approach_tolerance: PositiveFloat = 0.35
    roll_tolerance: PositiveFloat = 0.05
    table_clearance: NonNegativeFloat = 0.01
    base_under_table: NonNegativeFloat = 0.0
    base_lateral_margin: NonNegativeFloat = 0.50
    base_max_yaw: PositiveFloat = math.pi / 2
    start_reach: PositiveFloat = 1.10
    start_base_clearance: NonNegativeFloat = 0.05
    max_iterations: Annotated[int, Count(1, 100_000)] = 100
    attempts: Annotated[int, Count(1, 1000)] = 5


@dataclass(frozen=True)
class MotionConfig:
    """Timing of the joint trajectory through the keyframes (straight lines in joint space).

    A segment lasts the longest of: its tcp path length over ``tcp_speed`` (``transit_speed`` on the
    way to or from a waypoint lifted clear of the objects), each joint's travel over
    ``joint_speed_fraction`` of its velocity limit, and ``min_segment_duration``.

    With ``closed_among_obstacles`` the gripper closes on the way to the first keyframe and stays
    closed through the pushes, gaps and transits, opening on the way to the "approach" keyframe
    (in place before sliding onto the target if there is none): open fingers straddle a small
    obstacle and carry it along into the target. Keyframes are solved open either way (the tcp
    does not depend on the fingers).
    """

    tcp_speed: Annotated[float, SPEED] = 0.1
    transit_speed: Annotated[float, SPEED] = 0.25
    joint_speed_fraction: Annotated[float, Positive(0.01, 1.0)] = 0.5
    min_segment_duration: Annotated[float, Positive(upper=MAX_DURATION)] = 0.25
    closed_among_obstacles: bool = True


__all__ = ["DEFAULT_ALTERNATIVES", "MIN_SPEED", "SPEED", "IkConfig", "MotionConfig"]
