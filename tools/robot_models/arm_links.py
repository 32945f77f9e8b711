"""The Panda's and the iiwa 14's parts for ``make_arms.py``: their numbers and their links.

A development module, never imported by ``hlp_drake`` at run time; ``make_arms.py`` imports it from
the folder both sit in, and its docstring says where the numbers come from. This module holds each
arm's joint layout, limits, link masses, gripper dimensions and materials, and builds the links of
the arm (0..7) and of its gripper (flange, hand or housing, fingers, tcp) from primitives, with the
inertias of solid primitives.
"""

from __future__ import annotations

from urdf_writer import PI, Link, Vec, box, cyl_span, solid_inertia, sphere

# --- Franka Emika Panda --------------------------------------------------------------------------
# (joint, parent, child, origin xyz, origin rpy) of franka_description; every axis is the child's z.
PANDA_JOINTS = (
    ("panda_joint1", "panda_link0", "panda_link1", (0, 0, 0.333), (0, 0, 0)),
    ("panda_joint2", "panda_link1", "panda_link2", (0, 0, 0), (-PI / 2, 0, 0)),
    ("panda_joint3", "panda_link2", "panda_link3", (0, -0.316, 0), (PI / 2, 0, 0)),
    ("panda_joint4", "panda_link3", "panda_link4", (0.0825, 0, 0), (PI / 2, 0, 0)),
    ("panda_joint5", "panda_link4", "panda_link5", (-0.0825, 0.384, 0), (-PI / 2, 0, 0)),
    ("panda_joint6", "panda_link5", "panda_link6", (0, 0, 0), (PI / 2, 0, 0)),
    ("panda_joint7", "panda_link6", "panda_link7", (0.088, 0, 0), (PI / 2, 0, 0)),
)
PANDA_FLANGE = 0.107  # panda_link8 (the flange) along link 7's z
PANDA_LIMITS = (  # (lower, upper, effort, velocity), Franka's published limits
    (-2.8973, 2.8973, 87.0, 2.175),
    (-1.7628, 1.7628, 87.0, 2.175),
    (-2.8973, 2.8973, 87.0, 2.175),
    (-3.0718, -0.0698, 87.0, 2.175),
    (-2.8973, 2.8973, 12.0, 2.61),
    (-0.0175, 3.7525, 12.0, 2.61),
    (-2.8973, 2.8973, 12.0, 2.61),
)
PANDA_MASSES = (0.629769, 4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522)  # links 0..7
PANDA_HAND_YAW = -PI / 4  # the hand on the flange, as on the real robot
PANDA_HAND_MASS, PANDA_FINGER_MASS = 0.73, 0.015
PANDA_FINGER_BASE = 0.0584  # finger joints' origin along the hand's z
PANDA_FINGER_STROKE = 0.04  # per finger: 0 closed, 0.04 open (80 mm between the pads)
PANDA_FINGER_FORCE, PANDA_FINGER_SPEED = 70.0, 0.05
PANDA_FINGER_SIZE = (0.02, 0.012, 0.054)  # x, thickness along y, length along z (from the finger base)
PANDA_TCP = 0.1034  # tcp along the approach axis from the flange (franka's panda_hand_tcp)
PANDA_MATERIALS = {
    "panda_white": (0.93, 0.93, 0.92, 1.0),
    "panda_grey": (0.55, 0.56, 0.58, 1.0),
    "panda_dark": (0.18, 0.18, 0.20, 1.0),
    "pad_grey": (0.30, 0.30, 0.32, 1.0),
    "pedestal_grey": (0.42, 0.44, 0.47, 1.0),
    "pedestal_dark": (0.16, 0.17, 0.19, 1.0),
}

