"""A finalized Drake plant as MuJoCo's MJCF (``mjcf_from_plant``), for ``mujoco_anchor.py``.

The same bodies, masses, inertias, joint tree and limits, the same collision shapes (one geom per
Drake collision geometry, support spheres included) and friction coefficients, the same collision
filters, PD position actuators with Drake's gains and effort limits (the command ``q_d + kd / kp * v_d``
makes MuJoCo's ``kp (ctrl - q) - kv v`` Drake's ``kp (q_d - q) + kd (v_d - v)``), gravity compensation
through the actuators and couplers (a URDF's mimic joints: ``urdf_couplers``) as equality constraints.
``mujoco_names`` names the plant's bodies and joints in MuJoCo, ``mujoco_qpos`` its positions.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
from pydrake.geometry import (
    Box,
    Capsule,
    Convex,
    Cylinder,
    Ellipsoid,
    HalfSpace,
    Mesh,
    SceneGraphInspector,
    Sphere,
)
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, JointActuatorIndex, JointIndex, ModelInstanceIndex

INTEGRATOR = "implicitfast"
"""MuJoCo's default integrator (semi-implicit Euler) takes the actuators' damping explicitly: with
Drake's gains the robot ends its sequences up to 0.6 (m or rad) off the last knot at 5 ms and
diverges at 20 ms. ``implicitfast`` takes it implicitly (as SAP does)."""


class Coupler(NamedTuple):
    """A coupler constraint: ``follower = gear * leader + offset`` (joint names)."""

    follower: str
    leader: str
    gear: float = 1.0
    offset: float = 0.0


def urdf_couplers(path: Path) -> list[Coupler]:
    """The couplers of a URDF's ``<mimic>`` joints (Drake makes them coupler constraints, whose
    parameters pydrake does not expose)."""
    couplers = []
    for joint in ET.parse(path).getroot().iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            couplers.append(
                Coupler(
                    follower=joint.get("name"),
                    leader=mimic.get("joint"),
                    gear=float(mimic.get("multiplier", 1.0)),
                    offset=float(mimic.get("offset", 0.0)),
                )
            )
    return couplers


def _numbers(values) -> str:
    return " ".join(f"{float(v):.12g}" for v in values)


def _pose(element: ET.Element, X: RigidTransform) -> None:
    """Set ``element``'s pos and quat attributes to ``X``."""
    q = X.rotation().ToQuaternion()
    element.set("pos", _numbers(X.translation()))
    element.set("quat", _numbers([q.w(), q.x(), q.y(), q.z()]))


def mujoco_names(plant: MultibodyPlant, kind: str) -> tuple[list, list[str]]:
    """The plant's bodies or joints (``kind``) by index and their MuJoCo names: each one's own name,
    or ``instance/name`` where two share it."""
    if kind == "body":
        elements = [plant.get_body(BodyIndex(i)) for i in range(plant.num_bodies())]
    else:
        elements = [plant.get_joint(JointIndex(i)) for i in range(plant.num_joints())]
    names = [e.name() for e in elements]
    return elements, [
        n if names.count(n) == 1 else f"{plant.GetModelInstanceName(e.model_instance())}/{n}"
        for n, e in zip(names, elements)
    ]


