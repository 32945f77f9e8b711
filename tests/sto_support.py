"""Fixtures of the optimiser's tests: the default scene, both planners' initial trajectories on it,
a rollout world, and helpers for scenarios and short sequences."""

from __future__ import annotations

import numpy as np
import pytest

from hlp_drake.commands.run_scene import DEFAULT_SCENE
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.scenario import Scenario


def on(scene, data: str | None = None) -> Scenario:
    """The default scenario on ``scene``, with the YAML settings ``data`` laid over it."""
    scenario = Scenario(scene=scene)
    return scenario if data is None else scenario.updated(data)


@pytest.fixture(scope="module")
def scene():
    return load_scene(DEFAULT_SCENE)


@pytest.fixture(scope="module")
def trajectories(scene):
    """The initial (IK) trajectories of both planners on the default scene."""
    result = {}
    for planner in ("hlp", "sto"):
        diagram = make_planning_diagram(on(scene, f"planner: {{kind: {planner}}}"))
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort("scene").FixValue(context, scene)
        result[planner] = diagram.GetOutputPort("trajectory").Eval(context)
    return result


@pytest.fixture(scope="module")
def world(scene):
    return RolloutWorld(on(scene))


def short(sequence: ControlSequence, horizon: float) -> ControlSequence:
    """The first ``horizon`` seconds of ``sequence``, in 4 steps."""
    trajectory = sequence.to_trajectory()
    times = np.linspace(0.0, horizon, 5)
    return ControlSequence(times, np.column_stack([trajectory.value(t) for t in times]).T)