# --- KUKA LBR iiwa 14 R820 -----------------------------------------------------------------------
IIWA_JOINTS = (  # the layout of Drake's / iiwa_stack's iiwa14 URDF; every axis is the child's z
    ("iiwa_joint_1", "iiwa_link_0", "iiwa_link_1", (0, 0, 0.1575), (0, 0, 0)),
    ("iiwa_joint_2", "iiwa_link_1", "iiwa_link_2", (0, 0, 0.2025), (PI / 2, 0, PI)),
    ("iiwa_joint_3", "iiwa_link_2", "iiwa_link_3", (0, 0.2045, 0), (PI / 2, 0, PI)),
    ("iiwa_joint_4", "iiwa_link_3", "iiwa_link_4", (0, 0, 0.2155), (PI / 2, 0, 0)),
    ("iiwa_joint_5", "iiwa_link_4", "iiwa_link_5", (0, 0.1845, 0), (-PI / 2, PI, 0)),
    ("iiwa_joint_6", "iiwa_link_5", "iiwa_link_6", (0, 0, 0.2155), (PI / 2, 0, 0)),
    ("iiwa_joint_7", "iiwa_link_6", "iiwa_link_7", (0, 0.081, 0), (-PI / 2, PI, 0)),
)
IIWA_FLANGE = 0.045  # the flange along link 7's z
DEG = PI / 180.0
IIWA_LIMITS = tuple(  # (lower, upper, effort, velocity), KUKA's data sheet
    (-limit * DEG, limit * DEG, effort, speed * DEG)
    for limit, effort, speed in (
        (170, 320.0, 85),
        (120, 320.0, 85),
        (170, 176.0, 100),
        (120, 176.0, 75),
        (170, 110.0, 130),
        (120, 40.0, 135),
        (175, 40.0, 135),
    )
)
IIWA_MASSES = (5.0, 4.0, 4.0, 3.0, 2.7, 1.7, 1.8, 0.3)  # links 0..7 (iiwa_stack)
WSG_COUPLING = 0.015  # ISO flange coupling under the housing
WSG_BODY_SIZE = (0.05, 0.146, 0.072)  # x (palm normal), y (stroke), z (approach)
WSG_BODY_MASS, WSG_FINGER_MASS = 1.1, 0.05  # 1.2 kg with the fingers
WSG_FINGER_SIZE = (0.02, 0.012, 0.06)  # x, thickness along y, length along z from the housing
WSG_FINGER_STROKE = 0.055  # per finger: 0 closed, 0.055 open (110 mm between the pads)
WSG_FINGER_FORCE, WSG_FINGER_SPEED = 80.0, 0.2
WSG_BRACKET = 0.06  # the angle bracket: the gripper's axis this far from the flange along its z
WSG_TCP = 0.13  # tcp along the approach axis from the flange: mid-pad, 17 mm in from the tips
IIWA_MATERIALS = {
    "kuka_orange": (1.0, 0.42, 0.04, 1.0),
    "kuka_grey": (0.62, 0.63, 0.65, 1.0),
    "kuka_dark": (0.20, 0.20, 0.22, 1.0),
    "wsg_silver": (0.75, 0.76, 0.78, 1.0),
    "wsg_black": (0.08, 0.08, 0.09, 1.0),
    "pad_grey": (0.30, 0.30, 0.32, 1.0),
    "pedestal_grey": (0.42, 0.44, 0.47, 1.0),
    "pedestal_dark": (0.16, 0.17, 0.19, 1.0),
}


# --- Shared parts --------------------------------------------------------------------------------
def solid(link: Link, mass: float) -> Link:
    """Give ``link`` ``mass`` spread evenly over its collision shapes' volume."""
    return link.mass(*solid_inertia(mass, link.collisions))


def finger_links(
    prefix: str, names: tuple[str, str], size: Vec, mass: float, base: float, tcp: float, material: str
) -> list[Link]:
    """Two finger links: finger frame = the gripper frame moved ``base`` along z (the finger joints'
    origin), then by q along the joint axis; inner face on y = +-q, from z = 0 to the tip."""
    fx, fy, fz = size
    fingers = []
    for name, sy in zip(names, (1.0, -1.0)):
        comment = (
            f"{prefix} finger frame = gripper frame moved {base} m along z, then by q along its axis;"
            " inner face on y = +-q"
            if sy > 0
            else ""
        )
        finger = Link(name, comment)
        centre = (0.0, sy * fy / 2.0, fz / 2.0)
        finger.add(box(centre, size), material)
        pad_lo, pad_hi = tcp - base - 0.015, min(fz, tcp - base + 0.015)
        finger.add(
            box((0.0, sy * 0.001, (pad_lo + pad_hi) / 2.0), (fx - 0.004, 0.0025, pad_hi - pad_lo)),
            "pad_grey",
            collide=False,
        )
        fingers.append(solid(finger, mass))
    return fingers


