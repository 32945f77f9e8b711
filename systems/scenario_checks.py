"""The checks of a ``Scenario``'s settings: every value out of range, one message each."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from hlp_drake.errors import HlpError
from hlp_drake.planner.config import planner_config_problems
from hlp_drake.scene.generators import MAX_SEED
from hlp_drake.scene.validation import name_problem
from hlp_drake.systems.optimiser.config import StoCost
from hlp_drake.systems.perception.cameras import CLIPPING, PERCEPTION_SOURCES, camera_pose
from hlp_drake.transfer.rules import TransferConfig

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario

MAX_SETTING = 1e9
"""Largest value of any number in the settings (a stiffness of 1e6 N/m is typical)."""
MAX_TIME_STEP = 0.1
"""s: the largest plant and rollout time step."""
MIN_TIME_STEP = 1e-4
"""s: the smallest plant and rollout time step (a simulated second then takes 10,000 steps)."""
MIN_PERIOD = 1e-3
"""s: the shortest control step, sampling and re-planning period (each one is work per period)."""
MAX_DURATION = 60.0
"""s: the longest segment, settling, grasp phase or period: the simulated time of a run stays bounded."""
MIN_SPEED = 0.01
"""m/s: the slowest tcp speed (with MAX_DURATION per segment, a run's trajectory stays bounded)."""
MIN_TRAVEL_STEP = 1e-4
"""m: the finest step pushes and ways are measured in (their samples grow as its inverse)."""
MAX_PIXELS = 4096
"""The widest and tallest camera image, pixels; its square is the most pixels of all cameras together
(memory per frame grows with them)."""
MAX_CAMERAS = 8
"""Most cameras in a world."""
MAX_SCALE = 100.0
"""The largest factor of ``uncertainty``'s mass and friction ranges."""
MAX_WORKERS = 64
"""Most rollout processes."""
MAX_WORLD_OBSTACLES = 100
"""Most obstacles in a simulated world (the planner alone, ``hlp_drake.planner.plan``, takes a scene's
10,000): 100 on a 2 m table took 0.6 GB and 2 min to plan, verify and execute here; 400, 2.7 GB and
a minute per simulated second; 2,500, 10 GB before the plan."""
SAP_APPROXIMATIONS = ("sap", "lagged", "similar")
"""Discrete contact approximations solved by SAP (TAMSI, "tamsi", cannot simulate the mimic finger)."""
CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")


def scenario_problems(scenario: Scenario) -> list[str]:
    """The reasons ``scenario``'s settings cannot be used (empty when they are fine; the scene is
    validated on its own, by ``validate_scene``)."""
    problems: list[str] = [f"planner.hlp.{p}" for p in planner_config_problems(scenario.planner.hlp)]
    obstacles = getattr(scenario.scene, "obstacles", ())
    if isinstance(obstacles, tuple | list) and len(obstacles) > MAX_WORLD_OBSTACLES:
        problems.append(
            f"scene: {len(obstacles)} obstacles, more than the {MAX_WORLD_OBSTACLES} a simulated world takes "
            "(hlp_drake.planner.plan alone takes more)"
        )

    def positive(
        where: str, value: float, *, zero_ok: bool = False, lower: float = 0.0, upper: float = MAX_SETTING
    ) -> None:
        if not math.isfinite(value) or value < 0 or (value == 0 and not zero_ok):
            problems.append(f"{where} must be {'>= 0' if zero_ok else '> 0'}, got {value}")
        elif value < lower:
            problems.append(f"{where} must be between {lower:g} and {upper:g}, got {value:g}")
        elif value > upper:
            problems.append(f"{where} must be <= {upper:g}, got {value:g}")

    def count(where: str, value: int, low: int, high: int) -> None:
        if not low <= value <= high:
            problems.append(f"{where} must be between {low} and {high}, got {value}")

    plant = scenario.plant
    positive("plant.time_step", plant.time_step, lower=MIN_TIME_STEP, upper=MAX_TIME_STEP)
    if plant.discrete_contact_approximation not in SAP_APPROXIMATIONS:
        problems.append(
            f"plant.discrete_contact_approximation must be one of {', '.join(SAP_APPROXIMATIONS)} "
            f"(the robot's mimic finger needs SAP), got {plant.discrete_contact_approximation!r}"
        )
    if plant.contact_model not in CONTACT_MODELS:
        problems.append(
            f"plant.contact_model must be one of {', '.join(CONTACT_MODELS)}, got {plant.contact_model!r}"
        )
    contact = scenario.contact
    positive("contact.stiffness", contact.stiffness)
    positive("contact.hunt_crossley_dissipation", contact.hunt_crossley_dissipation, zero_ok=True)
    positive("contact.relaxation_time", contact.relaxation_time, zero_ok=True)
    positive("contact.corner_sphere_radius", contact.corner_sphere_radius, zero_ok=True)
    if contact.rim_spheres < 0 or contact.rim_spheres in (1, 2) or contact.rim_spheres > 64:
        problems.append(f"contact.rim_spheres must be 0 or between 3 and 64, got {contact.rim_spheres}")
    for name in ("table_friction", "object_friction", "gripper_friction"):
        positive(f"contact.{name}", getattr(contact, name))
    bodies = scenario.bodies
    positive("bodies.table_thickness", bodies.table_thickness)
    positive("bodies.object_density", bodies.object_density)
    positive("bodies.object_min_mass", bodies.object_min_mass)
    if bodies.object_max_mass < bodies.object_min_mass:
        problems.append(
            f"bodies.object_max_mass ({bodies.object_max_mass}) is below "
            f"bodies.object_min_mass ({bodies.object_min_mass})"
        )
    for name in ("base", "base_yaw", "arm", "wrist", "gripper"):
        gains = getattr(scenario.controller, name)
        positive(f"controller.{name}.kp", gains.kp, zero_ok=True)
        positive(f"controller.{name}.kd", gains.kd, zero_ok=True)
    ik = scenario.ik
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
    count("ik.max_iterations", ik.max_iterations, 1, 100_000)
    count("ik.attempts", ik.attempts, 1, 1000)
    motion = scenario.motion
    positive("motion.tcp_speed", motion.tcp_speed, lower=MIN_SPEED, upper=10.0)
    positive("motion.transit_speed", motion.transit_speed, lower=MIN_SPEED, upper=10.0)
    positive("motion.joint_speed_fraction", motion.joint_speed_fraction, lower=0.01, upper=1.0)
    positive("motion.min_segment_duration", motion.min_segment_duration, upper=MAX_DURATION)
    sto, grasp = scenario.optimiser, scenario.grasp
    count("optimiser.samples", sto.samples, 1, 1000)
    count("optimiser.max_iterations", sto.max_iterations, 1, 10_000)
    count("optimiser.max_rollouts", sto.max_rollouts, 1, 1_000_000)
    count("optimiser.workers", sto.workers, 1, MAX_WORKERS)
    count("optimiser.alternatives", sto.alternatives, 0, 100)
    count("optimiser.max_verifications", sto.max_verifications, 0, 1000)
    if sto.displaced_checks is not None:
        count("optimiser.displaced_checks", sto.displaced_checks, 0, 100)
    positive("optimiser.displaced_sigma", sto.displaced_sigma, zero_ok=True, upper=0.1)
    positive("optimiser.displaced_yaw_sigma", sto.displaced_yaw_sigma, zero_ok=True, upper=math.pi)
    count("optimiser.seed", sto.seed, 0, MAX_SEED)
    rim = sto.rollout_trims.rim_spheres
    if rim < 0 or rim in (1, 2):
        problems.append(f"optimiser.rollout_trims.rim_spheres must be 0 or >= 3, got {rim}")
    positive("optimiser.time_budget_s", sto.time_budget_s, zero_ok=True)
    for name in ("step_duration", "sample_period", "rollout_sample_period"):
        positive(f"optimiser.{name}", getattr(sto, name), lower=MIN_PERIOD, upper=MAX_DURATION)
    for name in ("mppi_temperature", "max_object_speed", "max_sink"):
        positive(f"optimiser.{name}", getattr(sto, name))
    positive("optimiser.rollout_time_step", sto.rollout_time_step, lower=MIN_TIME_STEP, upper=MAX_TIME_STEP)
    positive("optimiser.settle_s", sto.settle_s, zero_ok=True, upper=MAX_DURATION)
    positive("optimiser.weld_clearance", sto.weld_clearance)
    positive("optimiser.weld_lookahead", sto.weld_lookahead, zero_ok=True, upper=MAX_DURATION)
    positive("optimiser.weld_margin", sto.weld_margin, zero_ok=True)
    positive("optimiser.sleep_speed", sto.sleep_speed, zero_ok=True)
    if sto.weld_margin > sto.weld_clearance:
        problems.append(
            f"optimiser.weld_margin ({sto.weld_margin}) must not exceed optimiser.weld_clearance ({sto.weld_clearance})"
        )
    for name in ("vx", "vy", "yaw_rate"):
        positive(f"optimiser.noise.{name}", getattr(sto.noise, name), zero_ok=True)
    if not 0.0 <= sto.noise.end_fraction <= 1.0:
        problems.append(f"optimiser.noise.end_fraction must be in [0, 1], got {sto.noise.end_fraction}")
    for name in StoCost.__dataclass_fields__:
        positive(f"optimiser.cost.{name}", getattr(sto.cost, name), zero_ok=True)
    for name in TransferConfig.__dataclass_fields__:  # every margin may be 0, every length must be > 0
        positive(f"transfer.{name}", getattr(scenario.transfer, name), zero_ok=name.endswith("margin"))
    positive("transfer.travel_step", scenario.transfer.travel_step, lower=MIN_TRAVEL_STEP, upper=0.1)
    closed = scenario.closed_loop
    positive("closed_loop.replan_period", closed.replan_period, lower=MIN_PERIOD, upper=MAX_DURATION)
    count("closed_loop.iterations", closed.iterations, 0, 10_000)
    count("closed_loop.rollouts", closed.rollouts, 1, 1_000_000)
    count("closed_loop.max_rollouts", closed.max_rollouts, 1, 100_000_000)
    positive("closed_loop.replan_distance", closed.replan_distance)
    positive("closed_loop.track_distance", closed.track_distance, zero_ok=True)
    for name in ("close_s", "lift_s"):
        positive(f"grasp.{name}", getattr(grasp, name), upper=MAX_DURATION)
    positive("grasp.held_height", grasp.held_height)
    positive("grasp.lift_height", grasp.lift_height, zero_ok=True)
    positive("grasp.hold_s", grasp.hold_s, zero_ok=True, upper=MAX_DURATION)
    return problems + perception_problems(scenario) + uncertainty_problems(scenario)


def check_scenario(scenario: Scenario) -> Scenario:
    """``scenario`` if its settings can be used: the diagram builders' check of a scenario made in
    Python (a loaded one is checked as it loads, ``load_scenario``).

    Raises:
        HlpError: one line per problem (``scenario_problems``).
    """
    problems = scenario_problems(scenario)
    if problems:
        raise HlpError(*problems)
    return scenario


def _range_problem(where: str, value: float, low: float, high: float, unit: str = "") -> str | None:
    """The message that ``where`` must lie in [``low``, ``high``] if ``value`` does not (NaN does not), else None."""
    if low <= value <= high:
        return None

    def text(number: float) -> str:
        return str(number) if isinstance(number, int) else f"{number:g}"

    return (
        f"{where} must be between {text(low)} and {text(high)}{' ' + unit if unit else ''}, got {text(value)}"
    )


def perception_problems(scenario: Scenario) -> list[str]:
    """The reasons ``scenario.perception`` cannot be used: cameras that could not be built or would
    not bound a frame's memory, and settings out of range (one line each)."""
    perception, problems = scenario.perception, []
    if perception.source not in PERCEPTION_SOURCES:
        problems.append(
            f"perception.source must be one of {', '.join(PERCEPTION_SOURCES)}, got {perception.source!r}"
        )
    cameras = perception.cameras
    if perception.source == "camera" and not cameras:
        problems.append(
            "perception.cameras is empty, but perception.source is camera: the scene needs a camera"
        )
    if len(cameras) > MAX_CAMERAS:
        problems.append(f"perception.cameras: at most {MAX_CAMERAS} cameras, got {len(cameras)}")
    pixels = sum(camera.width * camera.height for camera in cameras)
    if pixels > MAX_PIXELS**2:
        problems.append(f"perception.cameras: at most {MAX_PIXELS**2} pixels in all, got {pixels}")
    names = [camera.name for camera in cameras]
    for name in sorted({n for n in names if names.count(n) > 1}):
        problems.append(f"perception.cameras: two cameras are named {name!r}")
    ranges = []  # (where, value, low, high, unit)
    for i, camera in enumerate(cameras[:MAX_CAMERAS]):
        where = f"perception.cameras[{i}]"
        named = name_problem(camera.name) or ("name is empty" if not camera.name else None)
        if named:
            problems.append(f"{where}: {named}")
        ranges += [
            (f"{where}.width", camera.width, 8, MAX_PIXELS, "pixels"),
            (f"{where}.height", camera.height, 8, MAX_PIXELS, "pixels"),
            (f"{where}.fov_y", camera.fov_y, 1.0, 170.0, "degrees"),
            (f"{where}.depth_noise", camera.depth_noise, 0.0, 0.1, "m"),
            (f"{where}.seed", camera.seed, 0, MAX_SEED, ""),
        ]
        near, far = CLIPPING
        if not near <= camera.min_depth < camera.max_depth <= far:
            problems.append(
                f"{where}: the depth range must satisfy {near:g} <= min_depth < max_depth <= {far:g} m, "
                f"got {camera.min_depth:g} and {camera.max_depth:g}"
            )
        if not 0.0 <= camera.dropout < 1.0:
            problems.append(f"{where}.dropout must be in [0, 1), got {camera.dropout:g}")
        for name in ("position", "look_at", "up"):
            if not all(map(math.isfinite, getattr(camera, name))):
                problems.append(f"{where}.{name} must be finite, got {list(getattr(camera, name))}")
        try:
            camera_pose(camera, scenario.scene)
        except (ValueError, RuntimeError) as error:  # RuntimeError: Drake's, e.g. a pose of NaN
            problems.append(f"{where}: {str(error).splitlines()[0]}")
    ranges += [
        ("perception.table_tolerance", perception.table_tolerance, 1e-5, 0.1, ""),
        ("perception.min_height", perception.min_height, 1e-4, 1.0, ""),
        ("perception.cluster_radius", perception.cluster_radius, 0.0, 0.5, ""),
        ("perception.cylinder_fill", perception.cylinder_fill, 0.5, 1.0, ""),
        ("perception.table_margin", perception.table_margin, 0.0, 1.0, ""),
        ("perception.min_points", perception.min_points, 1, 1_000_000, ""),
        ("perception.border_margin", perception.border_margin, 0, MAX_PIXELS // 2, ""),
        ("perception.ransac_points", perception.ransac_points, 3, 1_000_000, ""),
        ("perception.seed", perception.seed, 0, MAX_SEED, ""),
    ]
    return problems + [p for p in (_range_problem(*r) for r in ranges) if p]


def uncertainty_problems(scenario: Scenario) -> list[str]:
    """The reasons ``scenario.uncertainty``'s model error cannot be drawn (one line each)."""
    uncertainty = scenario.uncertainty
    problems = [
        _range_problem("uncertainty.seed", uncertainty.seed, 0, MAX_SEED),
        _range_problem("uncertainty.position_sigma", uncertainty.position_sigma, 0.0, 0.5, "m"),
        _range_problem("uncertainty.yaw_sigma", uncertainty.yaw_sigma, 0.0, math.pi, "rad"),
    ]
    for name in ("mass_scale", "friction_scale"):
        low, high = getattr(uncertainty, name)
        if not 1.0 / MAX_SCALE <= low <= high <= MAX_SCALE:
            problems.append(
                f"uncertainty.{name} must be [low, high] with {1.0 / MAX_SCALE:g} <= low <= high <= "
                f"{MAX_SCALE:g}, got [{low:g}, {high:g}]"
            )
    return [p for p in problems if p]
