"""Write ``mobile_ur5.urdf``: a UR5 arm with a two-finger gripper on an omnidirectional base.

A development script, never imported by ``hlp_drake`` at run time. It writes the URDF into
``hlp_drake/models/robot`` deterministically (the same text on every run), so the checked-in file
can be regenerated and compared::

    python tools/robot_models/make_mobile_ur5.py            # (re)write mobile_ur5.urdf
    python tools/robot_models/make_mobile_ur5.py --check    # exit 1 if the checked-in file is stale

The model, in the base's frame (x forward, y left, z up, origin on the floor below the middle of
the footprint):

* Base: a Ridgeback-sized body (0.96 x 0.79 m, top deck at 0.30 m, 135 kg) driven by three joints
  from the world: prismatic ``base_x_joint``, prismatic ``base_y_joint``, revolute
  ``base_yaw_joint``, through two nearly massless links.
* Riser: a round column (0.15 m across, 15 kg) on the deck, part of ``base_link``, lifting the arm's
  mount to 0.80 m, 0.09 m behind the base's front (the column's front 0.015 m behind it). The
  height is measured, not guessed: with the tcp held horizontal along +x at 0.06 m above a table
  top (the keypoint IK's grasp, 0.01 m clearance to the table), the tcp reaches past the table's
  front edge 0.85 m (0.70 m table) and 0.73 m (0.80 m table) from a 0.60 m mount, whose shoulder
  then sits below the table top and has to lift the arm over the edge, but 0.96 m for both from
  0.80 m: with the shoulder about level with the wrist the arm stretches out flat over the table,
  and only the column (and the UR5's base on it) must stay in front of the table's edge.
* Arm: a UR5 on the riser near the base's front, at zero joint angles stretched out along +x. The
  links follow UR's own layout (shoulder, elbow and wrist offsets), which reproduces the official DH
  kinematics exactly: link ``ur5_base`` is the DH base frame (the arm mount turned by pi about z)
  and link ``ur5_flange`` is the DH tool flange frame. Masses are the official ones, centres of mass
  UR's published ones; inertias treat each link as a solid cylinder.
* Gripper: Robotiq 2F-85 dimensions, two prismatic fingers with 0-0.0425 m stroke each (85 mm
  opening). ``left_finger_joint`` is actuated; ``right_finger_joint`` follows it through a URDF
  ``<mimic>``, which Drake turns into a coupler constraint (discrete plant with the SAP solver).
  Link ``tcp`` lies between the fingertip pads, +z along the approach direction, +y along the
  left finger's opening direction.

Geometry is primitives only (boxes and cylinders). Wheels, caps, rings and stripes are visual only.
The URDF helpers (primitives, links, joints, inertias) are in ``urdf_writer.py``, shared with
``make_arms.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # urdf_writer.py beside this script

from urdf_writer import (
    IDENTITY,
    PI,
    Link,
    Pose,
    Vec,
    add,
    apply,
    box,
    box_inertia,
    collision_group,
    combined_inertia,
    compose,
    cyl,
    cyl_span,
    cylinder_inertia,
    joint_xml,
    nums,
    rot,
    rpy_matrix,
    sub,
    transmission_xml,
    transpose,
)

OUTPUT = Path(__file__).resolve().parents[2] / "hlp_drake" / "models" / "robot" / "mobile_ur5.urdf"

# --- UR5 (official DH parameters, link masses, centres of mass in the DH link frames) -----------
UR5_DH = (  # (d, a, alpha) of links 1..6
    (0.089159, 0.0, PI / 2),
    (0.0, -0.425, 0.0),
    (0.0, -0.39225, 0.0),
    (0.10915, 0.0, PI / 2),
    (0.09465, 0.0, -PI / 2),
    (0.0823, 0.0, 0.0),
)
UR5_MASSES = (4.0, 3.7, 8.393, 2.275, 1.219, 1.219, 0.1879)  # base, shoulder ... wrist 3
UR5_COMS_DH = (  # centre of mass of links 1..6 in DH frame i
    (0.0, -0.02561, 0.00193),
    (0.2125, 0.0, 0.11336),
    (0.15, 0.0, 0.0265),
    (0.0, -0.0018, 0.01634),
    (0.0, 0.0018, 0.01634),
    (0.0, 0.0, -0.001159),
)
SHOULDER_OFFSET = 0.13585  # lateral offsets of UR's layout; they add up to d4:
ELBOW_OFFSET = -0.1197  # 0.13585 - 0.1197 + 0.093 = 0.10915
WRIST_1_OFFSET = 0.093

BIG_EFFORT, SMALL_EFFORT = 150.0, 28.0

# --- Base (Clearpath Ridgeback sized) ----------------------------------------------------------
BASE_LENGTH, BASE_WIDTH, DECK_HEIGHT = 0.96, 0.79, 0.30
BASE_MASS = 135.0  # the base without the riser
BASE_TRAVEL = 10.0  # +- m along world x and y
BASE_SPEED, BASE_YAW_RATE = 1.0, 2.0
BASE_FORCE, BASE_TORQUE = 1000.0, 400.0
WHEEL_RADIUS, WHEEL_WIDTH = 0.0762, 0.06

# --- Riser: a column on the deck lifting the arm's mount to about table height -------------------
MOUNT_HEIGHT = 0.80  # top of the riser = the arm's mount, m above the floor (see the docstring)
RISER_RADIUS = 0.075  # a round column under the mount, as wide as the UR5's base
RISER_MASS = 15.0  # a steel tube (150 mm, 8 mm wall) with its flanges
ARM_MOUNT_XYZ = (0.39, 0.0, MOUNT_HEIGHT)  # arm base on the riser, 0.09 m behind the base's front

# --- Gripper (Robotiq 2F-85 sized) --------------------------------------------------------------
GRIPPER_MASS, FINGER_MASS = 0.85, 0.04
FINGER_STROKE = 0.0425  # per finger: 0 closed, 0.0425 open (85 mm between the pads)
FINGER_SPEED, FINGER_FORCE, FINGER_DAMPING = 0.075, 100.0, 10.0
PALM_SIZE = (0.06, 0.13, 0.091)  # x (palm normal), y (opening), z (approach)
PALM_BOTTOM = 0.014  # the coupling disc sits below the palm
FINGER_SIZE = (0.022, 0.012, 0.065)  # thickness along y; spans z 0.095 .. 0.160
FINGER_TOP, FINGER_TIP = 0.095, 0.160
TCP_DEPTH = 0.14  # tcp along the approach axis from the flange: mid-pad, 20 mm in from the tips

MATERIALS = {
    "ur_grey": (0.78, 0.80, 0.83, 1.0),
    "ur_blue": (0.42, 0.62, 0.80, 1.0),
    "ur_dark": (0.16, 0.17, 0.19, 1.0),
    "gripper_black": (0.08, 0.08, 0.09, 1.0),
    "pad_grey": (0.30, 0.30, 0.32, 1.0),
    "base_dark": (0.22, 0.23, 0.25, 1.0),
    "base_black": (0.06, 0.06, 0.06, 1.0),
    "base_yellow": (0.96, 0.76, 0.10, 1.0),
}


# UR layout of the arm: (joint, parent, child, origin xyz, origin rpy, axis) in the parent link.
UR5_JOINTS = (
    ("shoulder_pan_joint", "ur5_base_link", "shoulder_link", (0, 0, UR5_DH[0][0]), (0, 0, 0), (0, 0, 1)),
    (
        "shoulder_lift_joint",
        "shoulder_link",
        "upper_arm_link",
        (0, SHOULDER_OFFSET, 0),
        (0, PI / 2, 0),
        (0, 1, 0),
    ),
    ("elbow_joint", "upper_arm_link", "forearm_link", (0, ELBOW_OFFSET, -UR5_DH[1][1]), (0, 0, 0), (0, 1, 0)),
    ("wrist_1_joint", "forearm_link", "wrist_1_link", (0, 0, -UR5_DH[2][1]), (0, PI / 2, 0), (0, 1, 0)),
    ("wrist_2_joint", "wrist_1_link", "wrist_2_link", (0, WRIST_1_OFFSET, 0), (0, 0, 0), (0, 0, 1)),
    ("wrist_3_joint", "wrist_2_link", "wrist_3_link", (0, 0, UR5_DH[4][0]), (0, 0, 0), (0, 1, 0)),
)
FLANGE_ORIGIN = ((0, UR5_DH[5][0], 0), (-PI / 2, 0, 0))  # ur5_flange in wrist_3_link


def ur5_coms() -> list[Vec]:
    """Centres of mass of links 1..6 expressed in this model's link frames (at q = 0 both agree)."""
    dh_pose: Pose = (rot("z", PI), (0.0, 0.0, 0.0))  # DH base in ur5_base_link
    link_pose: Pose = (IDENTITY, (0.0, 0.0, 0.0))
    coms = []
    for (d, a, alpha), com, joint in zip(UR5_DH, UR5_COMS_DH, UR5_JOINTS):
        dh_pose = compose(dh_pose, (rot("x", alpha), (a, 0.0, d)))
        link_pose = compose(link_pose, (rpy_matrix(*joint[4]), tuple(float(v) for v in joint[3])))
        p_world = add(dh_pose[1], apply(dh_pose[0], com))
        coms.append(apply(transpose(link_pose[0]), sub(p_world, link_pose[1])))
    return coms


