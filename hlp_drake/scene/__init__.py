"""The scene model: table, start, target and obstacles in the world frame (see ``hlp_drake.dataset.frames``)."""

from hlp_drake.runtime.exports import lazy_exports

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

# Imported on first use: a command's parser needs ``constants`` alone (no numpy, shapely or YAML).
__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "hlp_drake.scene.constants": ("DEFAULT_SCENE_FILE", "KINDS"),
        "hlp_drake.scene.generators": ("generate_scene",),
        "hlp_drake.scene.io": (
            "default_scene",
            "load_scene",
            "save_scene",
            "scene_from_dict",
            "scene_to_dict",
        ),
        "hlp_drake.scene.model": ("SHAPES", "Scene", "SceneObject", "Table"),
        "hlp_drake.scene.rows": ("Row", "find_rows"),
        "hlp_drake.scene.validation": ("scene_problems", "validate_scene"),
    },
)
