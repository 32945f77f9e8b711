"""``WorldConfig``: the simulated world's settings (plant, contact, objects, control, keypoint IK, motion).

A typed dataclass tree, loadable from YAML with Drake's ``yaml_load_typed``; a file only needs the
fields it changes::

    plant:
      time_step: 0.005
    control:
      arm: {kp: 3000.0, kd: 150.0}
    motion:
      tcp_speed: 0.2

The defaults follow the measurements in the project's Drake notes (section F): a discrete plant with
point contact and the SAP solver (the gripper's mimic finger is a coupler constraint, which only SAP
simulates), explicit point-contact stiffness of 1e6 N/m (the default is soft: ~2 mm sag), and small
spheres on the objects' corners and rims so that resting objects neither sink nor tunnel.
"""

# No "from __future__ import annotations": yaml_load_typed reads the field types at run time.
import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed
from pydrake.multibody.plant import MultibodyPlantConfig

from hlp_drake.errors import HlpError
from hlp_drake.systems.sto_config import UPDATES, GraspConfig, StoConfig, StoCost

SAP_APPROXIMATIONS = ("sap", "lagged", "similar")
"""Discrete contact approximations solved by SAP (TAMSI, "tamsi", cannot simulate the mimic finger)."""
CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")


def default_plant_config() -> MultibodyPlantConfig:
    """The plant settings of the world: 2 ms steps, point contact, the SAP solver and approximation."""
    return MultibodyPlantConfig(
        time_step=0.002,
        penetration_allowance=0.001,
        stiction_tolerance=1e-4,
        contact_model="point",
        discrete_contact_approximation="sap",
    )


@dataclass
class PdGains:
    """Gains of a joint PD controller (SI units: N/m and N s/m, or N m/rad and N m s/rad)."""

    kp: float = 0.0
    kd: float = 0.0


@dataclass
class ContactConfig:
    """Contact materials of the table, the scene objects and the gripper (point contact).

    Attributes:
        stiffness: point-contact stiffness of the table, the objects and the robot's geometry, N/m.
        hunt_crossley_dissipation: dissipation used by the "lagged" and "similar" approximations, s/m.
        relaxation_time: dissipation time scale used by the "sap" approximation, s.
        corner_sphere_radius: radius of the contact spheres put in the corners of every box and
            around the rims of every cylinder (flush with the faces), m; 0 turns them off.
        rim_spheres: number of spheres on each rim of a cylinder.
        table_friction, object_friction, gripper_friction: Coulomb friction coefficients (static and
            dynamic); Drake combines two surfaces' coefficients as 2 a b / (a + b).
    """

    stiffness: float = 1.0e6
    hunt_crossley_dissipation: float = 10.0
    relaxation_time: float = 0.01
    corner_sphere_radius: float = 0.001
    rim_spheres: int = 8
    table_friction: float = 0.3
    object_friction: float = 0.4
    gripper_friction: float = 0.8


@dataclass
class SceneModelConfig:
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


@dataclass
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


@dataclass
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
        max_iterations: SNOPT major-iteration limit per solve.
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
    max_iterations: int = 500
    attempts: int = 5


@dataclass
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