# --- The model -----------------------------------------------------------------------------------
def base_links() -> list[Link]:
    tiny = (1e-5, 1e-5, 1e-5)
    x_link = Link("base_x_link", "nearly massless links between the planar base joints").mass(
        0.01, (0, 0, 0), tiny
    )
    y_link = Link("base_y_link").mass(0.01, (0, 0, 0), tiny)
    base = Link("base_link", "omnidirectional base, origin on the floor below the middle of the footprint")
    body_h = DECK_HEIGHT - 0.03
    riser_h = MOUNT_HEIGHT - DECK_HEIGHT
    riser_centre = (ARM_MOUNT_XYZ[0], ARM_MOUNT_XYZ[1], DECK_HEIGHT + riser_h / 2.0)
    base.mass(
        *combined_inertia(
            [
                (
                    BASE_MASS,
                    (0.0, 0.0, 0.03 + body_h / 2.0),
                    box_inertia(BASE_MASS, (BASE_LENGTH, BASE_WIDTH, body_h)),
                ),
                (RISER_MASS, riser_centre, cylinder_inertia(RISER_MASS, RISER_RADIUS, riser_h, "z")),
            ]
        )
    )
    half_l, half_w = BASE_LENGTH / 2.0, BASE_WIDTH / 2.0
    base.add(box((0, 0, 0.19), (BASE_LENGTH, BASE_WIDTH, 0.18)), "base_dark", collide=False)
    base.add(box((0, 0, 0.29), (BASE_LENGTH, BASE_WIDTH, 0.02)), "base_black", collide=False)
    base.collisions.append(
        box((0, 0, 0.20), (BASE_LENGTH, BASE_WIDTH, 0.20))
    )  # body and deck: z 0.10 .. 0.30
    base.add(box((0, 0, 0.065), (0.60, 0.50, 0.07)), "base_black")  # belly between the wheels, z 0.03 .. 0.10
    for sx in (1, -1):  # yellow bumper strips front and back, stripes along the sides
        base.add(
            box((sx * (half_l + 0.004), 0, 0.20), (0.008, BASE_WIDTH - 0.08, 0.04)),
            "base_yellow",
            collide=False,
        )
    for sy in (1, -1):
        base.add(
            box((0, sy * (half_w + 0.004), 0.22), (BASE_LENGTH - 0.10, 0.008, 0.025)),
            "base_yellow",
            collide=False,
        )
    for sx in (1, -1):  # mecanum wheels under the body
        for sy in (1, -1):
            base.add(
                cyl("y", (sx * 0.32, sy * 0.30, WHEEL_RADIUS), WHEEL_RADIUS, WHEEL_WIDTH),
                "base_black",
                collide=False,
            )
            base.add(
                cyl("y", (sx * 0.32, sy * (0.30 + WHEEL_WIDTH / 2.0 + 0.002), WHEEL_RADIUS), 0.03, 0.004),
                "base_yellow",
                collide=False,
            )
    # The riser: a column on the deck under the arm's mount, with a foot and a top plate (visual).
    base.add(cyl("z", riser_centre, RISER_RADIUS, riser_h), "base_dark")
    mount_xy = (ARM_MOUNT_XYZ[0], ARM_MOUNT_XYZ[1])
    base.add(  # foot flange on the deck, inside the base's outline
        box((*mount_xy, DECK_HEIGHT + 0.006), (0.15, 0.22, 0.012)), "ur_dark", collide=False
    )
    ring = RISER_RADIUS + 0.002
    base.add(cyl("z", (*mount_xy, MOUNT_HEIGHT - 0.006), ring, 0.012), "ur_dark", collide=False)  # top flange
    base.add(cyl("z", (*mount_xy, MOUNT_HEIGHT - 0.08), ring, 0.03), "base_yellow", collide=False)  # stripe
    return [x_link, y_link, base]


