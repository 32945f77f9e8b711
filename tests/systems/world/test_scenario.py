"""The ``Scenario``: loading, one-line errors, the planner section (the initialiser and a tagged union
of low-level planners' settings), the former spellings, ``Conditions`` and the world model."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal

import pytest

from hlp_drake.commands.parsing import run_cli
from hlp_drake.errors import FormerName, HlpError
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.conditions import Conditions
from hlp_drake.systems.low_level.protocol import LowLevelConfig
from hlp_drake.systems.low_level.registry import LOW_LEVEL_PLANNERS, LowLevelEntry
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.model import WorldModel


def test_default_scenario_uses_sap_point_contact_and_stiff_materials():
    scenario = load_scenario()
    assert scenario.plant.time_step == pytest.approx(0.01)  # benchmarks/physics_models.py
    assert not scenario.plant.use_sampled_output_ports and not scenario.low_level.reduced_model
    assert scenario.plant.discrete_contact_approximation == "sap"
    assert scenario.plant.contact_model == "point"
    assert scenario.contact.stiffness >= 1e6 and scenario.contact.corner_sphere_radius > 0
    assert scenario.controller.gravity_compensation
    assert 0.1 <= scenario.bodies.object_min_mass < scenario.bodies.object_max_mass <= 0.5
    assert scenario.scene.name.startswith("default") and scenario.planner.initial == "hlp"
    assert scenario.low_level.kind == "sto" and scenario.planner.alternatives == 3


def test_scenario_loads_from_yaml_and_overrides_and_reads_back_its_own_yaml(tmp_path):
    path = tmp_path / "scenario.yaml"
    path.write_text(
        "plant:\n  time_step: 0.005\ncontroller:\n  arm: {kp: 3000.0, kd: 200.0}\nmotion:\n  tcp_speed: 0.2\n"
    )
    scenario = load_scenario(path, data="motion: {tcp_speed: 0.15}\nplanner: {initial: line}\n")
    assert scenario.plant.time_step == 0.005
    assert scenario.plant.discrete_contact_approximation == "sap"  # untouched defaults stay
    assert (scenario.controller.arm.kp, scenario.controller.arm.kd) == (3000.0, 200.0)
    assert scenario.controller.wrist == Scenario().controller.wrist
    assert scenario.motion.tcp_speed == 0.15 and scenario.planner.initial == "line"
    again = load_scenario(data=scenario.yaml)
    assert again.yaml == scenario.yaml and again.key == scenario.key != Scenario().key
    assert again.scene == scenario.scene and again.low_level == scenario.low_level
    (tmp_path / "empty.yaml").write_text("# nothing to change\n")
    assert load_scenario(tmp_path / "empty.yaml").key == Scenario().key


def test_a_scenarios_scene_is_read_whole_in_the_scene_file_format(tmp_path):
    from hlp_drake.scene.io import scene_to_text

    scene = generate_scene("gen1", 5)
    text = "scene:\n" + "".join(f"  {line}\n" for line in scene_to_text(scene).splitlines())
    scenario = load_scenario(data=text + "planner: {low_level: {samples: 3}}\n")
    assert scenario.scene == scene and scenario.low_level.samples == 3
    with pytest.raises(HlpError) as info:  # a scene is whole: no field of the default scene is kept
        load_scenario(data="scene: {name: partial, start: [0.1, 0.0]}\n")
    assert info.value.problems == (
        "overrides: scene: missing field 'table'",
        "overrides: scene: missing field 'target'",
    )


@pytest.mark.parametrize(
    "text, problem",
    [
        ("plant: [0.002,\n", "not valid YAML at line 2"),
        ("plant: {time_stp: 0.002}\n", "plant: unknown field 'time_stp'; did you mean 'time_step'?"),
        ("planer: {initial: line}\n", "scenario: unknown field 'planer'; did you mean 'planner'?"),
        ("colour: red\n", "scenario: unknown field 'colour'"),  # nothing close: no guess
        ("controller: {arm: {kp: fast}}\n", "controller.arm.kp: expected a number, got 'fast'"),
        ("ik: 3\n", "ik: expected a mapping, got int"),
        ("plant: {discrete_contact_approximation: tamsi}\n", "SAP"),
        ("plant: {time_step: 0.0}\n", "plant.time_step must be > 0"),
        ("plant: {time_step: 0.015}\n", "plant.time_step must be <= 0.01, got 0.015"),  # unstable
        ("bodies: {object_min_mass: 1.0, object_max_mass: 0.5}\n", "object_max_mass"),
        (
            "planner: {low_level: {update: annealing}}\n",
            "planner.low_level.update: expected one of greedy, mppi, got 'annealing'",
        ),
        ("planner: {low_level: {samples: 0}}\n", "planner.low_level.samples"),
        ("planner: {low_level: {noise: {end_fraction: 1.5}}}\n", "planner.low_level.noise.end_fraction"),
        ("planner: {low_level: {weld_clearance: 0.0}}\n", "planner.low_level.weld_clearance"),
        ("planner: {low_level: {weld_margin: 0.5}}\n", "planner.low_level.weld_margin"),
        ("transfer: {travel_step: 0.0}\n", "transfer.travel_step"),
        ("planner: {initial: astar}\n", "planner.initial must be one of hlp, line, got 'astar'"),
        (
            "planner: {low_level: {kind: astar}}\n",
            "planner.low_level.kind: unknown low-level planner 'astar'",
        ),
        ("planner: {low_level: 3}\n", "planner.low_level: expected a mapping, got int"),
        ("planner: {alternatives: -1}\n", "planner.alternatives must be between 0 and 100, got -1"),
        ("success: {pregrasp_margin: -0.01}\n", "success.pregrasp_margin must be >= 0"),
        ("scene: {table: 3}\n", "scene.table: expected a mapping"),
        ("grasp: {lift_s: 0.0}\n", "grasp.lift_s"),
        ("closed_loop: {replan_period: 0.0}\n", "closed_loop.replan_period must be > 0, got 0.0"),
        ("closed_loop: {rollouts: 0}\n", "closed_loop.rollouts must be between 1 and 1000000, got 0"),
        ("closed_loop: {track_distance: -0.01}\n", "closed_loop.track_distance must be >= 0"),
        # Values that loaded and then failed inside Drake, or ran out of memory or time:
        ("plant: {time_step: 1.0e-9}\n", "plant.time_step must be between 0.0001 and 0.01, got 1e-09"),
        ("motion: {tcp_speed: 1.0e-9}\n", "motion.tcp_speed must be between 0.01 and 10, got 1e-09"),
        (
            "planner: {low_level: {step_duration: 1.0e-9}}\n",
            "planner.low_level.step_duration must be between 0.001 and 60",
        ),
        ("grasp: {hold_s: 1.0e+9}\n", "grasp.hold_s must be <= 60, got 1e+09"),
        (
            "transfer: {travel_step: 1.0e-9}\n",
            "transfer.travel_step must be between 0.0001 and 0.1, got 1e-09",
        ),
        (
            "perception: {cameras: [{width: 100000}]}\n",
            "perception.cameras[0].width must be between 8 and 4096",
        ),
        ("perception: {cameras: [{fov_y: -5}]}\n", "perception.cameras[0].fov_y must be between 1 and 170"),
        ("perception: {cameras: [{up: [0, 0, 1]}]}\n", "up [0.0, 0.0, 1.0] is parallel to its view"),
        ("perception: {cameras: [{look_at: [0, 0, 1.6]}]}\n", "look_at is its position"),
        (
            "perception: {cameras: [{min_depth: 3, max_depth: 1}]}\n",
            "min_depth < max_depth <= 10 m, got 3 and 1",
        ),
        (
            "perception: {cameras: [{dropout: 1.0}]}\n",
            "perception.cameras[0].dropout must be in [0, 1), got 1",
        ),
        ("perception: {cameras: [{name: a}, {name: a}]}\n", "two cameras are named 'a'"),
        ("perception: {cameras: [{name: ''}]}\n", "perception.cameras[0]: name is empty"),
        (
            "perception: {source: camera, cameras: []}\n",
            "perception.cameras is empty, but perception.source is camera",
        ),
        ("perception: {ransac_points: 0}\n", "perception.ransac_points must be between 3 and 1000000, got 0"),
        (
            "uncertainty: {mass_scale: [-1, 0]}\n",
            "uncertainty.mass_scale must be [low, high] with 0.01 <= low",
        ),
        ("uncertainty: {friction_scale: [2, 0.5]}\n", "got [2, 0.5]"),
        ("uncertainty: {position_sigma: 10.0}\n", "uncertainty.position_sigma must be between 0 and 0.5 m"),
    ],
)
def test_bad_scenario_file_raises_one_line_hlp_errors_naming_the_file_and_field(tmp_path, text, problem):
    path = tmp_path / "bad_scenario.yaml"
    path.write_text(text)
    with pytest.raises(HlpError) as info:
        load_scenario(path)
    assert any(problem in p for p in info.value.problems), info.value.problems
    assert "colour" not in text or "did you mean" not in info.value.problems[0]
    assert all(p.startswith(str(path)) and "\n" not in p for p in info.value.problems)
    with pytest.raises(HlpError, match=r"missing\.yaml"):
        load_scenario(tmp_path / "missing.yaml")


def test_a_camera_source_without_a_camera_is_refused_whichever_way_it_is_asked_for():
    from hlp_drake.experiments.study import Study
    from hlp_drake.systems.execution.job import resolve_study

    no_cameras = "perception: {cameras: []}\n"
    scenario = load_scenario(data=no_cameras)  # fine while the scene comes from the plant
    assert Conditions(perception="truth").applied(scenario).perception.cameras == ()
    expected = "perception.cameras is empty, but perception.source is camera"
    with pytest.raises(HlpError, match=expected):
        Conditions(perception="camera").applied(scenario)
    with pytest.raises(HlpError, match=expected):  # a study's cell: before any job runs
        resolve_study(Study(perception=("camera",)), no_cameras, single_process_rollouts=False)


def test_a_scenario_made_in_python_is_checked_as_it_is_made_so_no_builder_gets_a_bad_one():
    from hlp_drake.systems.perception.cameras import CameraConfig, PerceptionConfig

    bad = PerceptionConfig(source="camera", cameras=(CameraConfig(width=0),))
    with pytest.raises(HlpError, match=r"perception\.cameras\[0\]\.width must be between 8 and 4096"):
        Scenario(perception=bad)
    with pytest.raises(HlpError, match=r"perception\.cameras\[0\]\.width must be between 8 and 4096"):
        replace(Scenario(), perception=bad)  # a variant is made too
    nan = PerceptionConfig(cameras=(CameraConfig(position=(math.nan, 0.0, 1.6)),))
    with pytest.raises(HlpError, match=r"perception\.cameras\[0\]\.position must be finite"):
        Scenario(perception=nan)  # the loader refuses NaN itself; a scenario made in Python is checked here


def test_a_scene_of_more_obstacles_than_a_world_takes_is_refused_before_any_is_built():
    from hlp_drake.scene.model import SceneObject
    from hlp_drake.systems.scenario import MAX_WORLD_OBSTACLES

    scene = load_scenario().scene
    crowd = tuple(
        SceneObject(f"o{i}", "box", 0.05 + 0.02 * (i % 30), -0.45 + 0.03 * (i // 30), (0.01, 0.01, 0.05))
        for i in range(MAX_WORLD_OBSTACLES + 1)
    )
    with pytest.raises(HlpError, match=r"scene: 101 obstacles, more than the 100 a simulated world takes"):
        replace(Scenario(), scene=replace(scene, obstacles=crowd))


@dataclass(frozen=True)
class SketchConfig(LowLevelConfig):
    """The settings of a planner registered by a test only."""

    kind: Literal["sketch"] = "sketch"
    smoothness: float = 1.0


@pytest.fixture
def sketch(monkeypatch):
    """A second low-level planner in the registry, for this test only."""
    entry = LowLevelEntry("sketch", SketchConfig, lambda config, context: None, "a test's planner")
    monkeypatch.setitem(LOW_LEVEL_PLANNERS, "sketch", entry)
    return entry


def test_the_low_level_section_is_a_tagged_union_of_the_registered_planners_settings(sketch):
    chosen = load_scenario(data="planner: {low_level: {kind: sketch, smoothness: 2.0}}")
    assert chosen.low_level == SketchConfig(smoothness=2.0)
    merged = chosen.updated("planner: {low_level: {smoothness: 3.0}}")  # no kind: the one it has
    assert merged.low_level == SketchConfig(smoothness=3.0)
    back = merged.updated("planner: {low_level: {kind: sto, samples: 3}}")  # another kind: its defaults
    assert back.low_level == StoConfig(samples=3)
    assert load_scenario(data=merged.yaml).low_level == merged.low_level  # its YAML reads back
    with pytest.raises(HlpError) as info:
        load_scenario(data="planner: {low_level: {samples: 3, smoothness: 2.0}}")
    (line,) = info.value.problems
    assert line.startswith("overrides: planner.low_level: 'smoothness' is a setting of sketch, not of sto")
    assert "(the low-level planners: sto, trajopt, rrt, sketch; give its kind to use another)" in line
    with pytest.raises(
        HlpError,
        match=r"planner\.low_level\.kind: unknown low-level planner 'prm' \(known: sto, trajopt, rrt, sketch\)",
    ):
        load_scenario(data="planner: {low_level: {kind: prm}}")


def test_the_former_spellings_are_read_in_their_new_places():
    with pytest.warns(
        FormerName, match="optimiser is now planner.low_level.*planner.kind is now planner.initial"
    ):
        former = load_scenario(
            data="planner: {kind: sto}\noptimiser: {samples: 3, alternatives: 1, settle_s: 0.5,"
            " cost: {pregrasp_margin: 0.02, goal_weight: 100.0}}"
        )
    assert former.planner.initial == "line" and former.planner.alternatives == 1
    assert former.low_level == StoConfig(samples=3, cost=replace(StoConfig().cost, goal_weight=100.0))
    assert (former.success.settle_s, former.success.pregrasp_margin) == (0.5, 0.02)
    assert "optimiser" not in former.yaml and "initial: line" in former.yaml  # written the new way
    for both in (
        "planner: {kind: hlp, initial: line}",
        "optimiser: {samples: 3}\nplanner: {low_level: {samples: 4}}",
        "optimiser: {settle_s: 0.5}\nsuccess: {settle_s: 0.4}",
    ):
        with pytest.raises(HlpError, match="given twice"), pytest.warns(FormerName):
            load_scenario(data=both)


def test_a_former_name_on_the_command_line_is_one_note_line_once(capsys):
    def main(argv) -> int:
        for _ in range(2):
            load_scenario(data="optimiser: {samples: 3}", where="old.yaml")
        return 0

    assert run_cli(main, []) == 0
    assert capsys.readouterr().err == (
        "note: old.yaml: read by former names: optimiser is now planner.low_level (its settle_s and "
        "cost.pregrasp_margin: success)\n"
    )


def test_conditions_lay_the_command_lines_settings_over_a_scenario(sketch):
    scenario = load_scenario()
    assert Conditions().applied(scenario) is scenario
    line = Conditions(initial="sto", workers=1, execution="closed", uncertainty=3).applied(scenario)
    assert line.planner.initial == "line" and line.low_level.workers == 1  # sto: the line's alias
    assert line.closed_loop.enabled and line.uncertainty.enabled and line.uncertainty.seed == 3
    other = Conditions(low_level="sketch", workers=4).applied(scenario)  # its default settings
    assert other.low_level == SketchConfig()  # it does not roll out: no workers to set
    with pytest.raises(
        HlpError, match=r"unknown low-level planner 'astar' \(known: sto, trajopt, rrt, sketch\)"
    ):
        Conditions(low_level="astar").applied(scenario)
    with pytest.raises(HlpError, match=r"unknown initialiser 'astar' \(known: hlp, line, sto \(= line\)\)"):
        Conditions(initial="astar").applied(scenario)


def test_the_world_model_gathers_the_sections_a_world_is_made_of():
    scenario = load_scenario(data="plant: {time_step: 0.005}\ncontroller: {gravity_compensation: false}")
    model = scenario.world_model
    assert isinstance(model, WorldModel) and model.plant.time_step == 0.005
    assert (model.robot, model.contact, model.bodies, model.ik) == (
        scenario.robot,
        scenario.contact,
        scenario.bodies,
        scenario.ik,
    )
    assert not model.controller.gravity_compensation and WorldModel().robot == Scenario().robot


def test_a_scene_file_given_as_a_scenario_is_one_line_pointing_at_scene():
    from hlp_drake.scene import DEFAULT_SCENE_FILE

    with pytest.raises(HlpError) as info:
        load_scenario(DEFAULT_SCENE_FILE)
    (problem,) = info.value.problems
    assert problem.startswith(
        f"{DEFAULT_SCENE_FILE}: this is a scene (table, target, obstacles), not a scenario"
    )
    assert "run it with --scene FILE" in problem
    with pytest.raises(HlpError) as info:  # a scenario with a misplaced scene field is not a scene
        load_scenario(data="plant: {time_step: 0.002}\ntable: {length: 1}\n")
    assert info.value.problems == ("overrides: scenario: unknown field 'table'",)
