"""A ``Scene`` as Drake bodies: a welded table top and the target and obstacles as free bodies.

Everything is built programmatically (no model files). The table is a box ``length x width x
table_thickness`` whose top surface is at the table's height, welded to the world; it has no legs, so
the robot's base may drive under its top. Every scene object becomes a model instance and a body,
both named after the object, with a box or cylinder for collision and illustration (``BodiesConfig``).

Contact (point contact, see the project's Drake notes section F): every collision geometry gets an
explicit stiffness and dissipation, and each object carries small contact spheres in its corners
(boxes) or around both rims (cylinders), flush with its faces. A box resting on a box under point
contact touches in one point and slowly sinks and rocks; the spheres give it a stable support
polygon. With 2 ms steps resting objects stay within ~0.1 mm.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import Annotated

import numpy as np
from pydrake.geometry import (
    AddContactMaterial,
    Box,
    Cylinder,
    GeometryId,
    ProximityProperties,
    SceneGraphInspector,
    Sphere,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex, RigidBody, SpatialInertia, UnitInertia
from pydrake.systems.framework import Context

from hlp_drake.config.ranges import NonNegativeFloat, PositiveFloat, Rule
from hlp_drake.scene.model import Scene, SceneObject, Table, plan_view_order

TABLE_NAME = "table"
TABLE_COLOR = np.array([0.55, 0.40, 0.25, 1.0])
TARGET_COLOR = np.array([0.85, 0.15, 0.15, 1.0])
OBSTACLE_COLOR = np.array([0.25, 0.45, 0.80, 1.0])
RIM_SPHERES = Rule(
    lambda v: not (v < 0 or v in (1, 2) or v > 64), "{where} must be 0 or between 3 and 64, got {value}"
)


@dataclass(frozen=True)
class ContactConfig:
    """Contact materials of the table, the scene objects and the gripper (point contact).

    Attributes:
        stiffness: point-contact stiffness of the table, objects and robot, N/m (Drake's default: soft).
        hunt_crossley_dissipation, relaxation_time: dissipation of "lagged", "similar" (s/m) and "sap" (s).
        corner_sphere_radius: the support spheres' radius, m (0: none); ``rim_spheres``: spheres per
            cylinder rim; ``top_spheres``: on the top corners and rim too, not just the bottom ones.
        robot_self_contact: contact between the robot's links (the plant filters links one joint apart).
        table_friction, object_friction, gripper_friction: Coulomb coefficients (static = dynamic, two
            surfaces combined as 2 a b / (a + b)).
    """

    stiffness: PositiveFloat = 1.0e6
    hunt_crossley_dissipation: NonNegativeFloat = 10.0
    relaxation_time: NonNegativeFloat = 0.01
    corner_sphere_radius: NonNegativeFloat = 0.001
    rim_spheres: Annotated[int, RIM_SPHERES] = 4
    top_spheres: bool = False
    robot_self_contact: bool = False
    table_friction: PositiveFloat = 0.3
    object_friction: PositiveFloat = 0.4
    gripper_friction: PositiveFloat = 0.8


@dataclass(frozen=True)
class BodiesConfig:
    """How a ``Scene`` becomes bodies: a table top ``table_thickness`` m thick (its top at the table's
    height), objects of ``object_density`` kg/m^3, masses clipped to [object_min_mass, object_max_mass] kg."""

    table_thickness: PositiveFloat = 0.04
    object_density: PositiveFloat = 400.0
    object_min_mass: PositiveFloat = 0.1
    object_max_mass: float = 0.5

    def problems(self, where: str) -> list[str]:
        """The rule across the fields (``where``: the section's path)."""
        low, high = self.object_min_mass, self.object_max_mass
        if not high < low:
            return []
        return [f"{where}.object_max_mass ({high}) is below {where}.object_min_mass ({low})"]


@dataclass(frozen=True)
class SceneModels:
    """The model instances ``add_scene`` created.

    Attributes:
        table: the table's model instance (one body, ``table``, welded to the world).
        objects: per scene object name (target first), its model instance; its body has the same name.
        welded: whether the objects were welded at their scene poses (a planning model) rather than free.
        welded_objects: the names of the objects welded at their scene poses (all of them if ``welded``).
    """

    table: ModelInstanceIndex
    objects: dict[str, ModelInstanceIndex]
    welded: bool = False
    welded_objects: frozenset[str] = frozenset()

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.objects)


def object_mass(obj: SceneObject, config: BodiesConfig) -> float:
    """The object's mass, kg: its volume times the density, clipped to the configured range."""
    sx, sy, height = obj.size
    volume = math.pi * (sx / 2.0) ** 2 * height if obj.shape == "cylinder" else sx * sy * height
    return float(np.clip(volume * config.object_density, config.object_min_mass, config.object_max_mass))


def object_pose(obj: SceneObject, table_height: float) -> RigidTransform:
    """The pose of an object's body frame (its centre) standing upright on the table top."""
    centre = [obj.x, obj.y, table_height + obj.height / 2.0]
    return RigidTransform(RotationMatrix.MakeZRotation(obj.yaw), centre)


def _contact_properties(contact: ContactConfig, friction: float) -> ProximityProperties:
    properties = ProximityProperties()
    AddContactMaterial(
        dissipation=contact.hunt_crossley_dissipation,
        point_stiffness=contact.stiffness,
        friction=CoulombFriction(friction, friction),
        properties=properties,
    )
    if contact.relaxation_time > 0:
        properties.AddProperty("material", "relaxation_time", contact.relaxation_time)
    return properties


def _support_points(obj: SceneObject, contact: ContactConfig) -> list[np.ndarray]:
    """Centres (in the object's frame) of its contact spheres, flush with its faces."""
    r = contact.corner_sphere_radius
    if r <= 0:
        return []
    sx, sy, height = obj.size
    z = height / 2.0 - r
    levels = (-1, 1) if contact.top_spheres else (-1,)
    if obj.shape == "box":
        x, y = sx / 2.0 - r, sy / 2.0 - r
        return [np.array([i * x, j * y, k * z]) for i in (-1, 1) for j in (-1, 1) for k in levels]
    if contact.rim_spheres <= 0:
        return []
    rho = sx / 2.0 - r
    angles = 2.0 * math.pi * np.arange(contact.rim_spheres) / contact.rim_spheres
    return [np.array([rho * math.cos(a), rho * math.sin(a), k * z]) for k in levels for a in angles]


def _add_object(
    plant: MultibodyPlant,
    obj: SceneObject,
    contact: ContactConfig,
    bodies: BodiesConfig,
    *,
    color: np.ndarray,
    support_spheres: bool = True,
    scales: tuple[float, float] = (1.0, 1.0),
) -> tuple[ModelInstanceIndex, RigidBody]:
    sx, sy, height = obj.size
    if obj.shape not in ("box", "cylinder"):
        raise ValueError(f"object {obj.name!r} has unknown shape {obj.shape!r}")
    instance = plant.AddModelInstance(obj.name)
    mass = object_mass(obj, bodies) * scales[0]
    if obj.shape == "box":
        shape = Box(sx, sy, height)
        unit_inertia = UnitInertia.SolidBox(sx, sy, height)
    else:
        shape = Cylinder(sx / 2.0, height)
        unit_inertia = UnitInertia.SolidCylinder(sx / 2.0, height, [0.0, 0.0, 1.0])
    body = plant.AddRigidBody(obj.name, instance, SpatialInertia(mass, np.zeros(3), unit_inertia))
    properties = _contact_properties(contact, contact.object_friction * scales[1])
    plant.RegisterCollisionGeometry(body, RigidTransform(), shape, f"{obj.name}_collision", properties)
    plant.RegisterVisualGeometry(body, RigidTransform(), shape, f"{obj.name}_visual", color)
    sphere = Sphere(contact.corner_sphere_radius) if contact.corner_sphere_radius > 0 else None
    for index, centre in enumerate(_support_points(obj, contact) if support_spheres else []):
        plant.RegisterCollisionGeometry(
            body, RigidTransform(centre), sphere, f"{obj.name}_support_{index}", properties
        )
    return instance, body


def is_support_geometry(inspector: SceneGraphInspector, geometry: GeometryId) -> bool:
    """Whether ``geometry``, of an object's body, is one of its support spheres (inside its shape: an
    object is a box or a cylinder)."""
    return isinstance(inspector.GetShape(geometry), Sphere)


def add_scene(
    plant: MultibodyPlant,
    scene: Scene,
    *,
    contact: ContactConfig | None = None,
    bodies: BodiesConfig | None = None,
    weld_objects: bool = False,
    welded_objects: Iterable[str] = (),
    with_objects: bool = True,
    scales: dict[str, tuple[float, float]] | None = None,
) -> SceneModels:
    """Add ``scene``'s table and objects to ``plant`` (not yet finalized).

    Args:
        plant: the plant; it must be registered with a SceneGraph for the geometry.
        scene: the scene.
        contact, bodies: contact materials and body settings (a ``Scenario``'s; the defaults by default).
        weld_objects: weld the objects to the world at their scene poses (a planning model) instead
            of leaving them free.
        welded_objects: names of objects to weld at their scene poses while the others stay free
            (objects a motion cannot reach, to shrink a simulation's contact problem); they get no
            support spheres (they rest on nothing, and their shape holds the spheres anyway).
        with_objects: False adds the table only (``SceneModels.objects`` is then empty).
        scales: per object name, factors on its mass and its friction coefficient (a world with
            model error, ``model_error``; default 1).

    Returns:
        The model instances; the objects' free-body default poses are their scene poses.

    Raises:
        ValueError: an object's name is taken by another model instance of the plant, the plant
            is finalized, or ``welded_objects`` names an object the scene does not have.
    """
    contact = ContactConfig() if contact is None else contact
    bodies = BodiesConfig() if bodies is None else bodies
    if plant.is_finalized():
        raise ValueError("add_scene needs a plant that is not finalized yet")
    welded = _welded_names(plant, scene, welded_objects, weld_objects)
    table = scene.table
    table_instance = _add_table(plant, table, contact, bodies.table_thickness)
    objects: dict[str, ModelInstanceIndex] = {}
    for obj in (scene.target, *plan_view_order(scene.obstacles)) if with_objects else ():
        color = TARGET_COLOR if obj is scene.target else OBSTACLE_COLOR
        instance, body = _add_object(
            plant,
            obj,
            contact,
            bodies,
            color=color,
            support_spheres=weld_objects or obj.name not in welded,
            scales=(scales or {}).get(obj.name, (1.0, 1.0)),
        )
        objects[obj.name] = instance
        X_WO = object_pose(obj, table.height)
        if obj.name in welded:
            plant.WeldFrames(plant.world_frame(), body.body_frame(), X_WO)
        else:
            plant.SetDefaultFloatingBaseBodyPose(body, X_WO)
    return SceneModels(table=table_instance, objects=objects, welded=weld_objects, welded_objects=welded)


def _welded_names(
    plant: MultibodyPlant, scene: Scene, welded_objects: Iterable[str], weld_objects: bool
) -> frozenset[str]:
    """The names of the objects to weld; a ``ValueError`` for an unknown one or a name the plant has."""
    names = [obj.name for obj in scene.objects]
    welded = frozenset(welded_objects)
    unknown = sorted(welded - set(names))
    if unknown:
        raise ValueError(f"cannot weld objects the scene does not have: {', '.join(unknown)}")
    for name in (TABLE_NAME, *names):
        if plant.HasModelInstanceNamed(name):
            raise ValueError(f"the plant already has a model instance named {name!r}")
    return frozenset(names) if weld_objects else welded


def _add_table(
    plant: MultibodyPlant, table: Table, contact: ContactConfig, thickness: float
) -> ModelInstanceIndex:
    """The table top: a box ``thickness`` thick welded with its top at the table's height."""
    table_instance = plant.AddModelInstance(TABLE_NAME)
    box = Box(table.length, table.width, thickness)
    table_body = plant.AddRigidBody(
        TABLE_NAME,
        table_instance,
        SpatialInertia(20.0, np.zeros(3), UnitInertia.SolidBox(table.length, table.width, thickness)),
    )
    plant.WeldFrames(
        plant.world_frame(),
        table_body.body_frame(),
        RigidTransform([table.length / 2.0, 0.0, table.height - thickness / 2.0]),
    )
    properties = _contact_properties(contact, contact.table_friction)
    plant.RegisterCollisionGeometry(table_body, RigidTransform(), box, "table_top_collision", properties)
    plant.RegisterVisualGeometry(table_body, RigidTransform(), box, "table_top_visual", TABLE_COLOR)
    return table_instance


def object_body(plant: MultibodyPlant, name: str) -> RigidBody:
    """The body of the scene object ``name`` (its model instance and body share the name)."""
    return plant.GetBodyByName(name, plant.GetModelInstanceByName(name))


def set_object_poses(plant: MultibodyPlant, context: Context, scene: Scene) -> None:
    """Put every object of ``scene`` at rest on the table at its scene pose, in the plant's ``context``."""
    for obj in scene.objects:
        body = object_body(plant, obj.name)
        plant.SetFreeBodyPose(context, body, object_pose(obj, scene.table.height))
        instance = body.model_instance()
        plant.SetVelocities(context, instance, np.zeros(plant.num_velocities(instance)))


def object_poses(plant: MultibodyPlant, context: Context, names) -> dict[str, RigidTransform]:
    """The world poses of the named objects' bodies (their centres)."""
    return {name: object_body(plant, name).EvalPoseInWorld(context) for name in names}


def object_planar_poses(
    plant: MultibodyPlant, context: Context, names
) -> dict[str, tuple[float, float, float]]:
    """Per object name, its planar pose (x, y, yaw): centre position and heading of its x axis.

    ``names`` may be a list of names or a ``Scene`` (all its objects). The yaw is the angle of the
    body's x axis projected onto the floor plane.
    """
    if isinstance(names, Scene):
        names = [obj.name for obj in names.objects]
    result = {}
    for name, X in object_poses(plant, context, names).items():
        R = X.rotation().matrix()
        x, y, _ = X.translation()
        result[name] = (float(x), float(y), float(math.atan2(R[1, 0], R[0, 0])))
    return result


def over_table_mask(positions: np.ndarray, table) -> np.ndarray:
    """Per object centre in ``positions`` (m, 3): whether it lies within the table's footprint."""
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    x_min, y_min, x_max, y_max = table.bounds
    x, y = positions[:, 0], positions[:, 1]
    return (x >= x_min) & (x <= x_max) & (y >= y_min) & (y <= y_max)


def off_table_mask(positions: np.ndarray, table) -> np.ndarray:
    """Per object centre in ``positions`` (m, 3): whether it is off the table (below the top or
    outside its footprint)."""
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    return ~(over_table_mask(positions, table) & (positions[:, 2] >= table.height))


def fallen_objects(plant: MultibodyPlant, context: Context, scene: Scene) -> list[str]:
    """Names of the objects that are no longer on the table.

    An object has fallen when its centre is below the table top or outside the table's footprint.
    """
    names = [obj.name for obj in scene.objects]
    poses = object_poses(plant, context, names)
    mask = off_table_mask(np.array([poses[name].translation() for name in names]), scene.table)
    return [name for name, off in zip(names, mask) if off]


def tilted_objects(
    plant: MultibodyPlant, context: Context, scene: Scene, *, max_tilt: float = math.radians(20.0)
) -> list[str]:
    """Names of the objects whose vertical axis leans more than ``max_tilt`` rad (knocked over)."""
    names = [obj.name for obj in scene.objects]
    return [
        name
        for name, X in object_poses(plant, context, names).items()
        if X.rotation().matrix()[2, 2] < math.cos(max_tilt)
    ]


def scene_from_plant(plant: MultibodyPlant, context: Context, scene: Scene) -> Scene:
    """``scene`` with every object moved to its current planar pose in ``context`` (for replanning)."""
    poses = object_planar_poses(plant, context, scene)

    def moved(obj: SceneObject) -> SceneObject:
        x, y, yaw = poses[obj.name]
        return obj.moved(x, y, yaw)

    return replace(scene, target=moved(scene.target), obstacles=tuple(moved(obj) for obj in scene.obstacles))


__all__ = [
    "TABLE_NAME",
    "BodiesConfig",
    "ContactConfig",
    "SceneModels",
    "add_scene",
    "fallen_objects",
    "object_body",
    "object_mass",
    "object_planar_poses",
    "object_pose",
    "object_poses",
    "off_table_mask",
    "over_table_mask",
    "scene_from_plant",
    "set_object_poses",
    "tilted_objects",
]