def arm_links() -> list[Link]:
    _, m1, m2, m3, m4, m5, m6 = UR5_MASSES
    c1, c2, c3, c4, c5, c6 = ur5_coms()
    d1, d5, d6 = UR5_DH[0][0], UR5_DH[4][0], UR5_DH[5][0]
    upper, fore = -UR5_DH[1][1], -UR5_DH[2][1]
    r_big, r_mid, r_small = 0.06, 0.05, 0.045

    base = Link(
        "ur5_base_link", "UR5: arm mount on the riser, x forward; the arm stretches along +x at q = 0"
    )
    base.mass(UR5_MASSES[0], (0, 0, 0.019), cylinder_inertia(UR5_MASSES[0], 0.075, 0.038, "z"))
    base.add(cyl_span("z", 0.0, 0.038, 0.075), "ur_grey")
    base.add(cyl_span("z", 0.038, 0.044, 0.062), "ur_dark", collide=False)

    # Shoulder: vertical J1 housing, z from 0.04 above the mount (frame at d1 above it).
    shoulder = Link("shoulder_link").mass(m1, c1, cylinder_inertia(m1, r_big, 0.15, "z"))
    shoulder.add(cyl_span("z", 0.044 - d1, 0.07, r_big), "ur_grey")
    shoulder.add(cyl_span("z", 0.07, 0.076, 0.045), "ur_blue", collide=False)
    shoulder.add(cyl_span("y", 0.0, SHOULDER_OFFSET - 0.045, r_big), "ur_grey")
    shoulder.add(
        cyl_span("y", SHOULDER_OFFSET - 0.045, SHOULDER_OFFSET - 0.039, 0.052), "ur_dark", collide=False
    )

    # Upper arm: frame on the J2 axis, z along the arm, y along the joint axes.
    upper_arm = Link("upper_arm_link").mass(m2, c2, cylinder_inertia(m2, r_big, upper, "z"))
    upper_arm.add(cyl_span("y", -0.039, 0.06, r_big), "ur_grey")
    upper_arm.add(cyl_span("y", 0.06, 0.066, 0.045), "ur_blue", collide=False)
    upper_arm.add(cyl_span("z", 0.0, upper, 0.045), "ur_grey")
    elbow_y = ELBOW_OFFSET
    upper_arm.add(cyl_span("y", -0.06, 0.05, r_mid, at=(0, 0, upper)), "ur_grey")
    upper_arm.add(cyl_span("y", 0.05, 0.056, 0.038, at=(0, 0, upper)), "ur_blue", collide=False)
    upper_arm.add(cyl_span("y", -0.066, -0.06, 0.044, at=(0, 0, upper)), "ur_dark", collide=False)

    # Forearm: frame on the J3 axis, in the plane 0.1197 m nearer the pan axis than the upper arm.
    forearm = Link("forearm_link").mass(m3, c3, cylinder_inertia(m3, 0.04, fore, "z"))
    forearm.add(cyl_span("y", -0.045, -elbow_y - 0.066, r_mid), "ur_grey")
    forearm.add(cyl_span("y", -0.051, -0.045, 0.038), "ur_blue", collide=False)
    forearm.add(cyl_span("z", 0.0, fore - 0.04, 0.038), "ur_grey")

    # Wrist 1: frame on the J4 axis (y), the J5 axis 0.093 m further along y.
    wrist_1 = Link("wrist_1_link").mass(m4, c4, cylinder_inertia(m4, r_small, 0.12, "y"))
    wrist_1.add(cyl_span("y", -0.045, WRIST_1_OFFSET - r_small, r_small), "ur_grey")
    wrist_1.add(cyl_span("y", -0.051, -0.045, 0.035), "ur_blue", collide=False)
    wrist_1.add(
        cyl_span("y", WRIST_1_OFFSET - r_small, WRIST_1_OFFSET - r_small + 0.006, 0.04),
        "ur_dark",
        collide=False,
    )

    # Wrist 2: frame on the J5 axis (z), the J6 axis d5 further along z.
    wrist_2 = Link("wrist_2_link").mass(m5, c5, cylinder_inertia(m5, r_small, 0.12, "z"))
    wrist_2.add(cyl_span("z", -r_small, d5 - r_small, r_small), "ur_grey")
    wrist_2.add(cyl_span("z", -r_small - 0.006, -r_small, 0.035), "ur_blue", collide=False)
    wrist_2.add(cyl_span("z", d5 - r_small, d5 - r_small + 0.006, 0.04), "ur_dark", collide=False)

    # Wrist 3: frame on the J6 axis (y); the tool flange d6 along y.
    wrist_3 = Link("wrist_3_link").mass(m6, c6, cylinder_inertia(m6, 0.0375, 0.03, "y"))
    wrist_3.add(cyl_span("y", -r_small + 0.006, d6 - 0.012, r_small), "ur_grey")
    wrist_3.add(cyl_span("y", -r_small, -r_small + 0.006, 0.035), "ur_blue", collide=False)
    wrist_3.add(cyl_span("y", d6 - 0.012, d6, 0.0315), "ur_dark")

    dh_base = Link(
        "ur5_base", "the UR5's DH base frame (as UR's controller reports it): the mount turned by pi"
    )
    flange = Link("ur5_flange", "the UR5's DH tool flange frame (ROS tool0): z out of the flange")
    return [base, shoulder, upper_arm, forearm, wrist_1, wrist_2, wrist_3, dh_base, flange]