# --- Panda ---------------------------------------------------------------------------------------
def panda_links() -> list[Link]:
    """The Panda's links 0..7 in franka_description's frames (at q = 0 links 0, 1, 3 and 5 are
    aligned with the base, the arm stands up and link 7's z points down)."""
    white, grey = "panda_white", "panda_grey"
    link0 = Link("panda_link0", "Panda: base on the pedestal, J1 axis = z")
    link0.add(cyl_span("z", 0.0, 0.14, 0.075), white)
    link0.add(box((-0.095, 0, 0.055), (0.13, 0.13, 0.11)), white)  # connector housing at the back
    link0.add(cyl_span("z", 0.0, 0.006, 0.09), grey, collide=False)  # mounting ring

    link1 = Link("panda_link1", "link 1: the shoulder column up to the J2 axis (z 0.333 above the base)")
    link1.add(cyl_span("z", -0.193, 0.0, 0.06), white)
    link1.add(cyl_span("z", -0.195, -0.188, 0.061), grey, collide=False)

    link2 = Link("panda_link2", "link 2: J2 housing (axis z) and the lower upper arm (along -y)")
    link2.add(cyl_span("z", -0.06, 0.06, 0.06), white)
    link2.add(cyl_span("y", -0.16, 0.0, 0.06), white)

    link3 = Link("panda_link3", "link 3: the upper upper arm (along -z) and the elbow's J4 housing")
    link3.add(cyl_span("z", -0.2, 0.0, 0.06), white)
    link3.add(cyl_span("y", 0.0, 0.11, 0.055, at=(0.0825, 0, 0)), white)
    link3.add(box((0.04, 0.055, 0.0), (0.08, 0.11, 0.1)), white)

    link4 = Link("panda_link4", "link 4: the elbow (J4 axis z) and the lower forearm (along +y)")
    link4.add(cyl_span("z", -0.01, 0.11, 0.055), white)
    link4.add(cyl_span("y", -0.03, 0.14, 0.055, at=(-0.0825, 0, 0)), white)
    link4.add(box((-0.04, 0.0, 0.03), (0.08, 0.1, 0.08)), white)

    link5 = Link(
        "panda_link5", "link 5: the forearm (along z) up to the wrist, its slim part offset along +y"
    )
    link5.add(cyl_span("z", -0.31, -0.17, 0.06), white)
    link5.add(box((0, 0.065, -0.11), (0.07, 0.05, 0.16)), white)
    link5.add(cyl_span("z", -0.05, 0.0, 0.045, at=(0, 0.07, 0)), white)

    link6 = Link("panda_link6", "link 6: J6 housing (axis z) and the arm to J7 (along +x)")
    link6.add(cyl_span("z", -0.07, 0.01, 0.05), white)
    link6.add(cyl_span("x", 0.0, 0.088, 0.045, at=(0, 0, -0.03)), white)

    link7 = Link("panda_link7", "link 7: J7 housing and the flange (z 0.107)")
    link7.add(cyl_span("z", -0.06, PANDA_FLANGE - 0.007, 0.045), white)
    link7.add(cyl_span("z", PANDA_FLANGE - 0.007, PANDA_FLANGE, 0.0315), "panda_dark")
    link7.add(cyl_span("z", -0.063, -0.06, 0.03), grey, collide=False)  # the pilot's ring

    links = [link0, link1, link2, link3, link4, link5, link6, link7]
    for link, mass in zip(links, PANDA_MASSES):
        solid(link, mass)
    return links


def panda_gripper_links() -> list[Link]:
    flange = Link("panda_flange", "the Panda's flange (franka's panda_link8): z out of the flange")
    hand = Link("panda_hand", "Franka Hand: turned -pi/4 about the flange's z; fingers open along y")
    hand.add(cyl_span("z", 0.0, 0.01, 0.04), "panda_dark")
    hand.add(box((0, 0, 0.034), (0.06, 0.2, 0.048)), "panda_white")
    hand.add(box((0, 0, PANDA_FINGER_BASE - 0.002), (0.03, 0.09, 0.004)), "panda_dark", collide=False)
    solid(hand, PANDA_HAND_MASS)
    fingers = finger_links(
        "Franka Hand:",
        ("panda_leftfinger", "panda_rightfinger"),
        PANDA_FINGER_SIZE,
        PANDA_FINGER_MASS,
        PANDA_FINGER_BASE,
        PANDA_TCP,
        "panda_dark",
    )
    tcp = Link("tcp", "tool centre point between the fingertip pads: z = approach, y = left finger opening")
    return [flange, hand, *fingers, tcp]


