"""The scene model: table, start, target and obstacles in the world frame (see ``hlp_drake.frames``)."""

from hlp_drake.scene.generators import KINDS, generate_scene
from hlp_drake.scene.io import (
    DEFAULT_SCENE_FILE,
    default_scene,
    load_scene,
    save_scene,
    scene_from_dict,
    scene_to_dict,
)
from hlp_drake.scene.model import SHAPES, Scene, SceneObject, Table
from hlp_drake.scene.rows import Row, find_rows
from hlp_drake.scene.validation import scene_problems, validate_scene

__all__ = [
    "DEFAULT_SCENE_FILE",
    "KINDS",
    "SHAPES",
    "Row",
    "Scene",
    "SceneObject",
    "Table",
    "default_scene",
    "find_rows",
    "generate_scene",
    "load_scene",
    "save_scene",
    "scene_from_dict",
    "scene_problems",
    "scene_to_dict",
    "validate_scene",
]