def gripper_links() -> list[Link]:
    gripper = Link("gripper_base_link", "two-finger gripper (Robotiq 2F-85 sized); frame = ur5_flange")
    px, py, pz = PALM_SIZE
    palm_centre = PALM_BOTTOM + pz / 2.0
    gripper.mass(GRIPPER_MASS, (0, 0, palm_centre), box_inertia(GRIPPER_MASS, (px, py, pz + PALM_BOTTOM)))
    gripper.add(cyl_span("z", 0.0, PALM_BOTTOM, 0.0375), "ur_dark")
    gripper.add(box((0, 0, palm_centre), PALM_SIZE), "gripper_black")
    gripper.add(
        box((0, 0, PALM_BOTTOM + pz - 0.004), (px + 0.004, py - 0.03, 0.008)), "pad_grey", collide=False
    )
    fx, fy, _ = FINGER_SIZE
    fingers = []
    for side, sy in (("left", 1.0), ("right", -1.0)):
        finger = Link(
            f"{side}_finger_link",
            "finger frame = gripper frame moved by q along its axis; inner face on y = +-q"
            if side == "left"
            else "",
        )
        centre = (0.0, sy * fy / 2.0, (FINGER_TOP + FINGER_TIP) / 2.0)
        finger.mass(FINGER_MASS, centre, box_inertia(FINGER_MASS, FINGER_SIZE))
        finger.add(box(centre, FINGER_SIZE), "gripper_black")
        pad_z = (TCP_DEPTH - 0.025 + FINGER_TIP) / 2.0
        finger.add(
            box((0.0, sy * 0.001, pad_z), (fx - 0.004, 0.0025, FINGER_TIP - TCP_DEPTH + 0.025 - 0.004)),
            "pad_grey",
            collide=False,
        )
        fingers.append(finger)
    tcp = Link("tcp", "tool centre point between the fingertip pads: z = approach, y = left finger opening")
    return [gripper, *fingers, tcp]


