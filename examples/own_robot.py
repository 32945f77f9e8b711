"""Your own robot: write a small 6-DOF arm (URDF) and its description (YAML), then run it.

    python examples/own_robot.py --out my_robot
    python -m hlp_drake.run_scene --robot my_robot/arm6.yaml --kind gen1 --seed 4

The arm stands on a pedestal in front of the table: a shoulder turning about z, two pitching joints
(upper arm and forearm 0.45 m each), a spherical wrist (roll, pitch, roll) and a two-finger gripper
whose right finger follows the left through a ``<mimic>``. Any URDF or SDF works the same way: the
description names its joints and frames, nothing else changes.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

MOUNT = 0.72  # the arm's mount above the floor, m: the shoulder at 0.82 m, about a table top's height
LINKS = (  # name, parent joint origin (x, z) in the parent link, axis, lower, upper, effort, length along x
    ("shoulder", (0.0, MOUNT), "0 0 1", -math.pi, math.pi, 150.0, 0.0),
    ("upper_arm", (0.0, 0.10), "0 1 0", -2.0, 2.0, 150.0, 0.45),
    ("forearm", (0.45, 0.0), "0 1 0", -2.9, 2.9, 150.0, 0.45),
    ("wrist_1", (0.45, 0.0), "1 0 0", -math.pi, math.pi, 28.0, 0.0),
    ("wrist_2", (0.0, 0.0), "0 1 0", -2.0, 2.0, 28.0, 0.0),
    ("wrist_3", (0.0, 0.0), "1 0 0", -math.pi, math.pi, 28.0, 0.05),
)
FILTERED = {
    "base": ("pedestal", "shoulder", "upper_arm"),
    "wrist": ("forearm", "wrist_1", "wrist_2", "wrist_3", "palm", "left_finger", "right_finger"),
}
"""Groups of links whose collisions with each other are ignored (Drake's URDF extension)."""
STROKE = 0.04  # each finger's travel from the centre, m (80 mm between the pads)


def _inertial(mass: float, length: float) -> str:
    inertia = mass * (0.05**2 * 3 + max(length, 0.05) ** 2) / 12
    return (
        f'<inertial><origin xyz="{length / 2} 0 0"/><mass value="{mass}"/><inertia ixx="{mass * 0.05**2 / 2}" '
        f'ixy="0" ixz="0" iyy="{inertia}" iyz="0" izz="{inertia}"/></inertial>'
    )


def _link(name: str, mass: float, length: float, radius: float = 0.045) -> str:
    if length > 0:  # a capsule-like cylinder along the link's x
        shape = f'<origin xyz="{length / 2} 0 0" rpy="0 {math.pi / 2} 0"/><geometry><cylinder radius="{radius}" length="{length}"/></geometry>'
    else:
        shape = f'<geometry><sphere radius="{radius + 0.01}"/></geometry>'
    return (
        f'<link name="{name}">{_inertial(mass, length)}<visual>{shape}<material name="grey"/></visual>'
        f"<collision>{shape}</collision></link>"
    )


def _transmission(joint: str) -> str:
    return (
        f'<transmission name="{joint}_transmission"><type>transmission_interface/SimpleTransmission</type>'
        f'<joint name="{joint}"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>'
        f'<actuator name="{joint}_motor"/></transmission>'
    )


def urdf() -> str:
    """The arm as URDF text."""
    parts = [
        '<?xml version="1.0"?>',
        '<robot name="arm6" xmlns:drake="http://drake.mit.edu">',
        '<material name="grey"><color rgba="0.7 0.72 0.75 1"/></material>',
        (
            '<link name="pedestal"><inertial><origin xyz="0 0 0.36"/><mass value="20"/>'
            '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="0.1"/></inertial>'
            f'<visual><origin xyz="0 0 {MOUNT / 2}"/><geometry><cylinder radius="0.08" length="{MOUNT}"/></geometry>'
            '<material name="grey"/></visual>'
            f'<collision><origin xyz="0 0 {MOUNT / 2}"/><geometry><cylinder radius="0.08" length="{MOUNT}"/></geometry>'
            "</collision></link>"
        ),
    ]
    parent = "pedestal"
    for i, (name, (x, z), axis, lower, upper, effort, length) in enumerate(LINKS, start=1):
        parts.append(_link(name, 2.0 if length else 1.0, length, 0.045 if i < 3 else 0.03))
        parts.append(
            f'<joint name="joint_{i}" type="revolute"><parent link="{parent}"/><child link="{name}"/>'
            f'<origin xyz="{x} 0 {z}"/><axis xyz="{axis}"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="{effort}" velocity="2.0"/></joint>'
        )
        parts.append(_transmission(f"joint_{i}"))
        parent = name
    palm = '<origin xyz="0.02 0 0"/><geometry><box size="0.04 0.12 0.05"/></geometry>'
    parts += [
        (
            f'<link name="palm">{_inertial(0.6, 0.04)}<visual>{palm}<material name="grey"/></visual>'
            f"<collision>{palm}</collision></link>"
        ),
        (
            '<joint name="palm_joint" type="fixed"><parent link="wrist_3"/><child link="palm"/>'
            '<origin xyz="0.05 0 0"/></joint>'
        ),
        '<link name="tcp"/>',
        (
            f'<joint name="tcp_joint" type="fixed"><parent link="palm"/><child link="tcp"/>'
            f'<origin xyz="0.12 0 0" rpy="0 {math.pi / 2} 0"/></joint>'
        ),
    ]
    for side, sign in (("left", 1), ("right", -1)):
        finger = '<origin xyz="0.085 0 0"/><geometry><box size="0.07 0.012 0.02"/></geometry>'
        parts.append(
            f'<link name="{side}_finger">{_inertial(0.04, 0.07)}<visual>{finger}<material name="grey"/></visual>'
            f"<collision>{finger}</collision></link>"
        )
        mimic = '<mimic joint="left_finger_joint" multiplier="1" offset="0"/>' if side == "right" else ""
        parts.append(
            f'<joint name="{side}_finger_joint" type="prismatic"><parent link="palm"/><child link="{side}_finger"/>'
            f'<origin xyz="0 {sign * 0.006} 0"/><axis xyz="0 {sign} 0"/>'
            f'<limit lower="0" upper="{STROKE}" effort="100" velocity="0.1"/>{mimic}</joint>'
        )
    parts.append(_transmission("left_finger_joint"))
    for group, members in FILTERED.items():  # neighbours that touch by design never count as collisions
        parts.append(f'<drake:collision_filter_group name="{group}">')
        parts += [f'<drake:member link="{link}"/>' for link in members]
        parts.append(f'<drake:ignored_collision_filter_group name="{group}"/></drake:collision_filter_group>')
    parts.append("</robot>")
    return "\n".join(parts) + "\n"


DESCRIPTION = """\
# A robot description (hlp_drake.systems.RobotDescription): the model and what the planner needs of it.
name: arm6
model: arm6.urdf                     # a path beside this file, a file:// or a package:// URL
base: {kind: fixed, frame: pedestal, pose: [-0.25, 0.0, 0.0]}   # x, y, yaw in front of the table
arm_joints: [joint_1, joint_2, joint_3, joint_4, joint_5, joint_6]
gripper_joint: left_finger_joint     # actuated, prismatic: each finger's travel
mimic_joints: [right_finger_joint]
tcp_frame: tcp                       # between the pads: +z the approach, +y the opening
flange_frame: palm
wrist_link: wrist_3
gripper_links: [palm, left_finger, right_finger]
finger_links: [left_finger, right_finger]
home: [0.0, -0.6, 1.6, 0.0, -1.0, 0.0]
gripper_open: 0.04
reach: 0.95                          # m from the base over the table: generated tables fit it
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="folder for arm6.urdf and arm6.yaml")
    out = Path(parser.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "arm6.urdf").write_text(urdf())
    (out / "arm6.yaml").write_text(DESCRIPTION)
    print(f"wrote {out / 'arm6.urdf'}, {out / 'arm6.yaml'}")


if __name__ == "__main__":
    main()