def _geom(
    parent: ET.Element, assets: ET.Element, inspector: SceneGraphInspector, geometry, name: str
) -> ET.Element:
    """A MuJoCo geom for a Drake collision geometry (meshes: their convex hull, else their box)."""
    shape = inspector.GetShape(geometry)
    X = inspector.GetPoseInFrame(geometry)
    geom = ET.SubElement(parent, "geom", name=name)
    if isinstance(shape, Box):
        geom.set("type", "box")
        geom.set("size", _numbers(np.array([shape.width(), shape.depth(), shape.height()]) / 2))
    elif isinstance(shape, Cylinder):
        geom.set("type", "cylinder")
        geom.set("size", _numbers([shape.radius(), shape.length() / 2]))
    elif isinstance(shape, Capsule):
        geom.set("type", "capsule")
        geom.set("size", _numbers([shape.radius(), shape.length() / 2]))
    elif isinstance(shape, Sphere):
        geom.set("type", "sphere")
        geom.set("size", _numbers([shape.radius()]))
    elif isinstance(shape, Ellipsoid):
        geom.set("type", "ellipsoid")
        geom.set("size", _numbers([shape.a(), shape.b(), shape.c()]))
    elif isinstance(shape, HalfSpace):
        geom.set("type", "plane")
        geom.set("size", "0 0 1")
    elif isinstance(shape, Mesh | Convex):
        try:
            hull = inspector.GetConvexHull(geometry)
        except RuntimeError:
            hull = None
        if hull is not None:
            vertices = [hull.vertex(i) for i in range(hull.num_vertices())]
            ET.SubElement(assets, "mesh", name=f"{name}_hull", vertex=_numbers(np.ravel(vertices)))
            geom.set("type", "mesh")
            geom.set("mesh", f"{name}_hull")
        else:
            box = inspector.GetObbInGeometryFrame(geometry)
            geom.set("type", "box")
            geom.set("size", _numbers(box.half_width()))
            X = X @ box.pose()
    else:
        raise NotImplementedError(f"geometry {name!r}: no MuJoCo geom for {type(shape).__name__}")
    _pose(geom, X)
    friction = inspector.GetProximityProperties(geometry).GetPropertyOrDefault(
        "material", "coulomb_friction", None
    )
    if friction is not None:  # MuJoCo's torsional and rolling defaults
        geom.set("friction", f"{friction.dynamic_friction():.12g} 0.005 0.0001")
    return geom


def _inertial(element: ET.Element, body) -> None:
    """``body``'s mass, centre of mass and inertia about it (none for a massless body)."""
    mass = body.default_mass()
    if mass > 0:
        inertia = body.default_spatial_inertia()
        com = inertia.get_com()
        I = inertia.Shift(com).CalcRotationalInertia().CopyToFullMatrix3()
        ET.SubElement(
            element,
            "inertial",
            pos=_numbers(com),
            mass=f"{mass:.12g}",
            fullinertia=_numbers([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]),
        )


