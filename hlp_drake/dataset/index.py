"""The structure of a dataset cache's ``index.json``, checked before the index is used.

The cache is the project's own file, but it lives on disk between runs: one damaged or edited
(whose digest was updated too) must be rebuilt, never trusted. ``check_index`` raises
``ValueError`` naming the first field that does not fit; the loader then rebuilds the cache. The
kept trials' track spans tile the track array in index order, so an index with a trial removed,
added or repeated is refused too. An edit that keeps every field well-formed and the spans
tiling (e.g. another outcome text) cannot be told from a real cache without a secret: the cache
guards against damage, and a user who suspects an edit deletes it (``HLP_CACHE``).
"""

from __future__ import annotations

import math
import re
from typing import Any

from hlp_drake.dataset.parse import MIN_SAMPLES
from hlp_drake.dataset.records import CATEGORIES

_TEXT_FIELDS = ("subject", "category", "outcome", "handedness", "trial_name")
_SUBJECT = re.compile(r"sub_\d+")


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _optional_number(value: Any) -> bool:
    return value is None or _number(value)


def _layout(rows: Any) -> bool:
    """[name, x, y, z, width, height, depth] rows."""
    return isinstance(rows, list) and all(
        isinstance(row, list) and len(row) == 7 and isinstance(row[0], str) and all(map(_number, row[1:]))
        for row in rows
    )


def _interactions(rows: Any) -> bool:
    """[start, end or None, dominant, non-dominant, type] rows."""
    return isinstance(rows, list) and all(
        isinstance(row, list)
        and len(row) == 5
        and _number(row[0])
        and _optional_number(row[1])
        and all(isinstance(v, str) for v in row[2:])
        for row in rows
    )


def _entry_problem(entry: Any, first_row: int) -> str | None:
    """What is wrong with one trial entry whose tracks start at ``first_row`` (None if nothing)."""
    if not isinstance(entry, dict):
        return "not a mapping"
    for name in _TEXT_FIELDS:
        if not isinstance(entry.get(name), str):
            return f"{name} is not text"
    if not _SUBJECT.fullmatch(entry["subject"]):
        return "subject is not a subject folder"
    if entry["category"] not in CATEGORIES:
        return "unknown category"
    if (
        not isinstance(entry.get("trial"), int)
        or isinstance(entry["trial"], bool)
        or not 0 < entry["trial"] < 1000
    ):
        return "trial is not a trial number"
    times = entry.get("times")
    if not (isinstance(times, list) and len(times) == 4 and all(map(_optional_number, times))):
        return "times are not 4 numbers or nulls"
    if not _optional_number(entry.get("start_x")):
        return "start_x is not a number"
    if not (_layout(entry.get("scene_layout")) and _layout(entry.get("objects_layout"))):
        return "a layout is not rows of a name and 6 numbers"
    if not _interactions(entry.get("interactions")):
        return "interactions are not rows of 2 times and 3 texts"
    tracks = entry.get("tracks")
    if not isinstance(tracks, dict) or not tracks:
        return "no tracks"
    for span in tracks.values():
        if not (isinstance(span, list) and len(span) == 2 and all(isinstance(v, int) for v in span)):
            return "a track span is not 2 integers"
        start, count = span
        if start != first_row or count < MIN_SAMPLES:
            return "the track spans do not follow each other through the track array"
        first_row += count
    return None


def _track_rows(entry: dict[str, Any]) -> int:
    return sum(count for _, count in entry["tracks"].values())


def _records(value: Any) -> bool:
    """A list of {"path": text, "reason": text}."""
    return isinstance(value, list) and all(
        isinstance(p, dict) and set(p) == {"path", "reason"} and all(isinstance(v, str) for v in p.values())
        for p in value
    )


def check_index(index: dict[str, Any]) -> None:
    """Raise ``ValueError`` if ``index`` (a parsed ``index.json``) is not a well-formed cache index."""
    rows = index.get("rows")
    if not isinstance(rows, int) or rows < 0:
        raise ValueError("index: rows is not a count")
    trials = index.get("trials")
    if not isinstance(trials, list):
        raise ValueError("index: trials is not a list")  # noqa: TRY004 (the loader rebuilds on ValueError)
    first_row, keys = 0, set()
    for k, entry in enumerate(trials):
        problem = _entry_problem(entry, first_row)
        if problem is None and (entry["subject"], entry["trial"]) in keys:
            problem = "a trial listed twice"
        if problem is not None:
            raise ValueError(f"index: trials[{k}]: {problem}")
        keys.add((entry["subject"], entry["trial"]))
        first_row += _track_rows(entry)
    if first_row != rows:
        raise ValueError(f"index: the trials' tracks cover {first_row} of the track array's {rows} rows")
    for name in ("problems", "notes"):
        if not _records(index.get(name)):
            raise ValueError(f"index: {name} are not path/reason records")
