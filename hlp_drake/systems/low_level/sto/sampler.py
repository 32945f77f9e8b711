"""``sample_rollout``: a rollout read every sample period, its objects put to sleep and woken as it goes.

An object asleep has its floating joint locked (``RolloutWorld.set_asleep``): it stays put and adds
no degrees of freedom to the contact problem, which is where most of a rollout's time goes
(resting objects' table contacts). At every sample the rollout

* wakes, from the previous sample on, every sleeping object that the robot or an awake object that
  has moved came within ``planner.low_level.weld_margin`` (plus the largest motion of a body since the
  previous sample) of: until then nothing can have touched it, so it would have stayed at rest
  anyway;
* wakes the objects the commanded motion comes within ``planner.low_level.weld_clearance`` of in the next
  ``planner.low_level.weld_lookahead`` s (``SleepSchedule``);
* puts back to sleep the awake objects that have come to rest (slower than ``planner.low_level.sleep_speed``
  at this sample and the previous one), with neither the robot nor a moving object within
  ``planner.low_level.weld_clearance`` (SceneGraph's distances), nor an object that stays awake within
  twice the margin (resting objects in contact sleep together), and the commanded motion not
  about to come near: e.g. an obstacle pushed aside and left there once the robot has gone.

A rollout's outcome is a pure function of the scene, the configuration, the start and the sequence.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.low_level.sto.cost import RolloutSamples

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.outcome import RolloutStart
    from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
    from hlp_drake.systems.low_level.sto.sleep import SleepSchedule


MOVED = 1.0e-3
"""An awake object whose geometry has moved more than this from its start (m) is watched near sleeping ones."""
ANGULAR_REST = 0.05
"""An object turning slower than this (rad/s) may count as at rest."""


class _ClosePairs:
    """``world.close_pairs`` at one sample, queried once at ``reach`` and filtered for any threshold
    up to it (a larger one queries again): the wake and the sleep checks share one query."""

    def __init__(self, world: RolloutWorld, reach: float) -> None:
        self._world, self._reach, self._pairs = world, reach, None

    def within(self, threshold: float) -> list[tuple[int, int, float]]:
        if threshold > self._reach:
            return self._world.close_pairs(threshold)
        if self._pairs is None:
            self._pairs = self._world.close_pairs(self._reach)
        return [pair for pair in self._pairs if pair[2] <= threshold]


def _near_asleep(
    world: RolloutWorld,
    pairs: _ClosePairs,
    poses: BodyPoses,
    motion: np.ndarray,
    start: BodyPoses,
    asleep: frozenset[str],
) -> frozenset[str]:
    """The sleeping objects within the margin (see the module's docstring) of the robot or of an
    awake object that has moved since ``start`` (the poses now; ``motion``: every watched body's
    since the previous sample)."""
    names = world.object_names
    moved = world.motion_bounds(poses, start) > MOVED
    moved[: world.num_robot_bodies] = True  # the robot always counts
    for i, name in enumerate(names):
        if name in asleep:
            moved[world.num_robot_bodies + i] = False
    step = float(np.max(motion[moved], initial=0.0))
    watchers = {name for name, m in zip(names, moved[world.num_robot_bodies :]) if m}
    near = set()
    for a, b, _ in pairs.within(world.spec.sto.weld_margin + step):
        for sleeper, other in ((a, b), (b, a)):
            name, other_name = world.object_name(sleeper), world.object_name(other)
            if name in asleep and (other in world.robot_bodies or other_name in watchers):
                near.add(name)
    return frozenset(near)


def _sleepers(
    world: RolloutWorld,
    pairs: _ClosePairs,
    motion: np.ndarray,
    asleep: frozenset[str],
    keep_awake: frozenset[str],
    sto: StoConfig,
) -> frozenset[str]:
    """The awake objects that may go to sleep now (see the module's docstring): at rest, with
    neither the robot nor a moving object within ``weld_clearance`` and no object staying awake
    within twice ``weld_margin`` (resting objects touching each other go to sleep together)."""
    names = world.object_names
    speed, turn = world.object_speeds()
    step = motion[world.num_robot_bodies :]
    resting = (speed < sto.sleep_speed) & (turn < ANGULAR_REST) & (step < sto.sleep_speed * sto.sample_period)
    index = {name: i for i, name in enumerate(names)}
    chosen = {n for i, n in enumerate(names) if resting[i] and n not in asleep and n not in keep_awake}
    if not chosen:
        return frozenset()
    touching: dict[str, set[str]] = {n: set() for n in chosen}
    for a, b, distance in pairs.within(sto.weld_clearance):
        for body, other in ((a, b), (b, a)):
            name, other_name = world.object_name(body), world.object_name(other)
            if name not in touching:
                continue
            if other in world.robot_bodies or (
                other_name is not None and other_name not in asleep and not resting[index[other_name]]
            ):
                chosen.discard(name)  # the robot or a moving object is near
            elif other_name is not None and other_name not in asleep and distance < 2.0 * sto.weld_margin:
                touching[name].add(other_name)
    changed = True
    while changed:  # an object touching one that stays awake stays awake too
        awake_touched = {n for n in chosen if touching[n] - chosen}
        chosen -= awake_touched
        changed = bool(awake_touched)
    return frozenset(chosen)


def sample_rollout(
    sequence: ControlSequence,
    sto: StoConfig,
    world: RolloutWorld,
    schedule: SleepSchedule,
    *,
    settle_s: float,
    start: RolloutStart | None = None,
) -> RolloutSamples:
    """Roll ``sequence`` out on ``world`` and read the state every ``sto.sample_period``, its objects
    asleep and awake as ``schedule`` and the checks of the module's docstring say, until ``settle_s``
    after its end.

    Args:
        start: the state to start from (default: the scene's, the robot at its start configuration);
            objects moving in it start awake.
    """
    end = sequence.duration + settle_s
    count = max(1, math.ceil(end / sto.sample_period - 1e-9))
    times = np.minimum(sto.sample_period * np.arange(count + 1), end)
    initial = None if start is None else start.states
    world.begin(sequence, states=initial)
    speed, turn = world.object_speeds()
    moving = {
        b.name() for b, v, w in zip(world.objects, speed, turn) if v >= sto.sleep_speed or w >= ANGULAR_REST
    }
    asleep = schedule.initially_asleep() - moving
    world.set_asleep(frozenset(), asleep)
    first = previous = world.watched_poses()
    saved = (0.0, world.states())  # the time and the states at the last sample read
    woken: set[str] = set()
    readings: list[list] = []
    problem, switches = None, 0
    k = 0
    while k < len(times):
        t = times[k]
        if t > world.time():
            problem = world.advance_to(t)
            if problem is not None:
                break
        poses = world.watched_poses()
        pairs = _ClosePairs(world, sto.weld_clearance)
        motion = world.motion_bounds(poses, previous)
        near = _near_asleep(world, pairs, poses, motion, first, asleep) if asleep else frozenset()
        if near:  # back to the previous sample (or the start) with those objects awake
            asleep, switches = asleep - near, switches + 1
            world.begin(sequence, time=saved[0], states=saved[1], asleep=asleep)
            continue
        reading = world.read()
        readings.append(reading)
        if reading.problem is not None:
            problem = f"{reading.problem} at t = {t:.2f} s"
            break
        due = schedule.due(t) - woken
        woken |= due
        sleepers = (
            _sleepers(world, pairs, motion, asleep, schedule.approaching(t), sto)
            if schedule.sleeping
            else frozenset()
        )
        after = (asleep - due) | sleepers
        if after != asleep:
            world.set_asleep(asleep, after)
            asleep, switches = after, switches + 1
        previous, saved = poses, (float(t), world.states())
        k += 1
    positions, tcps, forces, contacts, _ = zip(*readings) if readings else ([], [], [], [], [])
    return RolloutSamples(
        times[: len(readings)],
        np.array(positions),
        np.array(tcps),
        np.array(forces),
        np.array(contacts, dtype=bool),
        problem,
        asleep=tuple(sorted(asleep)),
        switches=switches,
    )


# What a rollout reads of its world at a sample: ``Reading`` (for the cost), ``BodyPoses`` (for the
# sleep checks), and ``contact_summary`` of the plant's contact results.
ROBOT, OBJECT, TABLE, OTHER = range(4)
"""Kinds of body (the world's own body is ``OTHER``), in this order."""


def contact_summary(results, body_kind: np.ndarray) -> tuple[float, bool]:
    """The largest point-contact force on an object in ``results`` (``ContactResults``; N) and
    whether the robot touches the table, ``body_kind`` giving each body index's kind."""
    contacts = [results.point_pair_contact_info(i) for i in range(results.num_point_pair_contacts())]
    if not contacts:
        return 0.0, False
    kinds = body_kind[[(int(c.bodyA_index()), int(c.bodyB_index())) for c in contacts]]
    on_object = np.flatnonzero((kinds == OBJECT).any(axis=1))
    forces = np.array([contacts[i].contact_force() for i in on_object]).reshape(-1, 3)
    table_contact = bool(np.any(np.all(np.sort(kinds, axis=1) == (ROBOT, TABLE), axis=1)))
    return float(np.max(np.linalg.norm(forces, axis=1), initial=0.0)), table_contact


def _rotation_angles(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """(n,) angles of the rotations taking each of the (n, 3, 3) ``R_a`` to ``R_b``."""
    cosine = (np.einsum("nij,nij->n", R_a, R_b) - 1.0) / 2.0
    return np.arccos(np.clip(cosine, -1.0, 1.0))


@dataclass(frozen=True)
class BodyPoses:
    """World poses of some bodies: (n, 3) origins and (n, 3, 3) rotations."""

    p: np.ndarray
    R: np.ndarray

    def motion(self, other: BodyPoses, radii: np.ndarray) -> np.ndarray:
        """(n,) bound on how far a point of each body's geometry is from where it was in ``other``
        (origin shift plus the turn times the geometry's radius about the origin)."""
        return np.linalg.norm(self.p - other.p, axis=1) + _rotation_angles(other.R, self.R) * radii


class Reading(NamedTuple):
    """The state of a rollout read at one sample."""

    positions: np.ndarray
    """(m, 3) object centres (the target first)."""
    tcp: np.ndarray
    """(3,) the tcp's position."""
    max_force: float
    """The largest contact force on an object, N."""
    table_contact: bool
    """Whether the robot touches the table."""
    problem: str | None
    """Why the simulation is not to be trusted (None if it is sane)."""
