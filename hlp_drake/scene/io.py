"""Scene files: YAML or JSON, chosen by the file extension. Loading validates; saving is atomic."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import yaml

from hlp_drake.atomic import write_text_atomic
from hlp_drake.errors import SceneError
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.scene.validation import validate_scene

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


class _Reader:
    """Reads typed fields out of nested plain data, naming the field in every error."""

    def __init__(self) -> None:
        self.problems: list[str] = []

    def mapping(self, value: Any, where: str, required: set[str], optional: set[str]) -> dict | None:
        if not isinstance(value, dict):
            self.problems.append(f"{where}: expected a mapping, got {type(value).__name__}")
            return None
        for key in sorted(set(value) - required - optional, key=str):
            self.problems.append(f"{where}: unknown field {key!r}")
        for key in sorted(required - set(value)):
            self.problems.append(f"{where}: missing field {key!r}")
        return value

    def number(self, value: Any, where: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.problems.append(f"{where}: expected a number, got {value!r}")
            return float("nan")
        return float(value)

    def numbers(self, value: Any, where: str, count: int) -> tuple[float, ...]:
        if not isinstance(value, (list, tuple)) or len(value) != count:
            self.problems.append(f"{where}: expected a list of {count} numbers, got {value!r}")
            return (float("nan"),) * count
        return tuple(self.number(v, f"{where}[{i}]") for i, v in enumerate(value))

    def text(self, value: Any, where: str) -> str:
        if not isinstance(value, str):
            self.problems.append(f"{where}: expected text, got {value!r}")
            return ""
        return value

    def scene_object(self, value: Any, where: str) -> SceneObject | None:
        data = self.mapping(value, where, {"name", "shape", "x", "y", "size"}, {"yaw"})
        if data is None or not {"name", "shape", "x", "y", "size"} <= set(data):
            return None
        return SceneObject(
            name=self.text(data["name"], f"{where}.name"),
            shape=self.text(data["shape"], f"{where}.shape"),
            x=self.number(data["x"], f"{where}.x"),
            y=self.number(data["y"], f"{where}.y"),
            size=self.numbers(data["size"], f"{where}.size", 3),  # type: ignore[arg-type]
            yaw=self.number(data.get("yaw", 0.0), f"{where}.yaw"),
        )


def scene_from_dict(data: Any) -> Scene:
    """Build and validate a Scene from plain data; raise ``SceneError`` naming every problem."""
    reader = _Reader()
    top = reader.mapping(data, "scene", {"table", "start", "target"}, {"name", "start_yaw", "obstacles"})
    if top is None or not {"table", "start", "target"} <= set(top):
        raise SceneError(*reader.problems)
    table_data = reader.mapping(top["table"], "table", {"length", "width", "height"}, set())
    table = None
    if table_data is not None and {"length", "width", "height"} <= set(table_data):
        table = Table(
            length=reader.number(table_data["length"], "table.length"),
            width=reader.number(table_data["width"], "table.width"),
            height=reader.number(table_data["height"], "table.height"),
        )
    target = reader.scene_object(top["target"], "target")
    raw_obstacles = top.get("obstacles") or []
    if not isinstance(raw_obstacles, list):
        reader.problems.append(f"obstacles: expected a list, got {type(raw_obstacles).__name__}")
        raw_obstacles = []
    obstacles = [reader.scene_object(v, f"obstacles[{i}]") for i, v in enumerate(raw_obstacles)]
    start = reader.numbers(top["start"], "start", 2)
    start_yaw = reader.number(top.get("start_yaw", 0.0), "start_yaw")
    raw_name = top.get("name")
    name = "" if raw_name is None else reader.text(raw_name, "name")
    if reader.problems or table is None or target is None or None in obstacles:
        raise SceneError(*(reader.problems or ["scene: incomplete"]))
    scene = Scene(
        table=table,
        start=start,  # type: ignore[arg-type]
        target=target,
        obstacles=tuple(obstacles),  # type: ignore[arg-type]
        start_yaw=start_yaw,
        name=name,
    )
    return validate_scene(scene)


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
        SceneError: the file is missing, unreadable, not YAML/JSON, or describes an invalid scene;
            every message starts with the file's path.
    """
    path = Path(path)
    suffix = _suffix(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise SceneError(f"{path}: cannot read: {error}") from None
    try:
        data = json.loads(text) if suffix in JSON_SUFFIXES else yaml.safe_load(text)
    except json.JSONDecodeError as error:
        raise SceneError(f"{path}: not valid JSON: {error}") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(error, "problem", None) or "syntax error"
        raise SceneError(f"{path}: not valid YAML{where}: {problem}") from None
    try:
        return scene_from_dict(data)
    except SceneError as error:
        raise SceneError(*(f"{path}: {p}" for p in error.problems)) from None


def save_scene(scene: Scene, path: str | os.PathLike[str]) -> None:
    """Validate ``scene`` and write it atomically as YAML or JSON (by extension)."""
    path = Path(path)
    suffix = _suffix(path)
    validate_scene(scene)
    write_text_atomic(path, scene_to_text(scene, json_format=suffix in JSON_SUFFIXES))
