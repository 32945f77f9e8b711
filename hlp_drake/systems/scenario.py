"""``Scenario``: one typed description of a run, the argument of every builder in ``hlp_drake.systems``.

A frozen dataclass tree (the pattern of manipulation's ``Scenario``): the scene, the planner, the
plant and contact settings, how the scene becomes bodies, the robot's controller, keypoint IK,
motion timing, the push transfer's margins, the optimiser and the grasp. Each section is a config
dataclass beside the code that uses it, each field with its range (``hlp_drake.config.ranges``). Loaded
by ``load_scenario`` (``hlp_drake.config.typed_yaml``; problems are located one-line errors), it is passed to
the builders at construction. A ``Scenario`` is checked once, when it is made (in Python too, and by
``dataclasses.replace``): one that exists can be used. ``Scenario.key`` (computed once) identifies
it, e.g. for rollout worlds.

A scenario file gives only what it changes; ``scene:`` is a scene in the format of a scene file (read
whole)::

    scene: {name: mine, table: {length: 0.9, width: 0.8, height: 0.75}, start: [0.1, 0.0],
            target: {name: Target, shape: cylinder, x: 0.7, y: 0.0, size: [0.06, 0.06, 0.12]},
            obstacles: []}
    planner: {kind: hlp}            # hlp (human-like) or sto (the straight line of the STO baseline)
    robot: {name: panda, ...}       # the robot (RobotDescription; --robot NAME reads a shipped one)
    plant: {time_step: 0.01}        # Drake's MultibodyPlantConfig
    controller: {arm: {kp: 2000.0, kd: 150.0}}
    optimiser: {samples: 8, max_iterations: 20}
"""

from __future__ import annotations

import contextvars
import hashlib
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Annotated, Literal

from pydrake.multibody.plant import MultibodyPlantConfig

from hlp_drake.config.ranges import config_problems
from hlp_drake.config.typed_yaml import dump_typed, load_typed
from hlp_drake.errors import HlpError
from hlp_drake.files.documents import parse_yaml, read_document
from hlp_drake.planner.config import PlannerConfig
from hlp_drake.scene.io import default_scene
from hlp_drake.scene.model import Scene
from hlp_drake.scene.validation import scene_problems
from hlp_drake.systems.execution.command import GraspConfig
from hlp_drake.systems.low_level.sto.config import ClosedLoopConfig, StoConfig
from hlp_drake.systems.perception.cameras import MAX_CAMERAS, PerceptionConfig, camera_pose
from hlp_drake.systems.planning.ik import IkConfig, MotionConfig
from hlp_drake.systems.world.robot_description import (
    MOBILE_UR5,
    RobotDescription,
    load_robot,
    with_model_beside,
)
from hlp_drake.systems.world.scene_models import BodiesConfig, ContactConfig
from hlp_drake.systems.world.uncertainty import UncertaintyConfig
from hlp_drake.systems.world.world import PLANT_RANGES, ControlConfig, default_plant_config
from hlp_drake.transfer.rules import TransferConfig

PLANNERS = ("hlp", "sto")
MAX_WORLD_OBSTACLES = 100
"""Most obstacles in a simulated world (the planner alone, ``hlp_drake.planner.plan``, takes a scene's
10,000): 100 on a 2 m table took 0.6 GB and 2 min to plan, verify and execute here; 400, 2.7 GB and
a minute per simulated second; 2,500, 10 GB before the plan."""
_LOADING = contextvars.ContextVar("loading", default=False)
"""True while ``load_scenario`` lays sources over each other: it checks the result once, naming them."""


