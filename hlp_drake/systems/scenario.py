"""``Scenario``: one typed description of a run, the argument of every builder in ``hlp_drake.systems``.

A frozen dataclass tree (the pattern of manipulation's ``Scenario``): the scene, the planner (the
initialiser and the low-level planner), the plant and contact settings, how the scene becomes
bodies, the robot's controller, keypoint IK, motion timing, the push transfer's margins and the
grasp. Only the top-level builders read it whole (``make_world_diagram``, ``make_planning_diagram``,
``make_execution_diagram``, the experiments' job); each block takes its own sections. Each section is a config
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
    planner:                        # the initialiser and the low-level planner
      initial: hlp                  # hlp (human-like) or line (the straight line; sto: its alias)
      low_level: {kind: sto, samples: 8, max_iterations: 20}   # the STO's settings
    robot: {name: panda, ...}       # the robot (RobotDescription; --robot NAME reads a shipped one)
    plant: {time_step: 0.01}        # Drake's MultibodyPlantConfig: the planner's model
    world: reference                # what the robot acts in and is judged in (or model)
    controller: {arm: {kp: 2000.0, kd: 150.0}}

The former spellings ``planner: {kind: ...}`` and ``optimiser: {...}`` are read as
``planner.initial`` and ``planner.low_level`` (its ``alternatives``: ``planner.alternatives``; its
``settle_s`` and ``cost.pregrasp_margin``: ``success``): ``legacy``.
"""

from __future__ import annotations

import contextvars
import warnings
from dataclasses import dataclass, field, fields, replace
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any

from pydrake.multibody.plant import MultibodyPlantConfig

from hlp_drake.config.ranges import Count, Rule, config_problems
from hlp_drake.config.typed_yaml import Documented, load_typed
from hlp_drake.errors import FormerName, HlpError
from hlp_drake.files.documents import parse_yaml, read_document
from hlp_drake.planner.config import PlannerConfig
from hlp_drake.scene.io import default_scene
from hlp_drake.scene.model import Scene
from hlp_drake.scene.validation import scene_problems
from hlp_drake.systems.execution.closed_loop import ClosedLoopConfig
from hlp_drake.systems.execution.command import GraspConfig
from hlp_drake.systems.low_level.protocol import LowLevelConfig
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.perception.cameras import MAX_CAMERAS, PerceptionConfig, camera_pose
from hlp_drake.systems.planning.config import DEFAULT_ALTERNATIVES, IkConfig, MotionConfig
from hlp_drake.systems.planning.initialisers import ALIASES, INITIALISERS
from hlp_drake.systems.world.judge import WorldConfig, world_section
from hlp_drake.systems.world.model import WorldModel
from hlp_drake.systems.world.robot_description import (
    MOBILE_UR5,
    RobotDescription,
    with_model_beside,
)
from hlp_drake.systems.world.scene_models import BodiesConfig, ContactConfig
from hlp_drake.systems.world.success import SuccessConfig
from hlp_drake.systems.world.uncertainty import UncertaintyConfig
from hlp_drake.systems.world.world_config import PLANT_RANGES, ControlConfig, default_plant_config
from hlp_drake.transfer.rules import TransferConfig

MAX_WORLD_OBSTACLES = 100
"""Most obstacles in a simulated world (the planner alone, ``hlp_drake.planner.plan``, takes a scene's
10,000): 100 on a 2 m table took 0.6 GB and 2 min to plan, verify and execute here; 400, 2.7 GB and
a minute per simulated second; 2,500, 10 GB before the plan."""
_LOADING = contextvars.ContextVar("loading", default=False)
"""True while ``load_scenario`` lays sources over each other: it checks the result once, naming them."""


INITIAL = Rule(
    lambda v: v in INITIALISERS, f"{{where}} must be one of {', '.join(INITIALISERS)}, got {{value!r}}"
)