@dataclass
class WorldConfig:
    """Everything ``make_world_diagram`` and ``KeypointIk`` need besides the scene.

    Attributes:
        plant: Drake's plant settings; ``time_step`` must be > 0 and ``discrete_contact_approximation``
            one of "sap", "lagged", "similar" (SAP), as the robot's mimic finger needs.
        contact: contact materials.
        scene: table and object models.
        control: robot PD gains.
        ik: keypoint inverse kinematics.
        motion: trajectory timing.
        sto: the stochastic trajectory optimiser.
        grasp: the grasp and lift after the reach.
        meshcat: whether a caller (e.g. a command-line tool) should visualise in MeshCat; see
            ``hlp_drake.systems.world.start_meshcat``.
    """

    plant: MultibodyPlantConfig = field(default_factory=default_plant_config)
    contact: ContactConfig = field(default_factory=ContactConfig)
    scene: SceneModelConfig = field(default_factory=SceneModelConfig)
    control: ControlConfig = field(default_factory=ControlConfig)
    ik: IkConfig = field(default_factory=IkConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    sto: StoConfig = field(default_factory=StoConfig)
    grasp: GraspConfig = field(default_factory=GraspConfig)
    meshcat: bool = False


def config_problems(config: WorldConfig) -> list[str]:
    """The reasons ``config`` cannot be used (empty when it is fine)."""
    problems: list[str] = []

    def positive(where: str, value: float, *, zero_ok: bool = False) -> None:
        if not math.isfinite(value) or value < 0 or (value == 0 and not zero_ok):
            problems.append(f"{where} must be {'>= 0' if zero_ok else '> 0'}, got {value}")

    plant = config.plant
    positive("plant.time_step", plant.time_step)
    if plant.discrete_contact_approximation not in SAP_APPROXIMATIONS:
        problems.append(
            f"plant.discrete_contact_approximation must be one of {', '.join(SAP_APPROXIMATIONS)} "
            f"(the robot's mimic finger needs SAP), got {plant.discrete_contact_approximation!r}"
        )
    if plant.contact_model not in CONTACT_MODELS:
        problems.append(
            f"plant.contact_model must be one of {', '.join(CONTACT_MODELS)}, got {plant.contact_model!r}"
        )
    contact = config.contact
    positive("contact.stiffness", contact.stiffness)
    positive("contact.hunt_crossley_dissipation", contact.hunt_crossley_dissipation, zero_ok=True)
    positive("contact.relaxation_time", contact.relaxation_time, zero_ok=True)
    positive("contact.corner_sphere_radius", contact.corner_sphere_radius, zero_ok=True)
    if contact.rim_spheres < 0 or contact.rim_spheres == 1 or contact.rim_spheres == 2:
        problems.append(f"contact.rim_spheres must be 0 or >= 3, got {contact.rim_spheres}")
    for name in ("table_friction", "object_friction", "gripper_friction"):
        positive(f"contact.{name}", getattr(contact, name))
    scene = config.scene
    positive("scene.table_thickness", scene.table_thickness)
    positive("scene.object_density", scene.object_density)
    positive("scene.object_min_mass", scene.object_min_mass)
    if scene.object_max_mass < scene.object_min_mass:
        problems.append(
            f"scene.object_max_mass ({scene.object_max_mass}) is below "
            f"scene.object_min_mass ({scene.object_min_mass})"
        )
    for name in ("base", "base_yaw", "arm", "wrist", "gripper"):
        gains = getattr(config.control, name)
        positive(f"control.{name}.kp", gains.kp, zero_ok=True)
        positive(f"control.{name}.kd", gains.kd, zero_ok=True)
    ik = config.ik
    for name in (
        "height",
        "position_tolerance",
        "approach_tolerance",
        "roll_tolerance",
        "start_reach",
        "base_max_yaw",
    ):
        positive(f"ik.{name}", getattr(ik, name))
    for name in ("table_clearance", "base_under_table", "base_lateral_margin", "start_base_clearance"):
        positive(f"ik.{name}", getattr(ik, name), zero_ok=True)
    if ik.max_iterations < 1 or ik.attempts < 1:
        problems.append(
            f"ik.max_iterations and ik.attempts must be >= 1, got {ik.max_iterations}, {ik.attempts}"
        )
    positive("motion.tcp_speed", config.motion.tcp_speed)
    positive("motion.transit_speed", config.motion.transit_speed)
    positive("motion.joint_speed_fraction", config.motion.joint_speed_fraction)
    positive("motion.min_segment_duration", config.motion.min_segment_duration)
    sto, grasp = config.sto, config.grasp
    for name in ("samples", "max_iterations", "workers"):
        if int(getattr(sto, name)) < 1:
            problems.append(f"sto.{name} must be >= 1, got {getattr(sto, name)}")
    if int(sto.alternatives) < 0:
        problems.append(f"sto.alternatives must be >= 0, got {sto.alternatives}")
    for name in ("time_budget_s", "step_duration", "mppi_temperature", "rollout_time_step",
                 "sample_period", "max_object_speed", "max_sink"):
        positive(f"sto.{name}", getattr(sto, name))
    positive("sto.settle_s", sto.settle_s, zero_ok=True)
    positive("sto.weld_clearance", sto.weld_clearance)
    positive("sto.weld_lookahead", sto.weld_lookahead, zero_ok=True)
    positive("sto.weld_margin", sto.weld_margin, zero_ok=True)
    if sto.weld_margin > sto.weld_clearance:
        problems.append(
            f"sto.weld_margin ({sto.weld_margin}) must not exceed sto.weld_clearance ({sto.weld_clearance})"
        )
    for name in ("vx", "vy", "yaw_rate"):
        positive(f"sto.noise.{name}", getattr(sto.noise, name), zero_ok=True)
    if not 0.0 <= sto.noise.end_fraction <= 1.0:
        problems.append(f"sto.noise.end_fraction must be in [0, 1], got {sto.noise.end_fraction}")
    if sto.update not in UPDATES:
        problems.append(f"sto.update must be one of {', '.join(UPDATES)}, got {sto.update!r}")
    for name in StoCost.__dataclass_fields__:
        positive(f"sto.cost.{name}", getattr(sto.cost, name), zero_ok=True)
    for name in ("close_s", "lift_s", "held_height"):
        positive(f"grasp.{name}", getattr(grasp, name))
    for name in ("lift_height", "hold_s"):
        positive(f"grasp.{name}", getattr(grasp, name), zero_ok=True)
    return problems


def _one_line(message: str, limit: int = 300) -> str:
    text = " ".join(str(message).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _describe(error: Exception) -> str:
    message = _one_line(error)
    if isinstance(error, AssertionError):  # the typed loader asserts on a scalar where a mapping belongs
        return f"a value has the wrong structure (expected a mapping or a scalar, got {message!r})"
    return message


def load_world_config(path: str | Path | None = None, *, overrides: str | None = None) -> WorldConfig:
    """The defaults, updated by the YAML file ``path`` and then by the YAML text ``overrides``.

    Raises:
        HlpError: the file is missing or unreadable, is not valid YAML, has a key ``WorldConfig``
            does not know or a value of the wrong type, or a value out of range. The one-line
            message names the file (or "overrides") and the problem.
    """
    config = WorldConfig()
    sources: list[tuple[str, str]] = []
    if path is not None:
        try:
            sources.append((str(path), Path(path).read_text()))
        except FileNotFoundError:
            raise HlpError(f"{path}: world config file not found") from None
        except (OSError, UnicodeDecodeError) as error:
            raise HlpError(f"{path}: cannot read the world config: {_one_line(error)}") from None
    if overrides is not None:
        sources.append(("overrides", overrides))
    for where, text in sources:
        try:
            document = yaml.safe_load(text)
        except yaml.YAMLError as error:
            mark = getattr(error, "problem_mark", None)
            where_in = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
            problem = getattr(error, "problem", None) or _one_line(error)
            raise HlpError(f"{where}: invalid YAML{where_in}: {problem}") from None
        if document is None:
            continue  # an empty document (or only comments) changes nothing
        try:
            config = yaml_load_typed(schema=WorldConfig, data=text, defaults=config)
        except (RuntimeError, ValueError, TypeError, KeyError, AssertionError) as error:  # the typed loader's
            raise HlpError(f"{where}: bad world config: {_describe(error)}") from None
    problems = config_problems(config)
    if problems:
        where = " + ".join(name for name, _ in sources) or "defaults"
        raise HlpError(f"{where}: bad world config: {'; '.join(problems)}")
    return config


def dump_world_config(config: WorldConfig) -> str:
    """``config`` as YAML text that ``load_world_config`` reads back (for logs and result files)."""
    return yaml_dump_typed(config)
