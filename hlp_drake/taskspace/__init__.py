"""The qualitative task-space model of the paper over any Scene (reference notes section 2)."""

from hlp_drake.taskspace.band import band_collision, band_collision_sampled, band_polygon, normal_of
from hlp_drake.taskspace.directions import DIRECTION_VECTORS, DIRECTIONS, direction_of
from hlp_drake.taskspace.model import ALPHA, Gap, TaskSpace, direction_blocks, free_fractions
from hlp_drake.taskspace.rect import Rect

__all__ = [
    "ALPHA",
    "DIRECTIONS",
    "DIRECTION_VECTORS",
    "Gap",
    "Rect",
    "TaskSpace",
    "band_collision",
    "band_collision_sampled",
    "band_polygon",
    "direction_blocks",
    "direction_of",
    "free_fractions",
    "normal_of",
]
