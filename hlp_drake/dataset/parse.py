"""Parsers for the dataset's CSV files; each raises ``ValueError`` with a readable reason."""

from __future__ import annotations

import csv
import io
import math

import numpy as np

from hlp_drake.dataset.records import INTERACTION_KINDS
from hlp_drake.errors import short

MOVEMENT_COLUMNS = 7  # time, pos_x, pos_y, pos_z, rot_x, rot_y, rot_z
MIN_SAMPLES = 2  # a track of fewer samples has no motion
MAX_VALUE = 1e6
"""A track, layout or log value beyond this (m, degrees or s) is not a VR room's: the file is damaged."""
LAYOUT_HEADER = ["object", "x", "y", "z", "width", "height", "depth"]
LOG_HEADER = ["start_time", "end_time", "dominant_object", "non_dominant_object", "interaction_type"]


def _text(data: bytes) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise ValueError(f"not UTF-8 text ({error.reason} at byte {error.start})") from None


def _rows(data: bytes, header: list[str]) -> list[list[str]]:
    rows = list(csv.reader(io.StringIO(_text(data))))
    if not rows:
        raise ValueError("empty file")
    if [h.strip() for h in rows[0]] != header:
        raise ValueError(f"unexpected header {rows[0]!r} (expected {header!r})")
    return [row for row in rows[1:] if row]


def _float(text: str, where: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{where}: not a number: {text!r}") from None


def parse_movement(data: bytes, name: str) -> np.ndarray:
    """A movement file -> (N, 7) float64 array (time, pos xyz, rot xyz; Unity frame, degrees)."""
    text = _text(data)
    header, _, body = text.partition("\n")
    columns = [c.strip() for c in header.split(",")]
    prefix = "" if name.endswith("Tracker") else f"{name}_"
    expected = ["time"] + [f"{prefix}{k}_{a}" for k in ("pos", "rot") for a in "xyz"]
    if columns != expected:
        raise ValueError(f"unexpected header {header.strip()!r} (expected {','.join(expected)!r})")
    if not body.strip():
        raise ValueError("no samples (a header only)")
    try:
        values = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2, dtype=np.float64)
    except ValueError as error:
        raise ValueError(f"malformed row: {short(str(error), 120)}") from None
    if values.shape[1] != MOVEMENT_COLUMNS:
        raise ValueError(f"rows have {values.shape[1]} columns, expected {MOVEMENT_COLUMNS}")
    return check_track(values)


def check_track(values: np.ndarray) -> np.ndarray:
    """``values`` (N, 7) if they are a usable track: at least 2 samples, all finite, times strictly
    increasing; else ``ValueError`` naming the first bad row (line numbers count the header)."""
    if len(values) < MIN_SAMPLES:
        raise ValueError(f"{len(values)} sample(s), a track needs at least {MIN_SAMPLES}")
    bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
    if len(bad):
        raise ValueError(f"line {bad[0] + 2}: non-finite value")
    bad = np.flatnonzero(np.any(np.abs(values) > MAX_VALUE, axis=1))
    if len(bad):
        raise ValueError(f"line {bad[0] + 2}: a value beyond +-{MAX_VALUE:g}")
    back = np.flatnonzero(np.diff(values[:, 0]) <= 0)
    if len(back):
        raise ValueError(
            f"line {back[0] + 3}: time does not increase ({values[back[0] + 1, 0]!r} after {values[back[0], 0]!r})"
        )
    return values


def parse_layout(data: bytes) -> list[list]:
    """A scene or object layout file -> rows ``[name, x, y, z, width, height, depth]`` (Unity frame)."""
    parsed = []
    for i, row in enumerate(_rows(data, LAYOUT_HEADER), start=2):
        if len(row) != len(LAYOUT_HEADER):
            raise ValueError(f"line {i}: {len(row)} fields, expected {len(LAYOUT_HEADER)}")
        values = [_float(v, f"line {i}") for v in row[1:]]
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"line {i}: non-finite value in {row!r}")
        if any(abs(v) > MAX_VALUE for v in values):
            raise ValueError(f"line {i}: a value beyond +-{MAX_VALUE:g} in {row!r}")
        parsed.append([row[0].strip(), *values])
    return parsed


def parse_interactions(data: bytes) -> list[list]:
    """An interaction log -> rows ``[start, end or None, dominant, non_dominant, type]``.

    A log whose last line has no line end, or with a kind not in ``INTERACTION_KINDS`` (e.g. "Pus"),
    was cut short: every log of the dataset ends its lines and uses those four kinds.
    """
    text = _text(data)
    if text and not text.endswith(("\n", "\r")):
        raise ValueError("truncated: the last line has no line end")
    parsed = []
    for i, row in enumerate(_rows(data, LOG_HEADER), start=2):
        if len(row) != len(LOG_HEADER):
            raise ValueError(f"line {i}: {len(row)} fields, expected {len(LOG_HEADER)}")
        start = _float(row[0], f"line {i}")
        end = _float(row[1], f"line {i}") if row[1].strip() else None
        if not math.isfinite(start) or (end is not None and not math.isfinite(end)):
            raise ValueError(f"line {i}: non-finite time in {row[:2]!r}")
        if max(abs(start), abs(end or 0.0)) > MAX_VALUE:
            raise ValueError(f"line {i}: a time beyond +-{MAX_VALUE:g} s in {row[:2]!r}")
        if end is not None and end < start:
            raise ValueError(f"line {i}: ends ({end!r}) before it starts ({start!r})")
        if row[4].strip() not in INTERACTION_KINDS:
            raise ValueError(
                f"line {i}: unknown interaction {short(row[4].strip(), 40)!r} (expected one of "
                f"{', '.join(INTERACTION_KINDS)}; the file may be cut short)"
            )
        parsed.append([start, end, row[2].strip(), row[3].strip(), row[4].strip()])
    return parsed


def parse_table(data: bytes, required: list[str]) -> list[dict[str, str]]:
    """A CSV with a header (trial_results.csv, participant_list.csv) -> rows as dicts."""
    reader = csv.DictReader(io.StringIO(_text(data)))
    missing = [c for c in required if c not in (reader.fieldnames or [])]
    if missing:
        raise ValueError(f"missing columns {missing}")
    return [row for row in reader if any(v for v in row.values() if v)]


def optional_float(text: str | None) -> float | None:
    """'' or None -> None, else the number (raises ValueError)."""
    if text is None or not text.strip():
        return None
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"not a finite number: {text.strip()[:40]!r}")
    return value
