"""A new low-level planner is one module and one registry line: a trivial planner, registered by this
test only (never shipped), that commands the initialiser's trajectory unchanged, runs alone as a
Drake block, through ``run_scene``'s code path and through a two-scene experiment grid."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Literal

import pytest
from sto_support import on

from hlp_drake.commands import command_main
from hlp_drake.commands.parsing import run_cli
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.protocol import LowLevelConfig, LowLevelContext, LowLevelProblem
from hlp_drake.systems.low_level.registry import LOW_LEVEL_PLANNERS, LowLevelEntry, register_low_level
from hlp_drake.systems.low_level.result import LowLevelResult
from hlp_drake.systems.low_level.system import LowLevelPlannerSystem

# --- The planner's module: its settings and its planner ----------------------------------------------


@dataclass(frozen=True)
class AsPlannedConfig(LowLevelConfig):
    """The settings of ``as_planned``: the control step its trajectory is sampled at, s; whether it
    accepts the trajectory."""

    kind: Literal["as_planned"] = "as_planned"
    step: float = 0.5
    accept: bool = True


class AsPlanned:
    """Commands the initialiser's trajectory as it is, and accepts it without simulating it."""

    kind = "as_planned"

    def __init__(self, config: AsPlannedConfig, context: LowLevelContext) -> None:
        self.config = config

    def as_commanded(self, trajectory) -> ControlSequence:
        return ControlSequence.from_trajectory(trajectory, self.config.step)

    def plan(self, problem: LowLevelProblem) -> LowLevelResult:
        reason = None if self.config.accept else "refused by its settings"
        return LowLevelResult(
            self.as_commanded(problem.initial), None, reason is None, reason, low_level=self.kind
        )


@pytest.fixture
def as_planned():
    """The registry line, for this test only."""
    entry = register_low_level(
        LowLevelEntry("as_planned", AsPlannedConfig, AsPlanned, "the initialiser's trajectory, unchanged")
    )
    yield entry
    del LOW_LEVEL_PLANNERS["as_planned"]


# --- It runs -----------------------------------------------------------------------------------------


def test_the_planner_runs_alone_as_a_drake_block(as_planned, scene, trajectories):
    planner = as_planned.make(AsPlannedConfig(step=0.25), LowLevelContext(on(scene).world_model))
    block = LowLevelPlannerSystem(planner)
    context = block.CreateDefaultContext()
    block.get_scene_input_port().FixValue(context, scene)
    block.get_initial_trajectory_input_port().FixValue(context, trajectories["hlp"])
    result = block.get_result_output_port().Eval(context)
    assert result.success and result.low_level == "as_planned" and result.rollouts == 0
    assert result.sequence.duration == pytest.approx(trajectories["hlp"].end_time())
    assert max(result.sequence.steps) <= 0.25 + 1e-9


def test_the_planner_runs_through_run_scenes_code_path(as_planned, tmp_path, capsys):
    out = tmp_path / "run.json"
    status = run_cli(command_main("run-scene"), ["--low-level", "as_planned", "--quiet", "--json", str(out)])
    printed = capsys.readouterr().out
    assert "low-level planner as_planned" in printed and "rollout workers" not in printed  # no pool
    assert "as_planned: success (" in printed and "iterations" not in printed  # it does not roll out
    report = json.loads(out.read_text())
    assert (report["initial"], report["low_level"], report["planner"]) == (
        "hlp",
        "as_planned",
        "hlp+as_planned",
    )
    assert report["optimisation"]["low_level"] == "as_planned" and report["rollouts"] == 0
    assert status == (0 if report["success"] else 1) and report["success"], report["failure_reason"]
    assert run_cli(command_main("run-scene"), ["--low-level", "as_planned", "--execution", "closed"]) == 2
    assert "closed-loop execution re-plans from the measured state" in capsys.readouterr().err
    config = tmp_path / "refuse.yaml"
    config.write_text("planner:\n  low_level:\n    kind: as_planned\n    accept: false\n")
    argv = ["--config", str(config), "--quiet", "--json", str(out)]
    assert run_cli(command_main("run-scene"), argv) == 1
    assert json.loads(out.read_text())["failure_reason"] == (
        "the low-level planner as_planned found no solution: refused by its settings"
    )


def test_the_planner_runs_through_a_two_scene_experiment_grid(as_planned, tmp_path, capsys):
    argv = ["gen1", "--scenes", "2", "--low-level", "as_planned", "sto", "--planner", "hlp"]
    argv += ["--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(command_main("experiments"), argv) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    (condition,) = summary["conditions"]
    assert [s["label"] for s in condition["series"]] == ["HLP", "hlp+as_planned"]
    assert summary["low_levels"] == ["as_planned", "sto"] and summary["initial"] == "hlp"
    rows = (tmp_path / "results.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * 2 and sum(",as_planned," in row for row in rows) == 2
    assert "| Gen I (6 objects) | hlp+as_planned | 2 |" in capsys.readouterr().out
