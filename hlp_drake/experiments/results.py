"""``results.csv``: one row per (scene, cell of the grid), read back for resuming, rewritten atomically.

Columns (in this order): the paper's ``scene, objects, planner, success, failure_reason, init_s,
optimise_s, total_s, rollouts, objects_moved, objects_dropped``, then ``seed, iterations,
verifications, rejected, verify_s, model_success, false_accept, replans, replan_rollouts, execute_s``,
then the cell's axes ``generator, robot, initial, low_level, execution, perception, model_error,
world``
(``planner`` names the initialiser and low-level planner pair: the paper's ``hlp`` and ``sto`` for
the STO; ``rollouts`` counts the low-level planner's rollouts, ``verifications`` its checks on the
execution model, of which ``rejected`` failed there, ``verify_s`` the seconds they took, part of
``optimise_s``; ``success`` is the verdict of the ``world`` the motion was executed in (``reference``
or the planner's own ``model``), ``model_success`` the low-level planner's own (it accepted a motion),
``false_accept`` the model accepted and the world failed; ``replans`` and ``replan_rollouts``: the closed-loop controller's; ``model_error``: the
seed of the world's model error, empty for none). Times are seconds; ``init_s`` = plan + IK,
``total_s`` = init + low-level planning (the simulated execution, ``execute_s``, is excluded);
``objects_moved`` and ``objects_dropped`` are counts. Booleans are ``true``/``false``; a missing
failure reason is an empty field.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from hlp_drake.errors import HlpError
from hlp_drake.experiments.runner import Row
from hlp_drake.files.atomic import atomic_path
from hlp_drake.files.documents import read_bytes

AXIS_COLUMNS = (
    "generator",
    "robot",
    "initial",
    "low_level",
    "execution",
    "perception",
    "model_error",
    "world",
)
"""The grid's axes, as rows name them."""
COLUMNS = (
    "scene",
    "objects",
    "planner",
    "success",
    "failure_reason",
    "init_s",
    "optimise_s",
    "total_s",
    "rollouts",
    "objects_moved",
    "objects_dropped",
    "seed",
    "iterations",
    "verifications",
    "rejected",
    "verify_s",
    "model_success",
    "false_accept",
    "replans",
    "replan_rollouts",
    "execute_s",
    *AXIS_COLUMNS,
    "grasp_held",
    "fallback",
)
"""The columns of ``results.csv``; a file written before the last ``LATER_COLUMNS`` lacks them."""
LATER_COLUMNS = {"grasp_held": None, "fallback": False}
"""Columns added after the first results files, with the value an older file's rows take (None:
unknown): ``grasp_held``, the grasp after a reach success (empty when there was none);
``fallback``, the low-level planner relaxed its problem to find the motion."""
KEY_COLUMNS = ("scene", "objects", *AXIS_COLUMNS[1:])
"""A row's identity (``row_key``)."""
CELL_COLUMNS = ("robot", "initial", "low_level", "planner", *AXIS_COLUMNS[4:])
"""A row's cell of the grid, as ``hlp_drake.config.what_ran.Labels`` names it."""
BOOL_COLUMNS = frozenset({"success", "model_success", "false_accept", "fallback"})
FLOAT_COLUMNS = frozenset({"init_s", "optimise_s", "total_s", "verify_s", "execute_s"})
TEXT_COLUMNS = frozenset({"scene", "planner", "failure_reason", *AXIS_COLUMNS} - {"model_error"})
INT_COLUMNS = frozenset(COLUMNS) - BOOL_COLUMNS - FLOAT_COLUMNS - TEXT_COLUMNS - {"model_error", "grasp_held"}
BOOLEANS = {"true": True, "false": False}
MAX_RESULTS_BYTES = 64 << 20
"""A larger ``results.csv`` is refused (a run of thousands of jobs writes a few MB)."""
MAX_SECONDS = 1e7
"""A time column beyond this (about 4 months) is not a job's."""
START_OVER = "use --fresh to start over or choose another --out"
"""How to get past a directory that cannot be resumed."""


def row_key(row: Row) -> tuple:
    """A row's identity: its scene (name and object count) and its cell (``KEY_COLUMNS``)."""
    return tuple(row[column] for column in KEY_COLUMNS)


def sort_key(row: Row) -> tuple:
    """The file's order: generator, object count, scene seed, then the cell."""
    cell = tuple("" if row[c] is None else str(row[c]) for c in AXIS_COLUMNS[1:])
    return row["generator"], row["objects"], row["seed"], row["planner"], cell


def _format(column: str, value: Any) -> str:
    if column == "grasp_held":
        return "" if value is None else ("true" if value else "false")
    if column in BOOL_COLUMNS:
        return "true" if value else "false"
    if column in FLOAT_COLUMNS:
        return f"{float(value):.6f}"
    return "" if value is None else str(value)


def _parse(column: str, text: str) -> Any:
    if column == "model_error":
        return int(text) if text else None
    if column == "grasp_held":
        return BOOLEANS[text] if text else None
    if column in BOOL_COLUMNS:
        return BOOLEANS[text]  # KeyError: not a boolean
    if column in INT_COLUMNS:
        return int(text)
    if column in FLOAT_COLUMNS:
        return float(text)
    if column == "failure_reason":
        return text or None
    return text