class _Tree:
    """One plant's conversion: its bodies and joints by index with their MuJoCo names, each body's
    inboard joint and children, the actuators by joint, and the MJCF's assets and geom names as the
    bodies are written."""

    def __init__(
        self,
        plant: MultibodyPlant,
        inspector: SceneGraphInspector,
        gravity_compensated: tuple[ModelInstanceIndex, ...],
    ) -> None:
        self.plant, self.inspector = plant, inspector
        self.bodies, self.body_names = mujoco_names(plant, "body")
        self.joints, self.joint_names = mujoco_names(plant, "joint")
        self.inboard = {int(j.child_body().index()): (j, n) for j, n in zip(self.joints, self.joint_names)}
        self.children: dict[int, list[int]] = {}
        for j in self.joints:
            self.children.setdefault(int(j.parent_body().index()), []).append(int(j.child_body().index()))
        self.actuated = {}
        for i in range(plant.num_actuators()):
            actuator = plant.get_joint_actuator(JointActuatorIndex(i))
            self.actuated[int(actuator.joint().index())] = actuator
        self.context = plant.CreateDefaultContext()
        self.compensated = {int(i) for i in gravity_compensated}
        self.geometry_names = {}
        self.assets = ET.Element("asset")

    def add_geoms(self, element: ET.Element, body) -> None:
        """A geom per collision geometry of ``body`` (a name taken already gets the body's prefixed)."""
        for g in self.plant.GetCollisionGeometriesForBody(body):
            name = self.inspector.GetName(g)
            if name in self.geometry_names.values():
                name = f"{self.body_names[int(body.index())]}/{name}"
            self.geometry_names[g] = name
            _geom(element, self.assets, self.inspector, g, name)

    def add_children(self, element: ET.Element, index: int) -> None:
        """The bodies whose inboard joint has body ``index`` for its parent, each with its subtree."""
        for child in self.children.get(index, []):
            self.add_body(element, child)

    def add_body(self, parent: ET.Element, index: int) -> None:
        """Body ``index`` in ``parent``: its pose and inboard joint, inertia, geoms and subtree."""
        body = self.bodies[index]
        element = ET.SubElement(parent, "body", name=self.body_names[index])
        self._add_joint(element, body, *self.inboard[index])
        _inertial(element, body)
        if int(body.model_instance()) in self.compensated:
            element.set("gravcomp", "1")
        self.add_geoms(element, body)
        self.add_children(element, index)

    def _add_joint(self, element: ET.Element, body, joint, joint_name: str) -> None:
        """``element``'s pose in its parent and the MuJoCo joint of its inboard ``joint``."""
        kind = joint.type_name()
        X_PF = joint.frame_on_parent().GetFixedPoseInBodyFrame()
        X_CM = joint.frame_on_child().GetFixedPoseInBodyFrame()
        if kind == "quaternion_floating":
            if not joint.parent_body().index() == self.plant.world_body().index():
                raise NotImplementedError(f"joint {joint_name!r}: a floating joint not on the world")
            _pose(element, self.plant.EvalBodyPoseInWorld(self.context, body))
            ET.SubElement(element, "freejoint", name=joint_name)
        elif kind == "weld":
            _pose(element, X_PF @ joint.X_FM() @ X_CM.inverse())
        elif kind in ("revolute", "prismatic"):
            _pose(element, X_PF @ X_CM.inverse())
            self._add_axis_joint(element, body, joint, joint_name, X_CM)
        else:
            raise NotImplementedError(f"joint {joint_name!r}: no MuJoCo joint for a {kind} joint")

    def _add_axis_joint(self, element: ET.Element, body, joint, joint_name: str, X_CM) -> None:
        """A hinge or slide joint with its limits, damping, reflected inertia and gravity compensation."""
        revolute = joint.type_name() == "revolute"
        axis = joint.revolute_axis() if revolute else joint.translation_axis()
        mj_joint = ET.SubElement(
            element,
            "joint",
            name=joint_name,
            type="hinge" if revolute else "slide",
            pos=_numbers(X_CM.translation()),
            axis=_numbers(X_CM.rotation().matrix() @ axis),
        )
        low, high = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        if np.isfinite(low) and np.isfinite(high):
            mj_joint.set("range", _numbers([low, high]))
        if joint.default_damping() > 0:
            mj_joint.set("damping", f"{joint.default_damping():.12g}")
        actuator = self.actuated.get(int(joint.index()))
        if actuator is not None:
            if actuator.default_reflected_inertia() > 0:
                mj_joint.set("armature", f"{actuator.default_reflected_inertia():.12g}")
            if int(body.model_instance()) in self.compensated:
                mj_joint.set("actuatorgravcomp", "true")

    def exclusions(self, root: ET.Element) -> ET.Element:
        """The contact element excluding every pair of bodies whose geometries Drake filters (pairs of
        anchored bodies aside: MuJoCo has no contact among them)."""
        plant = self.plant
        static = {int(b.index()) for b in self.bodies if plant.IsAnchored(b)}
        excluded = ET.SubElement(root, "contact")
        with_geometry = [b for b in self.bodies if plant.GetCollisionGeometriesForBody(b)]
        for a, body_a in enumerate(with_geometry):
            for body_b in with_geometry[a + 1 :]:
                if {int(body_a.index()), int(body_b.index())} <= static:
                    continue
                if all(
                    self.inspector.CollisionFiltered(ga, gb)
                    for ga in plant.GetCollisionGeometriesForBody(body_a)
                    for gb in plant.GetCollisionGeometriesForBody(body_b)
                ):
                    ET.SubElement(
                        excluded,
                        "exclude",
                        body1=self.body_names[int(body_a.index())],
                        body2=self.body_names[int(body_b.index())],
                    )
        return excluded

    def add_actuators(self, root: ET.Element) -> None:
        """A position actuator per PD-controlled joint actuator, in the plant's actuator order."""
        actuators = ET.SubElement(root, "actuator")
        for joint_index, actuator in sorted(self.actuated.items(), key=lambda item: int(item[1].index())):
            if not actuator.has_controller():
                raise NotImplementedError(f"actuator {actuator.name()!r} has no PD controller")
            gains = actuator.get_controller_gains()
            element = ET.SubElement(
                actuators,
                "position",
                name=actuator.name(),
                joint=self.joint_names[joint_index],
                kp=f"{gains.p:.12g}",
                kv=f"{gains.d:.12g}",
            )
            if math.isfinite(actuator.effort_limit()):
                element.set("forcerange", _numbers([-actuator.effort_limit(), actuator.effort_limit()]))