@dataclass(frozen=True)
class PlannerChoiceConfig:
    """The initialiser and the low-level planner.

    Attributes:
        initial: the initialiser, the low-level planner's start (``INITIALISERS``): "hlp" (the
            human-like planner) or "line" (the straight line of the paper's STO baseline).
        low_level: the low-level planner's settings, its name in ``kind`` (``LOW_LEVEL_PLANNERS``;
            default: the STO's).
        alternatives: when the plan's first motion fails (its IK, or the low-level planner's first
            rollout), its next this many distinct candidate plans may take its place (the HLP's, by
            expected arm collision; the straight line has none): the first whose IK succeeds
            replaces a plan whose IK failed (``KeypointIk``), and the STO rolls each out once and
            goes on from the best (0: never).
        models: a directory of trained decision models (``python -m hlp_drake.train --out DIR``);
            "" for the bundled ones.
        models_sha256: the SHA-256 of the trusted ``models.json`` in ``models``
            (``sha256sum models.json``); "" trusts whatever is there (the bundled models are
            always pinned).
        hlp: the human-like planner's settings.
    """

    initial: Annotated[str, INITIAL] = "hlp"
    low_level: LowLevelConfig = field(default_factory=StoConfig)
    alternatives: Annotated[int, Count(0, 100)] = DEFAULT_ALTERNATIVES
    models: str = ""
    models_sha256: str = ""
    hlp: PlannerConfig = field(default_factory=PlannerConfig)


@dataclass(frozen=True)
class Scenario(Documented):
    """Everything a run depends on (see the module's docstring). Frozen: derive variants with
    ``updated`` (YAML text) or ``dataclasses.replace``. Checked when made: settings out of range
    raise ``HlpError`` (one line each).

    Attributes:
        scene: the table, start, target and obstacles (default: the bundled default scene).
        planner: the initialiser, the low-level planner and their settings.
        robot: the robot (``RobotDescription``; default the mobile UR5).
        plant: Drake's plant settings; ``time_step`` > 0 and a SAP contact approximation ("sap",
            "lagged", "similar"), which the robot's mimic finger needs.
        contact: contact materials.
        bodies: how the scene's table and objects become bodies.
        controller: the robot's PD gains and gravity compensation.
        ik: keypoint inverse kinematics and the start pose.
        motion: the timing of the joint trajectory through the keyframes.
        transfer: the push transfer's margins (the robot's sizes come from its model).
        success: the paper's success test of a reach (the planners' that simulate, and the
            execution's).
        grasp: the grasp and lift after the reach.
        perception: where the planning blocks' scene comes from (the plant, or the cameras through
            ``ScenePerception``), the world's cameras and the perception block's settings.
        closed_loop: the receding-horizon controller of ``--execution closed`` (a low-level planner
            that re-plans, the STO).
        uncertainty: the seeded model error of ``--uncertainty`` (``model_error``).
        world: what the robot acts in and the run is judged in (``WorldConfig``; ``--world``):
            ``reference`` (finer physics than the planner's model) or ``model`` (the planner's own).
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
    success: SuccessConfig = field(default_factory=SuccessConfig)
    grasp: GraspConfig = field(default_factory=GraspConfig)
    perception: PerceptionConfig = field(default_factory=PerceptionConfig)
    closed_loop: ClosedLoopConfig = field(default_factory=ClosedLoopConfig)
    uncertainty: UncertaintyConfig = field(default_factory=UncertaintyConfig)
    world: WorldConfig = field(default_factory=WorldConfig)

    def __post_init__(self) -> None:
        """Refuse settings that cannot be used (the scene is checked on its own, ``validate_scene``).

        Raises:
            HlpError: one line per problem (``config_problems``), e.g. "planner.low_level.samples must be
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
    def world_model(self) -> WorldModel:
        """The planner's model of the world besides the scene: the robot, plant, contact, bodies,
        controller and start pose (``ik``) sections (computed once)."""
        return WorldModel(self.robot, self.plant, self.contact, self.bodies, self.controller, self.ik)

    @cached_property
    def executed_model(self) -> WorldModel:
        """What the robot acts in: ``world_model`` with the ``world`` section's physics (itself with
        ``world: model``)."""
        return self.world.of(self.world_model)

    @property
    def low_level(self) -> LowLevelConfig:
        """The low-level planner's settings (``planner.low_level``)."""
        return self.planner.low_level

    def updated(self, data: str, *, where: str = "overrides") -> Scenario:
        """This scenario with the YAML text ``data`` laid over it (see ``load_scenario``)."""
        return load_scenario(data=data, defaults=self, where=where)