def results_csv(rows: Iterable[Row]) -> str:
    """``rows`` as CSV text with the header, sorted by ``sort_key``."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in sorted(rows, key=sort_key):
        writer.writerow([_format(column, row[column]) for column in COLUMNS])
    return out.getvalue()


def read_results(
    path: Path, generators: Iterable[str] | None = None, cells: Iterable[tuple] | None = None
) -> list[Row]:
    """The rows of ``path`` (none when it does not exist).

    Args:
        generators: the run's scene generators: every row's scene must be one of theirs (the name
            its generator, seed and object count give); None: any.
        cells: the run's cells as rows name them (``CELL_COLUMNS``' values): every row's must be
            one of them; None: any.

    Raises:
        HlpError: the file is unreadable, too large, has other columns or a malformed row (one
            line, naming the file and line).
    """
    if not path.exists():
        return []
    reader = csv.reader(io.StringIO(read_run_file(path, MAX_RESULTS_BYTES), newline=""))
    try:
        header = tuple(next(reader, ()))
        if header != COLUMNS and header != COLUMNS[: -len(LATER_COLUMNS)]:
            raise HlpError(f"{path}: not an experiment results file (unexpected columns); {START_OVER}")
        rows = []
        for record in reader:
            try:
                rows.append(_row(header, record, generators, None if cells is None else set(cells)))
            except (KeyError, ValueError) as error:
                raise HlpError(
                    f"{path}: line {reader.line_num}: malformed row ({error}); {START_OVER}"
                ) from None
    except csv.Error as error:
        raise HlpError(f"{path}: unreadable ({error}); {START_OVER}") from None
    return rows


def read_run_file(path: Path, limit: int) -> str:
    """The text of a run folder's record ``path`` (``results.csv``, ``run.json``, ``config.json``).

    Raises:
        HlpError: it is unreadable, larger than ``limit`` bytes or not UTF-8 (one line, with how to
            start over).
    """
    try:
        return read_bytes(path, limit=limit).decode("utf-8")
    except HlpError as error:
        raise HlpError(f"{error.problems[0]}; {START_OVER}") from None
    except UnicodeDecodeError as error:
        raise HlpError(f"{path}: unreadable ({error}); {START_OVER}") from None


def _row(
    header: tuple[str, ...], record: list[str], generators: Iterable[str] | None, cells: set | None
) -> Row:
    """The row of one CSV ``record`` under ``header``; ValueError or KeyError names what is wrong."""
    if len(record) != len(header):
        raise ValueError(f"{len(record)} fields")
    row = {c: _parse(c, text) for c, text in zip(header, record)}
    for column, value in LATER_COLUMNS.items():  # an older file's rows
        row.setdefault(column, value)
    for column in INT_COLUMNS:
        if row[column] < 0:
            raise ValueError(f"{column} {row[column]}, expected a count")
    for column in FLOAT_COLUMNS:  # NaN: unknown (a crashed job's times)
        value = row[column]
        if not (math.isnan(value) or 0.0 <= value <= MAX_SECONDS):
            raise ValueError(f"{column} {value}, expected 0 to {MAX_SECONDS:g} s or nan")
    generator = row["generator"]
    if generators is not None and generator not in generators:
        raise ValueError(f"generator {generator!r}, not one of the study's")
    if row["scene"] != scene_name(generator, row["seed"], row["objects"]):
        raise ValueError(f"scene {row['scene']!r} is not the {generator} scene of its seed and object count")
    cell = tuple(row[column] for column in CELL_COLUMNS)
    if cells is not None and cell not in cells:
        raise ValueError(f"the cell {', '.join(map(str, cell))}, not one of the study's")
    return row


def scene_name(generator: str, seed: int, objects: int) -> str:
    """The name ``generate_scene`` gives the ``generator``'s scene of ``seed`` with ``objects``
    obstacles."""
    return f"{generator}-{objects}-{seed}" if generator == "gen2" else f"{generator}-{seed}"


def write_durable(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically and durably: temp file beside it, fsync, ``os.replace``."""
    with atomic_path(path) as tmp, tmp.open("w", encoding="utf-8", newline="") as file:
        file.write(text)
        file.flush()
        os.fsync(file.fileno())
    _fsync_directory(path.parent)


def _fsync_directory(directory: Path) -> None:
    """Make a rename in ``directory`` durable (where the platform allows opening a directory)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


class ResultsFile:
    """The rows of ``results.csv`` by ``row_key``; every ``add`` rewrites the file atomically."""

    def __init__(self, path: Path, rows: Iterable[Row] = ()) -> None:
        self.path = path
        self.rows: dict[tuple, Row] = {row_key(row): row for row in rows}

    def __contains__(self, key: tuple) -> bool:
        return key in self.rows

    def add(self, row: Row) -> None:
        missing = [column for column in COLUMNS if column not in row]
        if missing:
            raise ValueError(f"a job returned a row without {', '.join(missing)}")
        rows = {**self.rows, row_key(row): {column: row[column] for column in COLUMNS}}
        write_durable(self.path, results_csv(rows.values()))  # a failed write keeps neither
        self.rows = rows

    def save(self) -> None:
        write_durable(self.path, results_csv(self.rows.values()))