def _add_couplers(root: ET.Element, couplers: Sequence[Coupler]) -> None:
    """An equality element with a joint constraint per coupler (none without couplers)."""
    if couplers:
        equality = ET.SubElement(root, "equality")
        for c in couplers:
            ET.SubElement(
                equality,
                "joint",
                joint1=c.follower,
                joint2=c.leader,
                polycoef=_numbers([c.offset, c.gear, 0, 0, 0]),
            )


def mjcf_from_plant(
    plant: MultibodyPlant,
    inspector: SceneGraphInspector,
    *,
    time_step: float,
    couplers: Sequence[Coupler] = (),
    gravity_compensated: tuple[ModelInstanceIndex, ...] = (),
) -> str:
    """MJCF of a finalized plant's bodies, joints, collision geometry, PD actuators and couplers.

    Joints: weld (a fixed child body), revolute (hinge), prismatic (slide) and quaternion floating
    (free, on a body of the world, at its default pose) ones, with their limits and damping; the
    other positions: ``mujoco_qpos``. Every PD-controlled actuator becomes a position actuator with
    Drake's gains and effort limit (see the module's docstring for its command); ``couplers`` name
    joints by their MuJoCo names (``mujoco_names``). Contacts Drake filters are excluded (MuJoCo's
    own parent filter is off). Bodies of ``gravity_compensated`` model instances get MuJoCo's
    gravity compensation, applied through their joints' actuators.
    """
    tree = _Tree(plant, inspector, gravity_compensated)
    root = ET.Element("mujoco", model="drake_plant")
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    option = ET.SubElement(
        root,
        "option",
        timestep=f"{time_step:g}",
        integrator=INTEGRATOR,
        gravity=_numbers(plant.gravity_field().gravity_vector()),
    )
    ET.SubElement(option, "flag", filterparent="disable")
    root.append(tree.assets)
    worldbody = ET.SubElement(root, "worldbody")
    tree.add_geoms(worldbody, plant.world_body())
    tree.add_children(worldbody, int(plant.world_body().index()))
    excluded = tree.exclusions(root)
    tree.add_actuators(root)
    _add_couplers(root, couplers)
    for element in (tree.assets, excluded):
        if not len(element):
            root.remove(element)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode")


def mujoco_qpos(plant: MultibodyPlant, context, model) -> np.ndarray:
    """MuJoCo's qpos of the plant's positions in ``context`` (a model from ``mjcf_from_plant``)."""
    q = plant.GetPositions(context)
    qpos = model.qpos0.copy()
    joints, names = mujoco_names(plant, "joint")
    for joint, name in zip(joints, names):
        if joint.num_positions() == 0:
            continue
        address, start = model.jnt_qposadr[model.joint(name).id], joint.position_start()
        if joint.type_name() == "quaternion_floating":  # Drake: qw qx qy qz x y z; MuJoCo: x y z qw qx qy qz
            qpos[address : address + 3] = q[start + 4 : start + 7]
            qpos[address + 3 : address + 7] = q[start : start + 4]
        else:
            qpos[address] = q[start]
    return qpos