FORMER_NAMES = {
    "optimiser": "optimiser is now planner.low_level (its settle_s and cost.pregrasp_margin: success)",
    "planner.kind": "planner.kind is now planner.initial",
}
"""The scenario's former names that ``legacy`` reads, and where they are now."""


def _given(document: dict, dotted: str) -> bool:
    """Whether ``document`` has the setting ``dotted`` (e.g. ``planner.kind``)."""
    section: Any = document
    for name in dotted.split("."):
        if not isinstance(section, dict) or name not in section:
            return False
        section = section[name]
    return True


def _a_scene(document: Any) -> bool:
    """Whether ``document`` (a parsed scenario) is a scene instead: only a scene's fields, a table or
    obstacles among them."""
    scene_fields = {f.name for f in fields(Scene)}
    return (
        isinstance(document, dict)
        and bool(document)
        and set(document) <= scene_fields
        and bool({"table", "obstacles"} & set(document))
    )


def legacy(document: Any, where: str) -> Any:
    """``document`` (a parsed scenario) with its former spellings in their places: ``optimiser: {...}``
    is ``planner.low_level: {kind: sto, ...}`` (its ``alternatives``: ``planner.alternatives``),
    ``planner.kind`` is ``planner.initial``, and the initialiser ``sto`` is ``line`` (``ALIASES``).
    A former name (``FORMER_NAMES``) is read with a ``FormerName`` warning saying where it is now.

    Raises:
        HlpError: a setting given in both spellings (one line, naming ``where``).
    """
    if isinstance(document, dict) and "world" in document:
        document = {**document, "world": world_section(document["world"])}
    if not isinstance(document, dict) or not isinstance(document.get("planner", {}), dict):
        return document  # the typed check says what is wrong
    document, planner = dict(document), dict(document.get("planner") or {})
    former = [now for old, now in FORMER_NAMES.items() if _given(document, old)]
    if former:
        warnings.warn(f"{where}: read by former names: {'; '.join(former)}", FormerName, stacklevel=2)

    def move(section: dict, old: str, new: str, value: Any) -> None:
        if new in section:
            raise HlpError(f"{where}: planner.{new} is given twice (once by its former name, {old})")
        section[new] = value

    if "kind" in planner:
        move(planner, "planner.kind", "initial", planner.pop("kind"))
    if isinstance(planner.get("initial"), str):
        planner["initial"] = ALIASES.get(planner["initial"], planner["initial"])
    if "optimiser" in document:
        optimiser = document.pop("optimiser")
        if isinstance(optimiser, dict):
            optimiser = dict(optimiser)
            if "alternatives" in optimiser:
                move(planner, "optimiser.alternatives", "alternatives", optimiser.pop("alternatives"))
            document = _moved_success(document, optimiser, where)
            optimiser = {"kind": "sto", **optimiser}
        move(planner, "optimiser", "low_level", optimiser)
    if planner or "planner" in document:
        document["planner"] = planner
    return document


def _moved_success(document: dict, optimiser: dict, where: str) -> dict:
    """``document`` with the success test's settings of the former ``optimiser`` section
    (``settle_s``, ``cost.pregrasp_margin``, taken out of ``optimiser``) in ``success``."""
    moved = {}
    if "settle_s" in optimiser:
        moved["settle_s"] = optimiser.pop("settle_s")
    cost = optimiser.get("cost")
    if isinstance(cost, dict) and "pregrasp_margin" in cost:
        cost = dict(cost)
        moved["pregrasp_margin"] = cost.pop("pregrasp_margin")
        optimiser["cost"] = cost
    if not moved:
        return document
    success = document.get("success") or {}
    if not isinstance(success, dict) or set(moved) & set(success):
        raise HlpError(f"{where}: success.{next(iter(moved))} is given twice (once in the former optimiser)")
    return {**document, "success": {**success, **moved}}


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
            if _a_scene(document):
                raise HlpError(
                    f"{name}: this is a scene (table, target, obstacles), not a scenario: run it with "
                    "--scene FILE, or give it as a scenario's 'scene:' section"
                )
            document = legacy(document, name)
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


__all__ = [
    "MAX_WORLD_OBSTACLES",
    "PlannerChoiceConfig",
    "Scenario",
    "legacy",
    "load_scenario",
]
