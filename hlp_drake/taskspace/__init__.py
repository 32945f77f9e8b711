"""The qualitative task-space model of the paper over any Scene (reference notes section 2)."""

from hlp_drake.taskspace.band import band_collision, band_collision_sampled, band_polygon, normal_of
from hlp_drake.taskspace.directions import DIRECTION_VECTORS, DIRECTIONS, direction_of, mirror_direction
from hlp_drake.taskspace.model import (
    ALPHA,
    Gap,
    Node,
    TaskSpace,
    block_array,
    direction_blocks,
    free_fractions,
    overlap_areas,
    rect_array,
    rect_centres,
)
from hlp_drake.taskspace.rect import Rect

__all__ = [
    "ALPHA",
    "DIRECTIONS",
    "DIRECTION_VECTORS",
    "Gap",
    "Node",
    "Rect",
    "TaskSpace",
    "band_collision",
    "band_collision_sampled",
    "band_polygon",
    "block_array",
    "direction_blocks",
    "direction_of",
    "free_fractions",
    "mirror_direction",
    "normal_of",
    "overlap_areas",
    "rect_array",
    "rect_centres",
]