ARM_LIMITS = (  # (lower, upper, effort) per UR5 joint; velocity pi rad/s for all
    (-2 * PI, 2 * PI, BIG_EFFORT),
    (-2 * PI, 2 * PI, BIG_EFFORT),
    (-PI, PI, BIG_EFFORT),
    (-2 * PI, 2 * PI, SMALL_EFFORT),
    (-2 * PI, 2 * PI, SMALL_EFFORT),
    (-2 * PI, 2 * PI, SMALL_EFFORT),
)
ACTUATED = (
    ("base_x_joint", "base_y_joint", "base_yaw_joint")
    + tuple(j[0] for j in UR5_JOINTS)
    + ("left_finger_joint",)
)


def joints() -> list[str]:
    lines: list[str] = []
    lines += joint_xml(
        "base_x_joint",
        "prismatic",
        "world",
        "base_x_link",
        axis=(1, 0, 0),
        limit=(-BASE_TRAVEL, BASE_TRAVEL, BASE_FORCE, BASE_SPEED),
    )
    lines += joint_xml(
        "base_y_joint",
        "prismatic",
        "base_x_link",
        "base_y_link",
        axis=(0, 1, 0),
        limit=(-BASE_TRAVEL, BASE_TRAVEL, BASE_FORCE, BASE_SPEED),
    )
    lines += joint_xml(
        "base_yaw_joint",
        "revolute",
        "base_y_link",
        "base_link",
        axis=(0, 0, 1),
        limit=(-2 * PI, 2 * PI, BASE_TORQUE, BASE_YAW_RATE),
    )
    lines += joint_xml("arm_mount_joint", "fixed", "base_link", "ur5_base_link", ARM_MOUNT_XYZ)
    lines += joint_xml("ur5_base_joint", "fixed", "ur5_base_link", "ur5_base", rpy=(0, 0, PI))
    for (name, parent, child, xyz, rpy, axis), (lower, upper, effort) in zip(UR5_JOINTS, ARM_LIMITS):
        lines += joint_xml(
            name, "revolute", parent, child, xyz, rpy, axis=axis, limit=(lower, upper, effort, PI)
        )
    lines += joint_xml("ur5_flange_joint", "fixed", "wrist_3_link", "ur5_flange", *FLANGE_ORIGIN)
    lines += joint_xml("gripper_mount_joint", "fixed", "ur5_flange", "gripper_base_link")
    finger_limit = (0.0, FINGER_STROKE, FINGER_FORCE, FINGER_SPEED)
    lines += joint_xml(
        "left_finger_joint",
        "prismatic",
        "gripper_base_link",
        "left_finger_link",
        axis=(0, 1, 0),
        limit=finger_limit,
        damping=FINGER_DAMPING,
    )
    lines += joint_xml(
        "right_finger_joint",
        "prismatic",
        "gripper_base_link",
        "right_finger_link",
        axis=(0, -1, 0),
        limit=finger_limit,
        damping=FINGER_DAMPING,
        mimic="left_finger_joint",
    )
    lines += joint_xml("tcp_joint", "fixed", "gripper_base_link", "tcp", (0, 0, TCP_DEPTH))
    return lines


