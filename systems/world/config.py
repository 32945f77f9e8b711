"""The world's settings in a ``Scenario``: contact, bodies, controller, keypoint IK, motion and grasp.

Frozen dataclasses, read from a scenario file by Drake's typed loader (``hlp_drake.systems.scenario``);
a file only needs the fields it changes::

    plant:
      time_step: 0.005
    controller:
      arm: {kp: 3000.0, kd: 150.0}
    motion:
      tcp_speed: 0.2

The defaults follow the measurements in the project's Drake notes (section F): a discrete plant with
point contact and the SAP solver (the gripper's mimic finger is a coupler constraint, which only SAP
simulates), explicit point-contact stiffness of 1e6 N/m (the default is soft: ~2 mm sag), and small
spheres on the objects' corners and rims so that resting objects neither sink nor tunnel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from pydrake.multibody.plant import MultibodyPlantConfig

EXECUTION_SETTLE_S = 1.0
"""Simulated time the execution lets pass after the reach's trajectory ends before checking it, s."""


def default_plant_config() -> MultibodyPlantConfig:
    """The plant settings of the world: 2 ms steps, point contact, the SAP solver and approximation."""
    return MultibodyPlantConfig(
        time_step=0.002,
        penetration_allowance=0.001,
        stiction_tolerance=1e-4,
        contact_model="point",
        discrete_contact_approximation="sap",
    )


@dataclass(frozen=True)
class PdGains:
    """Gains of a joint PD controller (SI units: N/m and N s/m, or N m/rad and N m s/rad)."""

    kp: float = 0.0
    kd: float = 0.0


@dataclass(frozen=True)
class ContactConfig:
    """Contact materials of the table, the scene objects and the gripper (point contact).

    Attributes:
        stiffness: point-contact stiffness of the table, the objects and the robot's geometry, N/m.
        hunt_crossley_dissipation: dissipation used by the "lagged" and "similar" approximations, s/m.
        relaxation_time: dissipation time scale used by the "sap" approximation, s.
        corner_sphere_radius: radius of the contact spheres put in the corners of every box and
            around the rims of every cylinder (flush with the faces), m; 0 turns them off.
        rim_spheres: number of spheres on each rim of a cylinder.
        top_spheres: put spheres on the top corners and rim too (False: the bottom ones only).
        robot_self_contact: contact between the robot's own links (links one joint apart never
            touch: the plant filters them); False filters every robot-robot pair.
        table_friction, object_friction, gripper_friction: Coulomb friction coefficients (static and
            dynamic); Drake combines two surfaces' coefficients as 2 a b / (a + b).
    """

    stiffness: float = 1.0e6
    hunt_crossley_dissipation: float = 10.0
    relaxation_time: float = 0.01
    corner_sphere_radius: float = 0.001
    rim_spheres: int = 8
    top_spheres: bool = True
    robot_self_contact: bool = True
    table_friction: float = 0.3
    object_friction: float = 0.4
    gripper_friction: float = 0.8


@dataclass(frozen=True)
class BodiesConfig:
    """How a ``Scene`` becomes bodies.

    Attributes:
        table_thickness: thickness of the (welded) table top, m; the top surface is at the table height.
        object_density: density of the free objects, kg/m^3; a mass is then clipped to
            [object_min_mass, object_max_mass] kg.
    """

    table_thickness: float = 0.04
    object_density: float = 400.0
    object_min_mass: float = 0.1
    object_max_mass: float = 0.5


@dataclass(frozen=True)
class ControlConfig:
    """The robot's joint PD controllers (Drake's PD-controlled actuators, implicit in SAP).

    Attributes:
        base: gains of the base's x and y joints (N/m, N s/m).
        base_yaw: gains of the base's yaw joint.
        arm: gains of the UR5's shoulder and elbow joints.
        wrist: gains of the UR5's three wrist joints.
        gripper: gains of the actuated finger.
        gravity_compensation: add the robot's gravity torques as feed-forward actuation (computed on
            a robot-only model), so the arm holds its commanded pose without steady-state sag.
    """

    base: PdGains = field(default_factory=lambda: PdGains(kp=2.0e4, kd=4.0e3))
    base_yaw: PdGains = field(default_factory=lambda: PdGains(kp=1.0e4, kd=2.0e3))
    arm: PdGains = field(default_factory=lambda: PdGains(kp=2.0e3, kd=150.0))
    wrist: PdGains = field(default_factory=lambda: PdGains(kp=300.0, kd=10.0))
    gripper: PdGains = field(default_factory=lambda: PdGains(kp=2.0e3, kd=20.0))
    gravity_compensation: bool = True


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

    height: float = 0.06
    position_tolerance: float = 0.001
    approach_tolerance: float = 0.35
    roll_tolerance: float = 0.05
    table_clearance: float = 0.01
    base_under_table: float = 0.0
    base_lateral_margin: float = 0.50
    base_max_yaw: float = math.pi / 2
    start_reach: float = 1.10
    start_base_clearance: float = 0.05
    max_iterations: int = 100
    attempts: int = 5


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

    tcp_speed: float = 0.1
    transit_speed: float = 0.25
    joint_speed_fraction: float = 0.5
    min_segment_duration: float = 0.25
    closed_among_obstacles: bool = True


@dataclass(frozen=True)
class GraspConfig:
    """The grasp after a successful reach: close the fingers, then lift the tcp straight up.

    Attributes:
        close_s: time to close the fingers, s.
        lift_height: how far the tcp rises, m.
        lift_s: time of the lift, s.
        hold_s: time held at the top before the check, s.
        held_height: the grasp held when the target rose at least this far, m.
    """

    close_s: float = 1.0
    lift_height: float = 0.10
    lift_s: float = 1.5
    hold_s: float = 0.5
    held_height: float = 0.05
