"""What a rollout reads of its world at a sample: ``Reading`` (for the cost), ``BodyPoses`` (for the
sleep checks), and ``contact_summary`` of the plant's contact results."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

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