def urdf() -> str:
    lines = [
        '<?xml version="1.0"?>',
        "<!-- Generated by make_mobile_ur5.py in this folder; edit that script, not this file. -->",
        '<robot name="mobile_ur5" xmlns:drake="http://drake.mit.edu">',
    ]
    for name, rgba in MATERIALS.items():
        lines.append(f'  <material name="{name}"><color rgba="{nums(rgba)}"/></material>')
    for link in base_links() + arm_links() + gripper_links():
        lines += link.xml()
    lines += joints()
    for joint in ACTUATED:  # actuator order = this order
        lines += transmission_xml(joint)
    lines += collision_group("ur5_wrist", ("wrist_1_link", "wrist_2_link", "wrist_3_link"))
    lines += collision_group(
        "gripper", ("wrist_3_link", "gripper_base_link", "left_finger_link", "right_finger_link")
    )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only compare with the checked-in file")
    parser.add_argument("--out", type=Path, default=OUTPUT, help=f"output file (default {OUTPUT.name})")
    args = parser.parse_args(argv)
    text = urdf()
    if args.check:
        current = args.out.read_text() if args.out.exists() else ""
        if current != text:
            print(f"{args.out} is stale: run python {Path(__file__).name}", file=sys.stderr)
            return 1
        print(f"{args.out} is up to date")
        return 0
    args.out.write_text(text)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
