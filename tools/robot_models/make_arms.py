"""Write ``panda.urdf`` and ``iiwa14.urdf``: two fixed-base 7-DOF arms with parallel grippers on pedestals.

A development script, never imported by ``hlp_drake`` at run time. It writes both URDFs into
``hlp_drake/models/robot`` deterministically (the same text on every run), so the checked-in files can be regenerated and
compared::

    python tools/robot_models/make_arms.py            # (re)write panda.urdf and iiwa14.urdf
    python tools/robot_models/make_arms.py --check    # exit 1 if a checked-in file is stale

Each model's root link is its pedestal (``panda_pedestal``, ``iiwa14_pedestal``: origin on the floor
on the column's axis, x forward, z up), a round column up to the arm's mount; the arm's base link
sits on top of it, its first joint's axis on the column's axis. Weld the pedestal to the world
(``plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("panda_pedestal"))``).

The pedestal heights are measured by ``measure_reach.py`` in this folder: the tcp held horizontal
along +x (within 0.2 rad) 0.06 m above a 0.70 or 0.80 m table top, on a 5 cm grid in front of the
column; R is the largest half-disc (x >= 0.25 m) in which every point is reached, R50 the same
from x = 0.50 m; "clear" = free of self-collision and of a table whose edge is 0.20 m in front of
the axis:

* Panda, mount 0.35 m: R 0.94 / 0.92 m (0.70 / 0.80 m table) reached, also free of
  self-collision, 0.89 / 0.80 m clear of the table too; x on the centre line up to 0.90 m, from
  0.10 m (0.25 m clear over a 0.70 m table). The
  horizontal hand reaches the points near the axis only with the wrist folded over the base, with
  the tcp at least 0.41 m above the mount: from 0.36 m up, (0.25, 0) is lost over a 0.70 m table
  (R = 0), and lower mounts lose far reach over a 0.80 m table.
* iiwa 14, mount 0.20 m, its gripper on an angle bracket (``WSG_BRACKET``: the approach along the
  flange's x, the flange pointing down, as in iiwa cells). Its elbow (+-120 deg) keeps the wrist at
  least 0.41 m from the shoulder; with the gripper straight on the flange the wrist lies on the tool
  axis and the horizontal gripper reaches points near the axis only through its own pedestal (R 0
  clear at every mount, x from 0.45 m at 0.87 m). On the bracket, with the shoulder low, the wrist
  sits above the shoulder near the axis: R 0.98 / 0.95 m reached and free of self-collision, 0.76 /
  0.70 m clear of the table (0.70 / 0.80 m table), x on the centre line from 0.10-0.15 m. Lower
  mounts lose reach over the table (0.15 m: 0.70 / 0.65 m clear), higher ones the points near the
  axis (0.30 m: x from 0.40 m over a 0.70 m table).

Ready configurations (``PANDA_HOME``, ``IIWA_HOME``; ``measure_reach.py --home``): the tcp 0.06 m
above a 0.75 m table, 0.40 m (Panda) and 0.45 m (iiwa) in front of the axis, pointing along +x with the fingers
opening along y, clear of the arm, the pedestal and a table whose edge is 0.20 m in front of the
axis.

* ``panda``: the Franka Emika Panda. Kinematics are franka_description's URDF joint origins
  (``panda_arm.xacro``), which are exactly the Craig (modified) DH parameters of Franka's
  documentation ("Robot and interface specifications", frankaemika.github.io/docs): d1 = 0.333,
  d3 = 0.316, a4 = 0.0825, a5 = -0.0825, d5 = 0.384, a7 = 0.088, flange d = 0.107. Joint position,
  velocity and torque limits are Franka's published ones (same page). Link masses are the
  identified ones of Gaz, Cognetti, Oliva, Robuffo Giordano, De Luca, "Dynamic identification of
  the Franka Emika Panda robot with retrieval of feasible parameters using penalty-based
  optimization", IEEE RA-L 4(4), 2019, as franka_description ships them (``inertial.yaml``), with
  franka_description's link 0 (0.63 kg), hand (0.73 kg) and fingers (0.015 kg); centres of mass and
  inertias are those of solid primitives of the link's rough shape. The hand is the Franka Hand:
  turned by -pi/4 about the flange's z as on the real robot (its fingers then still open along the
  tcp's +y, since the tcp is a frame of the hand), fingers moving along the hand's y on joints
  0.0584 m out from the flange, 0-0.04 m travel each (80 mm opening), tcp (franka's
  ``panda_hand_tcp``) 0.1034 m from the flange, 70 N continuous grasp force, about 0.05 m/s per
  finger.
* ``iiwa14``: the KUKA LBR iiwa 14 R820. The links follow the layout of the iiwa14 URDF of
  Drake / ROS iiwa_stack (``iiwa14.xacro``), which reproduces the standard DH parameters exactly:
  d1 = 0.36 (0.1575 + 0.2025), d3 = 0.42 (0.2045 + 0.2155), d5 = 0.40 (0.1845 + 0.2155), d7 = 0.126
  to the flange (0.081 + 0.045), all a = 0, twists alpha = (-pi/2, pi/2, pi/2, -pi/2, -pi/2, pi/2, 0);
  link ``iiwa_link_0`` is the DH base frame and ``iiwa_flange`` the DH frame 7 at the flange (the
  orientation of ``iiwa_link_7``). Limits are KUKA's data sheet (LBR iiwa 14 R820: +-170, +-120,
  +-170, +-120, +-170, +-120, +-175 deg; 85, 85, 100, 75, 130, 135, 135 deg/s; 320, 320, 176,
  176, 110, 40, 40 N m). Link masses 4, 4, 3, 2.7, 1.7, 1.8, 0.3 kg (links 1-7) and 5 kg (link 0)
  are iiwa_stack's (the values Drake's iiwa14 URDF keeps as "Original Drake URDF value"); centres
  of mass and inertias are those of solid primitives. The gripper is sized like a Schunk WSG 50
  (a housing of about 146 x 50 x 72 mm, 1.2 kg, 0-0.055 m per finger = 110 mm stroke, 80 N grasp
  force, 0.2 m/s per finger) on a 15 mm coupling, fingers opening along the flange's y as in Drake's
  iiwa + WSG stations; tcp 0.13 m from the flange, between the fingertip pads.

Both grippers: the actuated finger (``panda_finger_joint1``, ``wsg_left_finger_joint``) opens along
the tcp's +y; the other finger (``panda_finger_joint2``, ``wsg_right_finger_joint``) follows it
through a URDF ``<mimic>``, which Drake turns into a coupler constraint (discrete plant with the SAP
solver). Link ``tcp`` lies between the fingertip pads, +z along the approach direction, +y along
the actuated finger's opening direction. Each arm joint and the actuated finger has a
``<transmission>`` (8 actuators; effort limits as published).

Geometry is primitives only (boxes, cylinders, spheres), roughly the real links' volumes; visual
geometry is the collision geometry with colours, plus a few visual-only details (the pedestal's
foot, flange rings, finger pads). Self-collision filter groups cover the links that overlap or
touch structurally (the wrist and the gripper); Drake already ignores the pairs a joint connects.

The arms' numbers and links are in ``arm_links.py``, the URDF helpers in ``urdf_writer.py`` (both
beside this script); this script adds the pedestals, joints, transmissions and collision groups.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # arm_links.py and urdf_writer.py beside it

from arm_links import (
    IIWA_FLANGE,
    IIWA_JOINTS,
    IIWA_LIMITS,
    IIWA_MATERIALS,
    PANDA_FINGER_BASE,
    PANDA_FINGER_FORCE,
    PANDA_FINGER_SPEED,
    PANDA_FINGER_STROKE,
    PANDA_FLANGE,
    PANDA_HAND_YAW,
    PANDA_JOINTS,
    PANDA_LIMITS,
    PANDA_MATERIALS,
    PANDA_TCP,
    WSG_BODY_SIZE,
    WSG_BRACKET,
    WSG_COUPLING,
    WSG_FINGER_FORCE,
    WSG_FINGER_SPEED,
    WSG_FINGER_STROKE,
    WSG_TCP,
    iiwa_links,
    panda_gripper_links,
    panda_links,
    wsg_links,
)
from urdf_writer import (
    PI,
    Link,
    box,
    collision_group,
    cyl_span,
    joint_xml,
    nums,
    solid_inertia,
    transmission_xml,
    write_or_check,
)

MODELS = Path(__file__).resolve().parents[2] / "hlp_drake" / "models" / "robot"
"""Where the robot models live (the package's ``hlp_drake/models/robot``)."""
PANDA_OUTPUT = MODELS / "panda.urdf"
IIWA_OUTPUT = MODELS / "iiwa14.urdf"

# --- Pedestals -----------------------------------------------------------------------------------
PANDA_MOUNT = 0.35
"""Height of the Panda's mount (top of its pedestal) above the floor, m (measure_reach.py)."""
IIWA_MOUNT = 0.20
"""Height of the iiwa's mount (top of its pedestal) above the floor, m (measure_reach.py)."""
PANDA_HOME = (0.5033, -1.0687, -0.5957, -2.8551, -2.7321, 2.7179, -0.1122)
"""Panda ready configuration: tcp at (0.40, 0, 0.81) m, exactly horizontal (the Panda's J6 range
keeps the hand from pointing forward with the arm in a vertical plane, so the elbow swings aside)."""
IIWA_HOME = (-1.667, 0.4998, -0.9336, 1.7007, -0.4002, -1.7409, 0.5327)
"""iiwa ready configuration: tcp at (0.50, 0, 0.81) m, pitched 0.06 rad down (the wrist housing,
on the tool axis 0.26 m behind the tcp, then clears the table top), the arm in the x-z plane (found
as ``measure_reach.py --home`` finds it, ``--home-x 0.5 --home-tolerance 0.07``, with joints 1, 3,
5 and 7 held at 0); nearer than about 0.5 m the horizontal gripper collides with the iiwa's own
base or pedestal."""
PEDESTAL_MASS = 30.0  # a steel column with a top plate and a foot plate; welded to the world anyway
PLATE_THICKNESS = 0.015

FINGER_DAMPING = 10.0


# --- Shared parts --------------------------------------------------------------------------------
def pedestal(name: str, height: float, radius: float, plate: float) -> Link:
    """A round column from the floor to ``height`` with a square top plate (``plate`` wide) under the
    arm's base and a wider foot plate on the floor (visual only)."""
    link = Link(name, f"pedestal: origin on the floor on the column's axis; the arm's mount {height} m up")
    top = height - PLATE_THICKNESS
    column = cyl_span("z", PLATE_THICKNESS, top, radius)
    top_plate = box((0, 0, top + PLATE_THICKNESS / 2), (plate, plate, PLATE_THICKNESS))
    foot = box((0, 0, PLATE_THICKNESS / 2), (2.5 * plate, 2.5 * plate, PLATE_THICKNESS))
    link.mass(*solid_inertia(PEDESTAL_MASS, [column, top_plate, foot]))
    link.add(column, "pedestal_grey")
    link.add(top_plate, "pedestal_dark")
    link.add(foot, "pedestal_dark", collide=False)
    return link


def arm_joints(spec, limits) -> list[str]:
    lines: list[str] = []
    for (name, parent, child, xyz, rpy), limit in zip(spec, limits):
        lines += joint_xml(name, "revolute", parent, child, xyz, rpy, axis=(0, 0, 1), limit=limit)
    return lines


def gripper_joints(
    palm: str, fingers: tuple[str, str], names: tuple[str, str], base: float, limit, tcp: float
) -> list[str]:
    lines: list[str] = []
    for name, finger, sy, mimic in zip(names, fingers, (1, -1), (None, names[0])):
        lines += joint_xml(
            name,
            "prismatic",
            palm,
            finger,
            (0, 0, base),
            axis=(0, sy, 0),
            limit=limit,
            damping=FINGER_DAMPING,
            mimic=mimic,
        )
    lines += joint_xml("tcp_joint", "fixed", palm, "tcp", (0, 0, tcp))
    return lines


def document(name: str, materials: dict, links: list[Link], body: list[str]) -> str:
    lines = [
        '<?xml version="1.0"?>',
        "<!-- Generated by make_arms.py in this folder; edit that script, not this file. -->",
        f'<robot name="{name}" xmlns:drake="http://drake.mit.edu">',
    ]
    for material, rgba in materials.items():
        lines.append(f'  <material name="{material}"><color rgba="{nums(rgba)}"/></material>')
    for link in links:
        lines += link.xml()
    lines += body
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


# --- Panda ---------------------------------------------------------------------------------------
PANDA_ACTUATED = tuple(j[0] for j in PANDA_JOINTS) + ("panda_finger_joint1",)


def panda_urdf(mount: float = PANDA_MOUNT) -> str:
    links = [pedestal("panda_pedestal", mount, 0.08, 0.22), *panda_links(), *panda_gripper_links()]
    body = joint_xml("panda_mount_joint", "fixed", "panda_pedestal", "panda_link0", (0, 0, mount))
    body += arm_joints(PANDA_JOINTS, PANDA_LIMITS)
    body += joint_xml("panda_flange_joint", "fixed", "panda_link7", "panda_flange", (0, 0, PANDA_FLANGE))
    body += joint_xml("panda_hand_joint", "fixed", "panda_flange", "panda_hand", rpy=(0, 0, PANDA_HAND_YAW))
    body += gripper_joints(
        "panda_hand",
        ("panda_leftfinger", "panda_rightfinger"),
        ("panda_finger_joint1", "panda_finger_joint2"),
        PANDA_FINGER_BASE,
        (0.0, PANDA_FINGER_STROKE, PANDA_FINGER_FORCE, PANDA_FINGER_SPEED),
        PANDA_TCP,
    )
    for joint in PANDA_ACTUATED:  # actuator order = this order
        body += transmission_xml(joint)
    # Links 5 and 7 overlap with J6 near its limits (filtered as in franka's and Drake's Panda models);
    # the closed fingers touch each other. The hand can still hit the forearm (link 5) and the rest.
    body += collision_group("panda_wrist", ("panda_link5", "panda_link7"))
    body += collision_group(
        "panda_gripper", ("panda_link7", "panda_hand", "panda_leftfinger", "panda_rightfinger")
    )
    return document("panda", PANDA_MATERIALS, links, body)


# --- iiwa 14 -------------------------------------------------------------------------------------
IIWA_ACTUATED = tuple(j[0] for j in IIWA_JOINTS) + ("wsg_left_finger_joint",)


def iiwa14_urdf(mount: float = IIWA_MOUNT) -> str:
    links = [pedestal("iiwa14_pedestal", mount, 0.1, 0.26), *iiwa_links(), *wsg_links()]
    body = joint_xml("iiwa_mount_joint", "fixed", "iiwa14_pedestal", "iiwa_link_0", (0, 0, mount))
    body += arm_joints(IIWA_JOINTS, IIWA_LIMITS)
    body += joint_xml("iiwa_flange_joint", "fixed", "iiwa_link_7", "iiwa_flange", (0, 0, IIWA_FLANGE))
    # An angle bracket: the gripper's approach along the flange's x, WSG_BRACKET out along its z, so
    # the tool axis is off the wrist (a horizontal gripper with the flange pointing down, as iiwa cells do).
    body += joint_xml(
        "wsg_mount_joint", "fixed", "iiwa_flange", "wsg_body", (0, 0, WSG_BRACKET), (PI, -PI / 2, 0)
    )
    body += gripper_joints(
        "wsg_body",
        ("wsg_left_finger", "wsg_right_finger"),
        ("wsg_left_finger_joint", "wsg_right_finger_joint"),
        WSG_COUPLING + WSG_BODY_SIZE[2],
        (0.0, WSG_FINGER_STROKE, WSG_FINGER_FORCE, WSG_FINGER_SPEED),
        WSG_TCP,
    )
    for joint in IIWA_ACTUATED:
        body += transmission_xml(joint)
    # The J6 housing (link 5) and link 7 overlap whatever J6's angle; the closed fingers touch.
    body += collision_group("iiwa_wrist", ("iiwa_link_5", "iiwa_link_7"))
    body += collision_group("wsg_gripper", ("iiwa_link_7", "wsg_body", "wsg_left_finger", "wsg_right_finger"))
    return document("iiwa14", IIWA_MATERIALS, links, body)


def main(argv: list[str] | None = None) -> int:
    return write_or_check(
        {PANDA_OUTPUT: panda_urdf, IIWA_OUTPUT: iiwa14_urdf},
        Path(__file__).name,
        __doc__.splitlines()[0],
        argv,
    )


if __name__ == "__main__":
    sys.exit(main())