# --- iiwa 14 -------------------------------------------------------------------------------------
def iiwa_links() -> list[Link]:
    """The iiwa's links 0..7 in the frames of Drake's iiwa14 URDF (at q = 0 the arm stands up; the
    odd links' z is the arm's axis, the even links' z the J2, J4, J6 axes and their y the arm's)."""
    orange, grey = "kuka_orange", "kuka_grey"
    link0 = Link("iiwa_link_0", "iiwa: base on the pedestal, J1 axis = z")
    link0.add(cyl_span("z", 0.0, 0.1575, 0.1), grey)
    link0.add(box((-0.12, 0, 0.065), (0.1, 0.12, 0.09)), grey)  # connector housing at the back
    link0.add(cyl_span("z", 0.0, 0.006, 0.12), "kuka_dark", collide=False)  # mounting ring

    link1 = Link("iiwa_link_1", "link 1: from the base up to the J2 housing (z 0.2025)")
    link1.add(cyl_span("z", 0.0, 0.16, 0.095), grey)
    link1.add(sphere((0, 0, 0.2025), 0.1), grey)

    link2 = Link("iiwa_link_2", "link 2: J2 (axis z) to J3, along +y")
    link2.add(cyl_span("y", 0.04, 0.2045, 0.09), orange)

    link3 = Link("iiwa_link_3", "link 3: J3 (axis z) to the J4 housing (z 0.2155)")
    link3.add(cyl_span("z", 0.0, 0.17, 0.09), grey)
    link3.add(sphere((0, 0, 0.2155), 0.09), grey)
    link3.add(cyl_span("z", 0.06, 0.075, 0.0905), "kuka_dark", collide=False)  # the band

    link4 = Link("iiwa_link_4", "link 4: J4 (axis z) to J5, along +y")
    link4.add(cyl_span("y", 0.04, 0.1845, 0.085), orange)

    link5 = Link("iiwa_link_5", "link 5: J5 (axis z) to the J6 housing (z 0.2155)")
    link5.add(cyl_span("z", 0.0, 0.16, 0.08), grey)
    link5.add(sphere((0, 0, 0.2155), 0.075), grey)
    link5.add(cyl_span("z", 0.05, 0.065, 0.0805), "kuka_dark", collide=False)

    link6 = Link("iiwa_link_6", "link 6: J6 (axis z) to J7, along +y")
    link6.add(cyl_span("z", -0.065, 0.065, 0.07), orange)
    link6.add(cyl_span("y", 0.0, 0.07, 0.065), orange)

    link7 = Link("iiwa_link_7", "link 7: the flange (z 0.045)")
    link7.add(cyl_span("z", -0.01, IIWA_FLANGE - 0.005, 0.05), grey)
    link7.add(cyl_span("z", IIWA_FLANGE - 0.005, IIWA_FLANGE, 0.04), "kuka_dark")

    links = [link0, link1, link2, link3, link4, link5, link6, link7]
    for link, mass in zip(links, IIWA_MASSES):
        solid(link, mass)
    return links


def wsg_links() -> list[Link]:
    flange = Link(
        "iiwa_flange",
        "the iiwa's flange: DH frame 7 (the orientation of iiwa_link_7), carrying the angle bracket",
    )
    flange.add(cyl_span("z", 0.0, WSG_BRACKET, 0.045), "kuka_dark")  # the bracket's stem along the flange's z
    body = Link("wsg_body", "WSG 50 sized gripper; frame = iiwa_flange; fingers open along y")
    bx, by, bz = WSG_BODY_SIZE
    body.add(cyl_span("z", 0.0, WSG_COUPLING, 0.045), "kuka_dark")
    body.add(box((0, 0, WSG_COUPLING + bz / 2.0), WSG_BODY_SIZE), "wsg_silver")
    top = WSG_COUPLING + bz
    body.add(box((0, 0, top - 0.003), (bx + 0.002, by - 0.02, 0.006)), "wsg_black", collide=False)
    solid(body, WSG_BODY_MASS)
    fingers = finger_links(
        "WSG 50:",
        ("wsg_left_finger", "wsg_right_finger"),
        WSG_FINGER_SIZE,
        WSG_FINGER_MASS,
        top,
        WSG_TCP,
        "wsg_black",
    )
    tcp = Link("tcp", "tool centre point between the fingertip pads: z = approach, y = left finger opening")
    return [flange, body, *fingers, tcp]
