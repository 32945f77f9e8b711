"""Scene files: YAML or JSON, chosen by the file extension. Loading validates; saving is atomic.

The format is the ``Scene`` dataclass itself, read by ``hlp_drake.config.typed_yaml`` the same way a scenario
file's ``scene:`` is read.
"""

from __future__ import annotations

import functools
import json
import os
from pathlib import Path
from typing import Any

import yaml

from hlp_drake.config.typed_yaml import load_typed
from hlp_drake.errors import SceneError
from hlp_drake.files.atomic import is_stdout, write_text_atomic
from hlp_drake.files.documents import parse_json, parse_yaml, read_document
from hlp_drake.scene.constants import DEFAULT_SCENE_FILE
from hlp_drake.scene.model import Scene, SceneObject
from hlp_drake.scene.validation import MAX_OBSTACLES, scene_problems, validate_scene

YAML_SUFFIXES = (".yaml", ".yml")
JSON_SUFFIXES = (".json",)


def _object_to_dict(obj: SceneObject) -> dict[str, Any]:
    return {
        "name": obj.name,
        "shape": obj.shape,
        "x": float(obj.x),
        "y": float(obj.y),
        "yaw": float(obj.yaw),
        "size": [float(v) for v in obj.size],
    }


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """Plain-data form of ``scene`` (what YAML and JSON files hold)."""
    return {
        "name": scene.name,
        "table": {
            "length": float(scene.table.length),
            "width": float(scene.table.width),
            "height": float(scene.table.height),
        },
        "start": [float(v) for v in scene.start],
        "start_yaw": float(scene.start_yaw),
        "target": _object_to_dict(scene.target),
        "obstacles": [_object_to_dict(obj) for obj in scene.obstacles],
    }


def scene_from_dict(data: Any, *, where: str = "") -> Scene:
    """Read and validate a Scene from parsed YAML or JSON (``Scene`` is the schema; see
    ``hlp_drake.config.typed_yaml``).

    Raises:
        SceneError: every problem on its own line, located (``obstacles[0].x: expected a number``)
            and prefixed with ``where`` when given.
    """
    prefix = f"{where}: " if where else ""
    obstacles = data.get("obstacles") if isinstance(data, dict) else None
    if isinstance(obstacles, list) and len(obstacles) > MAX_OBSTACLES:
        raise SceneError(f"{prefix}scene.obstacles: more than {MAX_OBSTACLES} obstacles ({len(obstacles)})")
    scene = load_typed(Scene, data, where=where, top="scene", error=SceneError)
    problems = scene_problems(scene)
    if problems:
        raise SceneError(*(prefix + p for p in problems))
    return scene


def _suffix(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in YAML_SUFFIXES + JSON_SUFFIXES:
        raise SceneError(f"{path}: unknown scene file type {path.suffix!r} (use .yaml, .yml or .json)")
    return suffix


def scene_to_text(scene: Scene, *, json_format: bool = False) -> str:
    data = scene_to_dict(scene)
    if json_format:
        return json.dumps(data, indent=2) + "\n"
    return yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=100)


def load_scene(path: str | os.PathLike[str]) -> Scene:
    """Read and validate a scene file (.yaml, .yml or .json).

    Raises:
        SceneError: the file is missing, unreadable, too large, not YAML/JSON (or breaks the
            limits of ``hlp_drake.files.documents``), or describes an invalid scene; every message starts
            with the file's path.
    """
    path = Path(path)
    suffix = _suffix(path)
    text = read_document(path, SceneError)
    parse = parse_json if suffix in JSON_SUFFIXES else parse_yaml
    data = parse(text, str(path), SceneError)
    if data is None:  # YAML of nothing but blanks and comments
        raise SceneError(f"{path}: the file is empty; a scene gives its table, start, target and obstacles")
    return scene_from_dict(data, where=str(path))


def save_scene(scene: Scene, path: str | os.PathLike[str]) -> None:
    """Validate ``scene`` and write it atomically as YAML or JSON (by extension; ``-``: YAML on
    standard output)."""
    path = Path(path)
    suffix = YAML_SUFFIXES[0] if is_stdout(path) else _suffix(path)
    validate_scene(scene)
    write_text_atomic(path, scene_to_text(scene, json_format=suffix in JSON_SUFFIXES))


@functools.cache
def default_scene() -> Scene:
    """The bundled default scene (``DEFAULT_SCENE_FILE``), read once."""
    return load_scene(DEFAULT_SCENE_FILE)
