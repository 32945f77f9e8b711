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
The UR5's numbers, links and joints are in ``ur5_arm.py``; the URDF helpers (primitives, links,
joints, inertias) in ``urdf_writer.py``, shared with ``make_arms.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # ur5_arm.py and urdf_writer.py beside it

from ur5_arm import UR5_JOINTS, arm_joints, arm_links
from urdf_writer import (
    PI,
    Link,
    box,
    box_inertia,
    collision_group,
    combined_inertia,
    cyl,
    cyl_span,
    cylinder_inertia,
    joint_xml,
    nums,
    transmission_xml,
)

OUTPUT = Path(__file__).resolve().parents[2] / "hlp_drake" / "models" / "robot" / "mobile_ur5.urdf"

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
    lines += arm_joints()
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
