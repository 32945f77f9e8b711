"""``RolloutPool``: STO rollouts on one or several worker processes.

Each worker process keeps pre-built ``SceneRollouts`` (one per scene and configuration, the latest
few, each with its full and reduced ``RolloutWorld``s), so a rollout only swaps a trajectory and
resets a context. With one worker the rollouts run in this process. The results are the same in both
cases: a rollout is a pure function of the scene, the configuration and the sequence.
"""

from __future__ import annotations

import hashlib
import multiprocessing
import time
from collections import OrderedDict
from concurrent.futures import ProcessPoolExecutor
from typing import Self

from hlp_drake.scene.model import Scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.world_config import WorldConfig, dump_world_config, load_world_config

_WORLDS_KEPT = 2
_worlds: OrderedDict = OrderedDict()  # per process: key -> SceneRollouts


def _world_key(scene: Scene, config_yaml: str) -> str:
    return hashlib.sha256(repr(scene).encode() + config_yaml.encode()).hexdigest()


def _world(scene: Scene, config_yaml: str, config: WorldConfig | None = None):
    """This process's ``SceneRollouts`` for ``scene`` and the configuration (built on first use)."""
    from hlp_drake.systems.rollout import SceneRollouts

    key = _world_key(scene, config_yaml)
    if key not in _worlds:
        _worlds[key] = SceneRollouts(scene, config if config is not None else load_world_config(overrides=config_yaml))
        while len(_worlds) > _WORLDS_KEPT:
            _worlds.popitem(last=False)
    _worlds.move_to_end(key)
    return _worlds[key]


def forget_worlds() -> None:
    """Drop this process's pre-built rollout worlds (so the next optimisation builds its own, as a
    first run would: comparisons must not hand one planner the worlds another one built)."""
    _worlds.clear()


def _rollout_task(scene: Scene, config_yaml: str, times, knots):
    return _world(scene, config_yaml).rollout(ControlSequence(times, knots))


def _warm_up(delay: float) -> int:
    import hlp_drake.systems.rollout  # noqa: F401  (imports Drake once per worker)

    time.sleep(delay)
    return multiprocessing.current_process().pid


class RolloutPool:
    """Rolls out control sequences on ``workers`` processes (1: in this process).

    Use as a context manager, or call ``close()``; one pool can serve many scenes in turn.
    """

    def __init__(self, workers: int = 1) -> None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.workers = int(workers)
        self.startup_s = 0.0
        self._executor: ProcessPoolExecutor | None = None
        if self.workers > 1:
            started = time.perf_counter()
            self._executor = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("spawn"))
            # Start every worker (and import Drake there) now, not inside the first optimisation.
            list(self._executor.map(_warm_up, [0.2] * self.workers))
            self.startup_s = time.perf_counter() - started

    def world(self, scene: Scene, config: WorldConfig):
        """This process's pre-built ``SceneRollouts`` for ``scene`` (for start checks and in-process rollouts)."""
        return _world(scene, dump_world_config(config), config)

    def rollouts(self, scene: Scene, config: WorldConfig, sequences: list[ControlSequence]) -> list:
        """The ``RolloutOutcome`` of every sequence, in order."""
        config_yaml = dump_world_config(config)
        if self._executor is None:
            world = _world(scene, config_yaml, config)
            return [world.rollout(sequence) for sequence in sequences]
        futures = [self._executor.submit(_rollout_task, scene, config_yaml, s.times, s.knots) for s in sequences]
        return [future.result() for future in futures]

    def close(self) -> None:
        if self._executor is not None:
            self._executor.shutdown(cancel_futures=True)
            self._executor = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
