"""``sample_rollout``: a rollout read every sample period, moving on to worlds with fewer objects welded.

At every sample the rollout also checks that neither the robot nor an object that has moved came
within ``optimiser.weld_margin`` (plus the largest motion of a body since the previous sample) of a
welded object; if one did, it goes back to the previous sample and on with it freed. Each welded
set is a world of its own, built once; moving on carries the robot's and the free objects' states over.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Protocol

import numpy as np

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.optimiser_config import StoConfig
from hlp_drake.systems.rollout_cost import RolloutSamples

if TYPE_CHECKING:
    from hlp_drake.systems.rollout_world import RolloutWorld


class WorldSet(Protocol):
    """Worlds of one scene by the objects welded in them."""

    def world_with(self, welded: frozenset[str]) -> RolloutWorld | None: ...


class Schedule(Protocol):
    """The objects to keep welded from a time on."""

    def welded_at(self, t: float) -> frozenset[str]: ...


def sample_rollout(
    sequence: ControlSequence, sto: StoConfig, worlds: WorldSet, schedule: Schedule
) -> RolloutSamples:
    """Roll ``sequence`` out and read the state every ``sto.sample_period``, on worlds of one scene
    with fewer and fewer objects welded.

    Args:
        worlds: ``worlds.world_with(welded)`` is the ``RolloutWorld`` with the objects ``welded``
            welded, or None if there is none (the samples then stop where it would be needed).
        schedule: ``schedule.welded_at(t)`` are the objects to keep welded from sample time ``t`` on
            (at most those welded before: an object once free stays free).

    At every sample the rollout moves on to a world with fewer objects welded (carrying over the
    robot's and the free objects' states) when ``welded_at`` frees some, and goes back to the
    previous sample and on with them freed when the robot or an object that has moved came near a
    welded object (``RolloutWorld.near_welded``): until then nothing can have touched it, so in the
    full model it would have stayed at rest, as it does welded.
    """
    end = sequence.duration + sto.settle_s
    count = max(1, math.ceil(end / sto.sample_period - 1e-9))
    times = np.minimum(sto.sample_period * np.arange(count + 1), end)
    welded = frozenset(schedule.welded_at(0.0))
    world = worlds.world_with(welded)
    world.begin(sequence)
    start = previous = world.watched_poses()
    readings: list[list] = []
    problem, touched, switches = None, (), 0
    saved: tuple[float, dict] | None = None  # the time and the states at the last sample read
    k = 0
    while k < len(times):
        t = times[k]
        if t > world.time():
            problem = world.advance_to(t)
            if problem is not None:
                break
        poses = world.watched_poses() if welded else previous  # nothing to watch for once all are free
        near = world.near_welded(poses, previous, start)
        if near:  # back to the previous sample (or the start) with those objects freed
            freed, at = frozenset(near), saved
        else:
            reading = world.read()
            readings.append(reading)
            if reading.problem is not None:
                problem = f"{reading.problem} at t = {t:.2f} s"
                break
            previous, saved = poses, (float(t), world.states()) if welded else None
            freed, at = welded - frozenset(schedule.welded_at(t)), saved
            k += 1
        if freed:
            successor = worlds.world_with(welded - freed)
            if successor is None:
                touched = tuple(sorted(freed))
                break
            world, welded, switches = successor, welded - freed, switches + 1
            if at is None:
                world.begin(sequence)
            else:
                world.begin(sequence, time=at[0], states=at[1])
    positions, tcps, forces, contacts, _ = zip(*readings) if readings else ([], [], [], [], [])
    return RolloutSamples(
        times[: len(readings)],
        np.array(positions),
        np.array(tcps),
        np.array(forces),
        np.array(contacts, dtype=bool),
        problem,
        touched,
        welded=tuple(sorted(welded)),
        switches=switches,
    )