@dataclass(frozen=True)
class PlannerChoiceConfig:
    """Which plan initialises the optimiser.

    Attributes:
        kind: "hlp" (the human-like planner) or "sto" (the straight line of the baseline STO); the
            optimiser and its settings are the same for both.
        models: a directory of trained decision models (``python -m hlp_drake.train --out DIR``);
            "" for the bundled ones.
        models_sha256: the SHA-256 of the trusted ``models.json`` in ``models``
            (``sha256sum models.json``); "" trusts whatever is there (the bundled models are
            always pinned).
        hlp: the human-like planner's settings.
    """

    kind: Literal["hlp", "sto"] = "hlp"
    models: str = ""
    models_sha256: str = ""
    hlp: PlannerConfig = field(default_factory=PlannerConfig)


@dataclass(frozen=True)
class Scenario:
    """Everything a run depends on (see the module's docstring). Frozen: derive variants with
    ``updated`` (YAML text) or ``dataclasses.replace``. Checked when made: settings out of range
    raise ``HlpError`` (one line each).

    Attributes:
        scene: the table, start, target and obstacles (default: the bundled default scene).
        planner: the planner and its settings.
        robot: the robot (``RobotDescription``; default the mobile UR5).
        plant: Drake's plant settings; ``time_step`` > 0 and a SAP contact approximation ("sap",
            "lagged", "similar"), which the robot's mimic finger needs.
        contact: contact materials.
        bodies: how the scene's table and objects become bodies.
        controller: the robot's PD gains and gravity compensation.
        ik: keypoint inverse kinematics and the start pose.
        motion: the timing of the joint trajectory through the keyframes.
        transfer: the push transfer's margins (the robot's sizes come from its model).
        optimiser: the stochastic trajectory optimiser.
        grasp: the grasp and lift after the reach.
        perception: where the planning blocks' scene comes from (the plant, or the cameras through
            ``ScenePerception``), the world's cameras and the perception block's settings.
        closed_loop: the receding-horizon controller of ``--execution closed``.
        uncertainty: the seeded model error of ``--uncertainty`` (``model_error``).
    """

    scene: Scene = field(default_factory=default_scene)
    planner: PlannerChoiceConfig = field(default_factory=PlannerChoiceConfig)
    robot: RobotDescription = field(default_factory=RobotDescription)
    plant: Annotated[MultibodyPlantConfig, PLANT_RANGES] = field(default_factory=default_plant_config)
    contact: ContactConfig = field(default_factory=ContactConfig)
    bodies: BodiesConfig = field(default_factory=BodiesConfig)
    controller: ControlConfig = field(default_factory=ControlConfig)
    ik: IkConfig = field(default_factory=IkConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    transfer: TransferConfig = field(default_factory=TransferConfig)
    optimiser: StoConfig = field(default_factory=StoConfig)
    grasp: GraspConfig = field(default_factory=GraspConfig)
    perception: PerceptionConfig = field(default_factory=PerceptionConfig)
    closed_loop: ClosedLoopConfig = field(default_factory=ClosedLoopConfig)
    uncertainty: UncertaintyConfig = field(default_factory=UncertaintyConfig)

    def __post_init__(self) -> None:
        """Refuse settings that cannot be used (the scene is checked on its own, ``validate_scene``).

        Raises:
            HlpError: one line per problem (``config_problems``), e.g. "optimiser.samples must be
                between 1 and 1000, got 0".
        """
        if not _LOADING.get():
            problems = config_problems(self)
            if problems:
                raise HlpError(*problems)

    def problems(self, where: str = "") -> list[str]:
        """The rules across sections: the world's obstacles, the cameras' poses over the scene's table,
        and a robot's names in its model (a robot other than the default: its model is parsed, once)."""
        problems = []
        if self.robot != MOBILE_UR5 and not self.robot.problems():
            from hlp_drake.systems.world.start_pose import kinematic_robot

            try:
                kinematic_robot(self.robot)
            except HlpError as error:
                problems += error.problems
        obstacles = getattr(self.scene, "obstacles", ())
        if isinstance(obstacles, tuple | list) and len(obstacles) > MAX_WORLD_OBSTACLES:
            problems.append(
                f"scene: {len(obstacles)} obstacles, more than the {MAX_WORLD_OBSTACLES} a simulated world "
                "takes (hlp_drake.planner.plan alone takes more)"
            )
        for i, camera in enumerate(self.perception.cameras[:MAX_CAMERAS]):
            try:
                camera_pose(camera, self.scene)
            except (ValueError, RuntimeError) as error:  # RuntimeError: Drake's, e.g. a pose of NaN
                problems.append(f"perception.cameras[{i}]: {str(error).splitlines()[0]}")
        return problems

    @cached_property
    def yaml(self) -> str:
        """The scenario as YAML text that ``load_scenario(data=...)`` reads back (computed once)."""
        return dump_typed(self)

    @cached_property
    def key(self) -> str:
        """A digest of ``yaml``: equal for equal scenarios (computed once)."""
        return hashlib.sha256(self.yaml.encode()).hexdigest()

    def updated(self, data: str, *, where: str = "overrides") -> Scenario:
        """This scenario with the YAML text ``data`` laid over it (see ``load_scenario``)."""
        return load_scenario(data=data, defaults=self, where=where)


def load_scenario(
    filename: str | Path | None = None,
    *,
    data: str | None = None,
    defaults: Scenario | None = None,
    where: str | None = None,
) -> Scenario:
    """``defaults`` (``Scenario()``), updated by the file ``filename`` and then by the YAML text ``data``.

    Args:
        where: how messages name ``data`` (default "overrides").

    Raises:
        HlpError: the file is missing or unreadable, is not YAML, has a field the scenario does not
            know or a value of the wrong type, or a value out of range; one line per problem, each
            naming the file (or ``where``) and the field.
    """
    sources: list[tuple[str, str]] = []
    if filename is not None:
        sources.append((str(filename), read_document(filename, missing="scenario file not found")))
    if data is not None:
        sources.append((where or "overrides", data))
    loading = _LOADING.set(True)
    try:
        scenario = Scenario() if defaults is None else defaults
        for name, text in sources:
            document = parse_yaml(text, name)
            scenario = load_typed(Scenario, document, defaults=scenario, where=name, top="scenario")
            if filename is not None and name == str(filename):  # a relative model path: the file's neighbour
                scenario = replace(scenario, robot=with_model_beside(scenario.robot, Path(filename).parent))
    finally:
        _LOADING.reset(loading)
    problems = [f"scene: {p}" for p in scene_problems(scenario.scene)] + config_problems(scenario)
    if problems:
        where = " + ".join(name for name, _ in sources) or "defaults"
        raise HlpError(*(f"{where}: {p}" for p in problems))
    return scenario


def with_conditions(
    scenario: Scenario,
    *,
    execution: str | None = None,
    uncertainty: int | None = None,
    perception: str | None = None,
    robot: str | None = None,
) -> Scenario:
    """``scenario`` run by ``robot`` (a shipped robot's name or a description file: ``load_robot``;
    None: as it says), executed ``execution`` ("open" or "closed"; None: as it says), with seeded
    model error of seed ``uncertainty`` (None: as it says), its scene from ``perception`` ("truth" or
    "camera"; None: as it says): the ``--robot``, ``--execution``, ``--uncertainty`` and
    ``--perception`` options of ``run_scene`` and the experiments.

    Raises:
        HlpError: the settings do not fit together so (e.g. a camera source without a camera).
    """
    changes = {}
    if robot is not None:
        changes["robot"] = load_robot(robot)
    if execution is not None:
        changes["closed_loop"] = replace(scenario.closed_loop, enabled=execution == "closed")
    if uncertainty is not None:
        changes["uncertainty"] = replace(scenario.uncertainty, enabled=True, seed=int(uncertainty))
    if perception is not None:
        changes["perception"] = replace(scenario.perception, source=perception)
    return replace(scenario, **changes) if changes else scenario  # checked as it is made


__all__ = [
    "MAX_WORLD_OBSTACLES",
    "PLANNERS",
    "PlannerChoiceConfig",
    "Scenario",
    "load_scenario",
    "with_conditions",
]
