"""The checks of a ``Scenario``'s settings: every value out of range, one message each."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from hlp_drake.planner.config import planner_config_problems
from hlp_drake.scene.generators import MAX_SEED
from hlp_drake.systems.optimiser_config import StoCost
from hlp_drake.systems.transfer_geometry import TransferConfig

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario

MAX_SETTING = 1e9
"""Largest value of any number in the settings (a stiffness of 1e6 N/m is typical)."""
MAX_TIME_STEP = 0.1
"""s: the largest plant and rollout time step."""
MAX_WORKERS = 64
"""Most rollout processes."""
SAP_APPROXIMATIONS = ("sap", "lagged", "similar")
"""Discrete contact approximations solved by SAP (TAMSI, "tamsi", cannot simulate the mimic finger)."""
CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")


def scenario_problems(scenario: Scenario) -> list[str]:
    """The reasons ``scenario``'s settings cannot be used (empty when they are fine; the scene is
    validated on its own, by ``validate_scene``)."""
    problems: list[str] = [f"planner.hlp.{p}" for p in planner_config_problems(scenario.planner.hlp)]

    def positive(where: str, value: float, *, zero_ok: bool = False, upper: float = MAX_SETTING) -> None:
        if not math.isfinite(value) or value < 0 or (value == 0 and not zero_ok):
            problems.append(f"{where} must be {'>= 0' if zero_ok else '> 0'}, got {value}")
        elif value > upper:
            problems.append(f"{where} must be <= {upper:g}, got {value:g}")

    def count(where: str, value: int, low: int, high: int) -> None:
        if not low <= value <= high:
            problems.append(f"{where} must be between {low} and {high}, got {value}")

    plant = scenario.plant
    positive("plant.time_step", plant.time_step, upper=MAX_TIME_STEP)
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
    positive("motion.tcp_speed", scenario.motion.tcp_speed)
    positive("motion.transit_speed", scenario.motion.transit_speed)
    positive("motion.joint_speed_fraction", scenario.motion.joint_speed_fraction)
    positive("motion.min_segment_duration", scenario.motion.min_segment_duration)
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
    for name in (
        "step_duration",
        "mppi_temperature",
        "sample_period",
        "rollout_sample_period",
        "max_object_speed",
        "max_sink",
    ):
        positive(f"optimiser.{name}", getattr(sto, name))
    positive("optimiser.rollout_time_step", sto.rollout_time_step, upper=MAX_TIME_STEP)
    positive("optimiser.settle_s", sto.settle_s, zero_ok=True)
    positive("optimiser.weld_clearance", sto.weld_clearance)
    positive("optimiser.weld_lookahead", sto.weld_lookahead, zero_ok=True)
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
    closed = scenario.closed_loop
    positive("closed_loop.replan_period", closed.replan_period)
    count("closed_loop.iterations", closed.iterations, 0, 10_000)
    count("closed_loop.rollouts", closed.rollouts, 1, 1_000_000)
    count("closed_loop.max_rollouts", closed.max_rollouts, 1, 100_000_000)
    positive("closed_loop.replan_distance", closed.replan_distance)
    positive("closed_loop.track_distance", closed.track_distance, zero_ok=True)
    for name in ("close_s", "lift_s", "held_height"):
        positive(f"grasp.{name}", getattr(grasp, name))
    for name in ("lift_height", "hold_s"):
        positive(f"grasp.{name}", getattr(grasp, name), zero_ok=True)
    return problems
