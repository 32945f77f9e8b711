"""The planar human arm of the planner (reference 5.4) and the collision of its motion with obstacles."""

from __future__ import annotations

import numpy as np

from hlp_drake.features.plane import paper_angle
from hlp_drake.taskspace.band import band_coverage_sampled, convex_rect_overlap


def arm_joints(hand: np.ndarray, q: np.ndarray, upper_arm: float, forearm: float) -> np.ndarray:
    """Joint positions (..., 4, 2): neck, shoulder, elbow, hand, anchored at the hand.

    A right arm seen from above: the forearm runs back and to the right of the hand, the upper arm
    back from the elbow, and the neck lies beside the shoulder on the body-centre (+y) side.
    """
    hand = np.asarray(hand, float)
    q1, q2 = q[..., 0], q[..., 1]
    phi = q1 + q2 - np.pi
    elbow = hand + forearm * np.stack([-np.sin(phi), -np.cos(phi)], axis=-1)
    shoulder = elbow + upper_arm * np.stack([-np.sin(q1), -np.cos(q1)], axis=-1)
    neck = shoulder + np.stack([np.zeros_like(q1), np.full_like(q1, upper_arm)], axis=-1)
    return np.stack([neck, shoulder, elbow, hand], axis=-2)


def _is_convex(quad: np.ndarray) -> np.ndarray:
    """Whether quadrilaterals (..., 4, 2) are convex (or degenerate): no two turns of opposite sense."""
    following = np.roll(np.arange(4), -1)
    edge = quad[..., following, :] - quad
    nxt = edge[..., following, :]
    turn = edge[..., 0] * nxt[..., 1] - edge[..., 1] * nxt[..., 0]
    return np.all(turn >= 0.0, axis=-1) | np.all(turn <= 0.0, axis=-1)


def _inflate(rects: np.ndarray, margin: float) -> np.ndarray:
    return rects + np.array([-margin, -margin, margin, margin])


def sweep_collision(
    before: np.ndarray,
    after: np.ndarray,
    occluders: np.ndarray,
    mask: np.ndarray,
    *,
    band: float,
    faithful: bool,
) -> np.ndarray:
    """Collision of the three links moving from ``before`` to ``after`` joints, per motion.

    Args:
        before, after: (n, 4, 2) joints per motion.
        occluders: (m, 4) rectangles; ``mask`` (n, m) says which count for each motion.
        band: half-width of a link's band.
        faithful: the original's measure (each link's band at the start pose, stretched along the
            smaller of its two joints' motion angles, sampled); otherwise the exact area the links
            sweep (two triangles per link, each occluder inflated by ``band``).

    Returns:
        (n,) sum over the links of the mean covered fraction of the counted occluders.
    """
    n = len(before)
    if n == 0 or len(occluders) == 0:
        return np.zeros(n)
    counted = np.maximum(mask.sum(axis=1), 1)
    if not faithful:
        # A link sweeps the quadrilateral of its two poses: as one polygon where it is convex, else
        # as two triangles (the second polygon of a convex sweep is a point); all in one batch.
        inflated = _inflate(occluders, band)
        areas = (inflated[:, 2] - inflated[:, 0]) * (inflated[:, 3] - inflated[:, 1])
        a0, b0, a1, b1 = before[:, :3], before[:, 1:], after[:, :3], after[:, 1:]  # (n, 3, 2) per link
        quad = np.stack([a0, b0, b1, a1], axis=2)
        convex = _is_convex(quad)[..., None, None]
        first = np.where(convex, quad, np.stack([a0, b0, b1, b1], axis=2))
        second = np.where(convex, a0[:, :, None], np.stack([a0, b1, a1, a1], axis=2))
        polygons = np.concatenate([first, second], axis=1).reshape(-1, 4, 2)  # (n * 6, 4, 2)
        cover = convex_rect_overlap(polygons, inflated).reshape(n, 2, 3, -1).sum(axis=1) / areas
        cover = np.minimum(cover, 1.0)  # (n, 3 links, m)
        return (np.where(mask[:, None, :], cover, 0.0).sum(axis=2) / counted[:, None]).sum(axis=1)
    total = np.zeros(n)
    for link in range(3):
        a0, b0, a1, b1 = before[:, link], before[:, link + 1], after[:, link], after[:, link + 1]
        da, db = a1 - a0, b1 - b0
        phi = np.minimum(paper_angle(da), paper_angle(db))
        offsets = np.column_stack([np.sin(phi), -np.cos(phi)])  # the original's (cos, sin) in its frame
        reach = np.maximum(np.linalg.norm(da, axis=1), np.linalg.norm(db, axis=1))
        cover = np.stack(
            [
                band_coverage_sampled(a0[i], b0[i], offsets[i], band, band + reach[i], occluders)[0]
                for i in range(n)
            ]
        )
        total += np.where(mask, cover, 0.0).sum(axis=1) / counted
    return total
