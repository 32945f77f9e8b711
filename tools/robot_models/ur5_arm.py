"""The UR5 of ``make_mobile_ur5.py``: its numbers, its links and its joints.

A development module, never imported by ``hlp_drake`` at run time; ``make_mobile_ur5.py`` imports it
from the folder both sit in, and its docstring says where the numbers come from. This module holds
the UR5's official DH parameters, masses and centres of mass, the joint layout of UR's own model
(the links' frames), the joint limits, and writes the arm's links (primitives, solid-cylinder
inertias) and joints from its mount (``ur5_base_link``) to the tool flange (``ur5_flange``).
"""

from __future__ import annotations

from urdf_writer import (
    IDENTITY,
    PI,
    Link,
    Pose,
    Vec,
    add,
    apply,
    compose,
    cyl_span,
    cylinder_inertia,
    joint_xml,
    rot,
    rpy_matrix,
    sub,
    transpose,
)

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

ARM_LIMITS = (  # (lower, upper, effort) per UR5 joint; velocity pi rad/s for all
    (-2 * PI, 2 * PI, BIG_EFFORT),
    (-2 * PI, 2 * PI, BIG_EFFORT),
    (-PI, PI, BIG_EFFORT),
    (-2 * PI, 2 * PI, SMALL_EFFORT),
    (-2 * PI, 2 * PI, SMALL_EFFORT),
    (-2 * PI, 2 * PI, SMALL_EFFORT),
)


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


def arm_joints() -> list[str]:
    """The UR5's joints from ``ur5_base_link`` (its mount) to ``ur5_flange``."""
    lines = joint_xml("ur5_base_joint", "fixed", "ur5_base_link", "ur5_base", rpy=(0, 0, PI))
    for (name, parent, child, xyz, rpy, axis), (lower, upper, effort) in zip(UR5_JOINTS, ARM_LIMITS):
        lines += joint_xml(
            name, "revolute", parent, child, xyz, rpy, axis=axis, limit=(lower, upper, effort, PI)
        )
    lines += joint_xml("ur5_flange_joint", "fixed", "wrist_3_link", "ur5_flange", *FLANGE_ORIGIN)
    return lines
