"""Faults of the rollout pool, injected: a worker killed between batches, workers dying again and
again, and ``run_scene`` with a worker killed mid-optimisation. The run survives with the same
result, or its optimisation ends as a failure, with one warning line a death."""

from __future__ import annotations

import json
import os
import re
import signal

import numpy as np
import pytest
from fault_support import fault_markers, rollout_exiting, rollout_killing_its_worker_once, warnings
from sto_support import on, short, spec

from hlp_drake.commands.parsing import run_cli
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto import pool as pool_module
from hlp_drake.systems.low_level.sto.optimiser import optimise, sample_base_noise
from hlp_drake.systems.low_level.sto.pool import MAX_DEATHS, RolloutPool

WARNING = re.compile(
    r"warning: a rollout worker died \((signal \d+|exit status \d+)\); restarted the workers"
)

faults = pytest.fixture(fault_markers, name="faults")


def comparable(outcome) -> tuple:
    """A rollout's outcome without its wall-clock time."""
    return (
        outcome.cost,
        outcome.terms,
        outcome.success,
        outcome.failure_reason,
        outcome.target_distance,
        outcome.fallen,
        outcome.simulated_s,
        outcome.asleep,
        outcome.switches,
    )


def test_a_killed_rollout_worker_is_replaced_and_its_rollouts_run_again(scene, trajectories, capsys):
    base = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    config = on(scene)
    noise = sample_base_noise(np.random.default_rng(0), base, config.low_level.noise, 3)
    sequences = [base.with_base_velocity(v) for v in noise]
    with RolloutPool(2) as pool:
        undisturbed = pool.rollouts(spec(config), sequences)
        assert warnings(capsys.readouterr().err) == []
        victim = next(iter(pool._executor._processes.values()))
        os.kill(victim.pid, signal.SIGKILL)  # as the out-of-memory killer would
        disturbed = pool.rollouts(spec(config), sequences)
        again = pool.rollouts(spec(config), sequences)  # the replaced workers go on serving
    assert [comparable(o) for o in disturbed] == [comparable(o) for o in undisturbed]
    assert [comparable(o) for o in again] == [comparable(o) for o in undisturbed]
    (line,) = warnings(capsys.readouterr().err)
    assert WARNING.match(line) and "(signal 9)" in line, line


def test_workers_dying_again_and_again_end_the_optimisation_as_a_failure(
    scene, trajectories, capsys, monkeypatch
):
    monkeypatch.setattr(pool_module, "_rollout_task", rollout_exiting)
    config = on(scene, "planner: {low_level: {samples: 2, max_iterations: 3}}")
    initial = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)  # fails: too short
    with RolloutPool(2) as pool:
        result = optimise(
            spec(config), initial, pool
        )  # the initial rollout here, the iterations' on the workers
        with pytest.raises(pool_module.WorkersLost):  # the pool stays given up
            pool.rollouts(spec(config), [initial, initial])
    assert not result.success and result.iterations == 0 and result.rollouts == 1
    assert result.failure_reason == f"the rollout workers died {MAX_DEATHS} times in a row (exit status 3)"
    lines = warnings(capsys.readouterr().err)
    assert len(lines) == MAX_DEATHS - 1 and all(WARNING.match(line) for line in lines), lines
    assert all("(exit status 3)" in line for line in lines)


def run_scene_json(tmp_path, name: str, capsys) -> tuple[int, dict, str]:
    """``run_scene --planner sto`` on 2 workers, in this process: its exit status, JSON and stderr."""
    from hlp_drake.commands.run_scene import main

    out = tmp_path / f"{name}.json"
    status = run_cli(main, ["--planner", "sto", "--workers", "2", "--quiet", "--json", str(out)])
    return status, json.loads(out.read_text()), capsys.readouterr().err


def without_times(report: dict) -> dict:
    """A run's JSON without its wall-clock times."""
    report = {**report, "timings": None}
    report["optimisation"] = {k: v for k, v in report["optimisation"].items() if not k.endswith("_s")}
    return report


def test_run_scene_with_a_rollout_worker_killed_mid_optimisation_gives_the_same_result(
    tmp_path, capsys, monkeypatch, faults
):
    status, undisturbed, err = run_scene_json(tmp_path, "undisturbed", capsys)
    assert status == 0 and undisturbed["iterations"] >= 1 and warnings(err) == []
    monkeypatch.setattr(pool_module, "_rollout_task", rollout_killing_its_worker_once)
    status, disturbed, err = run_scene_json(tmp_path, "disturbed", capsys)
    assert (faults / "rollout").exists()  # a worker did die
    assert status == 0 and "Traceback" not in err
    (line,) = warnings(err)
    assert WARNING.match(line) and "(signal 9)" in line, line
    assert without_times(disturbed) == without_times(undisturbed)
