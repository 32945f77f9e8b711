"""Helpers of the scripts that write this folder's URDF files (``make_mobile_ur5.py``, ``make_arms.py``).

A development module, never imported by ``hlp_drake`` at run time; the scripts import it from the
folder they sit in. It holds small rigid-transform helpers (3x3 tuples, no numpy), inertias of solid
primitives, and the URDF text of links (primitive geometry), joints, transmissions and Drake
collision filter groups, written the same way on every run so the generated files are reproducible.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path

PI = math.pi

# --- Small rigid-transform helpers (3x3 tuples) --------------------------------------------------
Mat = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
Vec = tuple[float, float, float]


def rot(axis: str, angle: float) -> Mat:
    c, s = math.cos(angle), math.sin(angle)
    if axis == "x":
        return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))
    if axis == "y":
        return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


def mul(a: Mat, b: Mat) -> Mat:
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))


def apply(r: Mat, v: Vec) -> Vec:
    return tuple(sum(r[i][k] * v[k] for k in range(3)) for i in range(3))


def transpose(r: Mat) -> Mat:
    return tuple(tuple(r[j][i] for j in range(3)) for i in range(3))


def add(a: Vec, b: Vec) -> Vec:
    return tuple(x + y for x, y in zip(a, b))


def sub(a: Vec, b: Vec) -> Vec:
    return tuple(x - y for x, y in zip(a, b))


Pose = tuple[Mat, Vec]
IDENTITY: Mat = rot("z", 0.0)


def compose(a: Pose, b: Pose) -> Pose:
    return mul(a[0], b[0]), add(a[1], apply(a[0], b[1]))


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Mat:
    return mul(rot("z", yaw), mul(rot("y", pitch), rot("x", roll)))


# --- Inertias ----------------------------------------------------------------------------------
def cylinder_inertia(mass: float, radius: float, length: float, axis: str) -> Vec:
    """(ixx, iyy, izz) of a solid cylinder about its centre, its axis along ``axis``."""
    along = mass * radius**2 / 2.0
    across = mass * (3.0 * radius**2 + length**2) / 12.0
    return tuple(along if a == axis else across for a in "xyz")


def box_inertia(mass: float, size: Vec) -> Vec:
    x, y, z = size
    return (mass * (y * y + z * z) / 12.0, mass * (x * x + z * z) / 12.0, mass * (x * x + y * y) / 12.0)


def sphere_inertia(mass: float, radius: float) -> Vec:
    moment = 0.4 * mass * radius**2
    return (moment, moment, moment)


def combined_inertia(parts: list[tuple[float, Vec, Vec]]) -> tuple[float, Vec, tuple[float, ...]]:
    """Mass, centre of mass and (ixx, iyy, izz, ixy, ixz, iyz) about it (URDF signs: ixy = -sum m x y)
    of rigid parts (mass, centre of mass, principal (ixx, iyy, izz) about it, axes along the link's)."""
    mass = sum(m for m, _, _ in parts)
    com = tuple(sum(m * c[i] for m, c, _ in parts) / mass for i in range(3))
    ixx = iyy = izz = ixy = ixz = iyz = 0.0
    for m, c, (jxx, jyy, jzz) in parts:
        dx, dy, dz = sub(c, com)
        ixx += jxx + m * (dy * dy + dz * dz)
        iyy += jyy + m * (dx * dx + dz * dz)
        izz += jzz + m * (dx * dx + dy * dy)
        ixy -= m * dx * dy
        ixz -= m * dx * dz
        iyz -= m * dy * dz
    return mass, com, (ixx, iyy, izz, ixy, ixz, iyz)


# --- URDF text -----------------------------------------------------------------------------------
def num(x: float) -> str:
    text = f"{x:.12g}"
    return "0" if text in ("0", "-0") else text


def nums(values) -> str:
    return " ".join(num(float(v)) for v in values)


AXIS_RPY = {"x": (0.0, PI / 2, 0.0), "y": (PI / 2, 0.0, 0.0), "z": (0.0, 0.0, 0.0)}


class Shape:
    """A primitive with its pose in the link: ``box`` (size), ``cylinder`` (radius, length, axis) or
    ``sphere`` (radius)."""

    def __init__(
        self,
        kind: str,
        xyz: Vec,
        *,
        size: Vec = (0, 0, 0),
        radius: float = 0.0,
        length: float = 0.0,
        axis: str = "z",
        rpy: Vec = (0.0, 0.0, 0.0),
    ) -> None:
        self.kind, self.xyz, self.size, self.radius, self.length = kind, xyz, size, radius, length
        self.axis = axis
        self.rpy = AXIS_RPY[axis] if kind == "cylinder" else rpy

    def xml(self) -> str:
        if self.kind == "box":
            geometry = f'<box size="{nums(self.size)}"/>'
        elif self.kind == "sphere":
            geometry = f'<sphere radius="{num(self.radius)}"/>'
        else:
            geometry = f'<cylinder radius="{num(self.radius)}" length="{num(self.length)}"/>'
        return f'<origin xyz="{nums(self.xyz)}" rpy="{nums(self.rpy)}"/><geometry>{geometry}</geometry>'

    def volume(self) -> float:
        if self.kind == "box":
            return self.size[0] * self.size[1] * self.size[2]
        if self.kind == "sphere":
            return 4.0 / 3.0 * PI * self.radius**3
        return PI * self.radius**2 * self.length

    def inertia(self, mass: float) -> Vec:
        """Principal moments of a solid shape of ``mass`` about its centre, along the link's axes
        (boxes are axis-aligned here: ``rpy`` zero)."""
        if self.kind == "box":
            return box_inertia(mass, self.size)
        if self.kind == "sphere":
            return sphere_inertia(mass, self.radius)
        return cylinder_inertia(mass, self.radius, self.length, self.axis)


def cyl(axis: str, center: Vec, radius: float, length: float) -> Shape:
    return Shape("cylinder", center, radius=radius, length=length, axis=axis)


def box(center: Vec, size: Vec) -> Shape:
    return Shape("box", center, size=size)


def sphere(center: Vec, radius: float) -> Shape:
    return Shape("sphere", center, radius=radius)


def span(axis: str, lo: float, hi: float, at: Vec = (0.0, 0.0, 0.0)) -> tuple[Vec, float]:
    """Centre and length of a segment [lo, hi] along ``axis`` through point ``at``."""
    centre = list(at)
    centre["xyz".index(axis)] = (lo + hi) / 2.0
    return tuple(centre), hi - lo


def cyl_span(axis: str, lo: float, hi: float, radius: float, at: Vec = (0.0, 0.0, 0.0)) -> Shape:
    centre, length = span(axis, lo, hi, at)
    return cyl(axis, centre, radius, length)


def solid_inertia(mass: float, shapes: list[Shape]) -> tuple[float, Vec, tuple[float, ...]]:
    """Mass, centre of mass and inertia of ``mass`` spread evenly over the volume of ``shapes``
    (overlaps count twice; axis-aligned boxes): a solid approximation of a link."""
    total = sum(shape.volume() for shape in shapes)
    parts = []
    for shape in shapes:
        m = mass * shape.volume() / total
        parts.append((m, shape.xyz, shape.inertia(m)))
    return combined_inertia(parts)


class Link:
    def __init__(self, name: str, comment: str = "") -> None:
        self.name, self.comment = name, comment
        self.inertial: tuple[float, Vec, tuple[float, ...]] | None = None
        self.visuals: list[tuple[Shape, str]] = []
        self.collisions: list[Shape] = []

    def mass(self, mass: float, com: Vec, inertia: tuple[float, ...]) -> Link:
        """``inertia`` about ``com``: (ixx, iyy, izz) or (ixx, iyy, izz, ixy, ixz, iyz)."""
        self.inertial = (mass, com, inertia)
        return self

    def add(self, shape: Shape, material: str, *, collide: bool = True) -> Link:
        self.visuals.append((shape, material))
        if collide:
            self.collisions.append(shape)
        return self

    def xml(self) -> list[str]:
        lines = [f"  <!-- {self.comment} -->"] if self.comment else []
        lines.append(f'  <link name="{self.name}">')
        if self.inertial is not None:
            mass, com, inertia = self.inertial
            ixx, iyy, izz, ixy, ixz, iyz = (*inertia, 0.0, 0.0, 0.0)[:6]
            lines += [
                "    <inertial>",
                f'      <origin xyz="{nums(com)}" rpy="0 0 0"/>',
                f'      <mass value="{num(mass)}"/>',
                (
                    f'      <inertia ixx="{num(ixx)}" ixy="{num(ixy)}" ixz="{num(ixz)}" iyy="{num(iyy)}"'
                    f' iyz="{num(iyz)}" izz="{num(izz)}"/>'
                ),
                "    </inertial>",
            ]
        for i, (shape, material) in enumerate(self.visuals):
            lines.append(
                f'    <visual name="{self.name}_visual_{i}">{shape.xml()}'
                f'<material name="{material}"/></visual>'
            )
        for i, shape in enumerate(self.collisions):
            lines.append(f'    <collision name="{self.name}_collision_{i}">{shape.xml()}</collision>')
        lines.append("  </link>")
        return lines


def joint_xml(
    name: str,
    kind: str,
    parent: str,
    child: str,
    xyz=(0, 0, 0),
    rpy=(0, 0, 0),
    *,
    axis: Vec | None = None,
    limit: tuple[float, float, float, float] | None = None,
    damping: float | None = None,
    mimic: str | None = None,
) -> list[str]:
    lines = [
        f'  <joint name="{name}" type="{kind}">',
        f'    <parent link="{parent}"/>',
        f'    <child link="{child}"/>',
        f'    <origin xyz="{nums(xyz)}" rpy="{nums(rpy)}"/>',
    ]
    if axis is not None:
        lines.append(f'    <axis xyz="{nums(axis)}"/>')
    if limit is not None:
        lower, upper, effort, velocity = limit
        lines.append(
            f'    <limit lower="{num(lower)}" upper="{num(upper)}" effort="{num(effort)}" '
            f'velocity="{num(velocity)}"/>'
        )
    if damping is not None:
        lines.append(f'    <dynamics damping="{num(damping)}" friction="0"/>')
    if mimic is not None:
        lines.append(f'    <mimic joint="{mimic}" multiplier="1" offset="0"/>')
    lines.append("  </joint>")
    return lines


def transmission_xml(joint: str) -> list[str]:
    stem = joint.removesuffix("_joint")
    return [
        f'  <transmission name="{stem}_transmission">',
        "    <type>transmission_interface/SimpleTransmission</type>",
        (
            f'    <joint name="{joint}"><hardwareInterface>hardware_interface/EffortJointInterface'
            "</hardwareInterface></joint>"
        ),
        f'    <actuator name="{stem}_motor"><mechanicalReduction>1</mechanicalReduction></actuator>',
        "  </transmission>",
    ]


def collision_group(name: str, members: tuple[str, ...]) -> list[str]:
    lines = [f'  <drake:collision_filter_group name="{name}">']
    lines += [f'    <drake:member link="{m}"/>' for m in members]
    lines += [
        f'    <drake:ignored_collision_filter_group name="{name}"/>',
        "  </drake:collision_filter_group>",
    ]
    return lines


def write_or_check(
    outputs: dict[Path, Callable[[], str]], script: str, description: str, argv: list[str] | None = None
) -> int:
    """The command line of a generating script: write each file of ``outputs`` (path -> text), or
    with ``--check`` only compare and exit 1 if any checked-in file differs."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--check", action="store_true", help="only compare with the checked-in files")
    args = parser.parse_args(argv)
    stale = 0
    for path, text_of in outputs.items():
        text = text_of()
        if args.check:
            current = path.read_text() if path.exists() else ""
            if current != text:
                print(f"{path} is stale: run python {script}", file=sys.stderr)
                stale = 1
            else:
                print(f"{path} is up to date")
        else:
            path.write_text(text)
            print(f"wrote {path}")
    return stale
