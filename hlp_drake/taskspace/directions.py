"""The eight direction classes around an object and the direction of a displacement.

F = forward (+x, away from the start), B = back (-x), L = left (+y), R = right (-y), as seen from
the start facing the target. The order FF, BB, LL, RR, FR, FL, BR, BL is the original code's.
"""

from __future__ import annotations

import math

DIRECTIONS = ("FF", "BB", "LL", "RR", "FR", "FL", "BR", "BL")
# Unit step (dx, dy) of each direction in the world frame.
DIRECTION_VECTORS = {
    "FF": (1, 0),
    "BB": (-1, 0),
    "LL": (0, 1),
    "RR": (0, -1),
    "FR": (1, -1),
    "FL": (1, 1),
    "BR": (-1, -1),
    "BL": (-1, 1),
}
_BY_SIGNS = {v: k for k, v in DIRECTION_VECTORS.items()}
# Counter-clockwise from +x (FF) in 45 degree steps: FF, FL, LL, BL, BB, BR, RR, FR.
_SECTORS = ("FF", "FL", "LL", "BL", "BB", "BR", "RR", "FR")


def _sign(value: float) -> int:
    return int(value > 0) - int(value < 0)


def direction_of(dx: float, dy: float, *, faithful: bool = False) -> str | None:
    """Direction class of the displacement (dx, dy); None for a zero displacement.

    Args:
        faithful: use the original code's exact sign test (any non-zero lateral change makes a
            diagonal, so continuous data is nearly always diagonal); otherwise the nearest of the
            eight directions by angle (45 degree sectors).
    """
    if dx == 0.0 and dy == 0.0:
        return None
    if faithful:
        return _BY_SIGNS[(_sign(dx), _sign(dy))]
    sector = math.floor(math.atan2(dy, dx) / (math.pi / 4.0) + 0.5) % 8
    return _SECTORS[sector]


def mirror_direction(name: str | None) -> str | None:
    """The direction seen in a mirror along the forward axis (left and right swapped)."""
    if name is None:
        return None
    dx, dy = DIRECTION_VECTORS[name]
    return _BY_SIGNS[(dx, -dy)]
