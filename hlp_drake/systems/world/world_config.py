"""The world's settings: the plant's (``default_plant_config``, ``PLANT_RANGES``) and the robot's PD
control (``ControlConfig``): a ``Scenario``'s ``plant`` and ``controller``."""

from __future__ import annotations

from dataclasses import dataclass, field

from pydrake.multibody.plant import MultibodyPlantConfig

from hlp_drake.config.ranges import MAX_TIME_STEP, MIN_TIME_STEP, Fields, NonNegativeFloat, Positive, Rule

WRIST_JOINTS = 3
"""The arm's last joints that take ``controller.wrist``'s gains."""
DESIRED_STATE_PORT = "robot.desired_state"
SAP_APPROXIMATIONS = ("sap", "lagged", "similar")
"""Discrete contact approximations solved by SAP (TAMSI, "tamsi", cannot simulate the mimic finger)."""
CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")
PLANT_RANGES = Fields(
    {
        "time_step": Positive(MIN_TIME_STEP, MAX_TIME_STEP),
        "discrete_contact_approximation": Rule(
            lambda v: v in SAP_APPROXIMATIONS,
            f"{{where}} must be one of {', '.join(SAP_APPROXIMATIONS)} (the robot's mimic finger needs SAP), "
            "got {value!r}",
        ),
        "contact_model": Rule(
            lambda v: v in CONTACT_MODELS,
            f"{{where}} must be one of {', '.join(CONTACT_MODELS)}, got {{value!r}}",
        ),
    }
)
"""The ranges of a ``Scenario``'s ``plant`` (Drake's ``MultibodyPlantConfig`` declares none)."""


def default_plant_config() -> MultibodyPlantConfig:
    """The plant settings of the world, the execution model the optimiser also rolls out on: 10 ms
    steps, point contact, the SAP solver and approximation, outputs from the current state.

    SAP simulates the gripper's mimic finger (a coupler constraint). The step and the contact geometry
    (``ContactConfig``) are the fastest setting whose verdicts and final object poses agree with
    the same model at 1 ms (``benchmarks/physics_models.py``; docs/results.md, "One execution model").
    """
    return MultibodyPlantConfig(
        time_step=0.01,
        penetration_allowance=0.001,
        stiction_tolerance=1e-4,
        contact_model="point",
        discrete_contact_approximation="sap",
        use_sampled_output_ports=False,
    )


@dataclass(frozen=True)
class PdGains:
    """Gains of a joint PD controller (SI units: N/m and N s/m, or N m/rad and N m s/rad)."""

    kp: NonNegativeFloat = 0.0
    kd: NonNegativeFloat = 0.0


@dataclass(frozen=True)
class ControlConfig:
    """The robot's joint PD controllers (Drake's PD-controlled actuators, implicit in SAP).

    Attributes:
        base: gains of a mobile base's x and y joints (N/m, N s/m).
        base_yaw: gains of its yaw joint.
        arm: gains of the arm's joints before the wrist.
        wrist: gains of the arm's last three joints.
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


__all__ = [
    "CONTACT_MODELS",
    "DESIRED_STATE_PORT",
    "PLANT_RANGES",
    "SAP_APPROXIMATIONS",
    "WRIST_JOINTS",
    "ControlConfig",
    "PdGains",
    "default_plant_config",
]
