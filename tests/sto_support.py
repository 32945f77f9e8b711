"""Fixtures of the optimiser's tests: the default scene, both initialisers' trajectories on it, a
rollout world, and helpers for scenarios, rollout specs and short sequences."""

from __future__ import annotations

import numpy as np
import pytest

from hlp_drake.commands.run_scene import DEFAULT_SCENE
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.scenario import Scenario


def on(scene, data: str | None = None) -> Scenario:
    """The default scenario on ``scene``, with the YAML settings ``data`` laid over it."""
    scenario = Scenario(scene=scene)
    return scenario if data is None else scenario.updated(data)


def spec(scenario: Scenario) -> RolloutSpec:
    """What the STO of ``scenario`` rolls out: its scene, world model, STO settings and success test."""
    return RolloutSpec.of(scenario)


def sto(scene, settings: str = "") -> RolloutSpec:
    """``spec`` of the default scenario on ``scene`` with the STO's ``settings`` (YAML flow mapping
    items, e.g. ``"samples: 2"``)."""
    return spec(on(scene, f"planner: {{low_level: {{{settings}}}}}"))


@pytest.fixture(scope="module")
def scene():
    return load_scene(DEFAULT_SCENE)


@pytest.fixture(scope="module")
def trajectories(scene):
    """The initial (IK) trajectories of both initialisers on the default scene, by name."""
    result = {}
    for initial in ("hlp", "line"):
        diagram = make_planning_diagram(on(scene, f"planner: {{initial: {initial}}}"))
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort("scene").FixValue(context, scene)
        result[initial] = diagram.GetOutputPort("trajectory").Eval(context)
    return result


@pytest.fixture(scope="module")
def world(scene):
    return RolloutWorld(spec(on(scene)))


def short(sequence: ControlSequence, horizon: float) -> ControlSequence:
    """The first ``horizon`` seconds of ``sequence``, in 4 steps."""
    trajectory = sequence.to_trajectory()
    times = np.linspace(0.0, horizon, 5)
    return ControlSequence(times, np.column_stack([trajectory.value(t) for t in times]).T)
