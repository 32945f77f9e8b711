"""One pass over the dataset's files -> a cache: ``index.json`` plus one memory-mapped ``tracks.npy``.

The first load parses every CSV (streaming through the archive if that is the source); later loads
read the small index and map the track array, so a trial's arrays are only touched when it is used.
The cache is keyed by the source's fingerprint and ``CACHE_VERSION`` and written atomically.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import re
import shutil
import sys
import tempfile
from collections import Counter, defaultdict
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from hlp_drake.dataset.convert import scene_from_layouts, stale_start
from hlp_drake.dataset.index import check_index
from hlp_drake.dataset.parse import (
    optional_float,
    parse_interactions,
    parse_layout,
    parse_movement,
    parse_table,
)
from hlp_drake.dataset.records import ARM_PARTS, TRACKERS, category_of, trial_key
from hlp_drake.dataset.source import PARTICIPANTS_FILE, Source
from hlp_drake.errors import HlpError, short
from hlp_drake.runtime.terminal import bars_disabled

CACHE_VERSION = 6  # 6: damaged interaction logs (cut short, naming an object the scene lacks) are left
# out (5: values beyond parse.MAX_VALUE, files beyond source.MAX_FILE_BYTES and trials listed twice;
# 4: the track array holds the kept trials' tracks only, in index order)
COVERAGE_TOLERANCE = 0.1  # s: a track may start or end this much inside its trial (the data: <= 12 ms)
INDEX_DIGEST = "index.sha256"  # beside index.json: a cache whose index was edited or damaged is rebuilt
CACHE_ENV_VAR = "HLP_CACHE"
_TRIAL_FILE = re.compile(r"^(sub_\d+)/T(\d{3})/(scene|movement)/(.+)$")
_MOVEMENT = re.compile(r"^(.+)_movement_T\d{3}\.csv$")
RESULTS_FILE = "trial_results.csv"
RESULT_COLUMNS = ["trial_num", "outcome"]


def default_cache_root() -> Path:
    """``$HLP_CACHE``, else ``$XDG_CACHE_HOME/hlp_drake``, else ``~/.cache/hlp_drake``."""
    if os.environ.get(CACHE_ENV_VAR):
        return Path(os.environ[CACHE_ENV_VAR]).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "hlp_drake"


class _Collector:
    """Accumulates parsed files and problems during the pass over the source."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.problems: list[dict[str, str]] = []
        self.notes: list[dict[str, str]] = []
        self.where: dict[str, str] = {}
        self.participants: dict[str, dict[str, str]] | None = None
        self.results: dict[str, list[dict[str, str]]] = {}
        self.trial_files: dict[tuple[str, int], dict[str, Any]] = defaultdict(dict)
        self.broken: set[tuple[str, int]] = set()
        self.blocks: list[np.ndarray] = []
        self.rows = 0

    def describe(self, relative: str) -> str:
        """Where a user finds ``relative``: in the part it was read from (else the first part)."""
        return self.where.get(relative) or self.source.parts[0].describe(relative)

    def problem(self, relative: str, reason: str) -> None:
        self.problems.append({"path": self.describe(relative), "reason": reason})

    def note(self, relative: str, reason: str) -> None:
        """A correction made to a trial that is kept (e.g. a stale start point)."""
        self.notes.append({"path": self.describe(relative), "reason": reason})

    def add(self, relative: str, where: str, content: bytes | OSError) -> None:
        self.where[relative] = where
        match = _TRIAL_FILE.match(relative)
        if isinstance(content, OSError):
            self.problem(relative, f"cannot read: {content}")
            if match:
                self.broken.add((match.group(1), int(match.group(2))))
            return
        try:
            if relative == PARTICIPANTS_FILE:
                rows = parse_table(content, ["ppid", "handedness"])
                self.participants = {r["ppid"].strip(): r for r in rows}
            elif relative.count("/") == 1 and relative.endswith("/" + RESULTS_FILE):
                self.results[relative.split("/")[0]] = parse_table(content, RESULT_COLUMNS)
            elif match:
                self._add_trial_file(match, content)
        except ValueError as error:
            self.problem(relative, str(error))
            if match:
                self.broken.add((match.group(1), int(match.group(2))))

    def _add_trial_file(self, match: re.Match, content: bytes) -> None:
        subject, number, folder, name = match.group(1), int(match.group(2)), match.group(3), match.group(4)
        files = self.trial_files[(subject, number)]
        if folder == "scene":
            if name.startswith("scene_layout_"):
                files["scene_layout"] = parse_layout(content)
            elif name.startswith("grid_objects_layout_"):
                files["objects_layout"] = parse_layout(content)
            return
        if name.startswith("interaction_log_"):
            files["interactions"] = parse_interactions(content)
            return
        movement = _MOVEMENT.match(name)
        if movement:
            block = parse_movement(content, movement.group(1))
            files.setdefault("tracks", {})[movement.group(1)] = [self.rows, len(block)]
            files.setdefault("track_times", {})[movement.group(1)] = (float(block[0, 0]), float(block[-1, 0]))
            self.blocks.append(block)
            self.rows += len(block)


def _trial_number(row: dict[str, str]) -> int | None:
    """A trial_results row's trial number (None if it is not a number)."""
    try:
        return int(row["trial_num"])
    except (KeyError, TypeError, ValueError):
        return None


def _assemble(collector: _Collector) -> list[dict[str, Any]]:
    """Join trial_results rows with their trial folders; every rejected trial becomes a problem."""
    participants = collector.participants
    if participants is None:
        collector.problem(PARTICIPANTS_FILE, "missing: handedness unknown for every subject")
        participants = {}
    trials = []
    listed: set[tuple[str, int]] = set()
    subjects = sorted({s for s, _ in collector.trial_files} | set(collector.results))
    for subject in subjects:
        if subject not in collector.results:
            collector.problem(
                f"{subject}/{RESULTS_FILE}", "missing or unreadable: the subject's trials are skipped"
            )
            continue
        handedness = (participants.get(subject, {}).get("handedness") or "unknown").strip().lower()
        if subject not in participants and collector.participants is not None:
            collector.problem(PARTICIPANTS_FILE, f"no row for {subject}: handedness unknown")
        where = f"{subject}/{RESULTS_FILE}"
        listings = Counter(_trial_number(row) for row in collector.results[subject])
        for line, row in enumerate(collector.results[subject], start=2):
            try:
                number = int(row["trial_num"])
                category = category_of(number)
                times = [
                    optional_float(row.get(c))
                    for c in ("start_time", "end_time", "start_moved_time", "target_reached_time")
                ]
            except (TypeError, ValueError) as error:
                collector.problem(where, f"line {line}: {error}")
                continue
            key = (subject, number)
            listed.add(key)
            if listings[number] > 1:  # which row is the trial's is unknown: neither is kept
                collector.problem(where, f"line {line}: {trial_key(*key)} is listed more than once: left out")
                continue
            entry = _trial_entry(collector, key, category, handedness, row, times)
            if entry is not None:
                trials.append(entry)
    for key in sorted(set(collector.trial_files) - listed):
        if key[0] in collector.results:
            collector.problem(trial_key(*key), f"folder not listed in {key[0]}/{RESULTS_FILE}: skipped")
    return trials


def _trial_entry(
    collector: _Collector,
    key: tuple[str, int],
    category: str,
    handedness: str,
    row: dict[str, str],
    times: list[float | None],
) -> dict[str, Any] | None:
    subject, number = key
    folder = trial_key(subject, number)
    if key in collector.broken:
        return None  # already reported with the broken file's path
    files = collector.trial_files.get(key)
    if files is None:
        collector.problem(folder, f"listed in {RESULTS_FILE} but its folder is missing")
        return None
    if not _complete(collector, folder, number, files, times):
        return None
    try:
        start_x = optional_float(row.get("start_pos_x"))
        scene = scene_from_layouts(files["scene_layout"], files["objects_layout"], folder, start_x=start_x)
    except (ValueError, HlpError) as error:
        collector.problem(f"{folder}/scene/grid_objects_layout_T{number:03d}.csv", f"invalid scene: {error}")
        return None
    stale = stale_start(files["scene_layout"], start_x)
    if stale is not None:
        collector.note(
            f"{folder}/scene/scene_layout_T{number:03d}.csv",
            f"StartPoint x {stale:.4f} is stale: {subject}/{RESULTS_FILE} start_pos_x {start_x:.4f} "
            f"used (start at world y {scene.start[1]:+.4f} m)",
        )
    return {
        "subject": subject,
        "trial": number,
        "category": category,
        "outcome": (row.get("outcome") or "").strip(),
        "handedness": handedness,
        "trial_name": (row.get("trial_name") or "").strip(),
        "times": times,
        "start_x": start_x,
        "scene_layout": files["scene_layout"],
        "objects_layout": files["objects_layout"],
        "tracks": files["tracks"],
        "interactions": files["interactions"],
    }


def _complete(
    collector: _Collector, folder: str, number: int, files: dict[str, Any], times: list[float | None]
) -> bool:
    """Whether a trial's files are all there, its tracks span the trial and its interaction log names
    only the scene's objects; if not, the problems say what is wrong (every missing file or short
    track, the first stranger)."""
    missing = [
        f"{folder}/scene/{name}_T{number:03d}.csv"
        for field, name in (("scene_layout", "scene_layout"), ("objects_layout", "grid_objects_layout"))
        if field not in files
    ]
    if "interactions" not in files:
        missing.append(f"{folder}/movement/interaction_log_T{number:03d}.csv")
    if "objects_layout" in files:
        tracks = files.get("tracks", {})
        missing += [
            f"{folder}/movement/{name}_movement_T{number:03d}.csv"
            for name in [*TRACKERS, *(r[0] for r in files["objects_layout"])]
            if name not in tracks
        ]
    if missing:
        for path in missing:
            collector.problem(path, "missing: trial skipped")
        return False
    start_time, end_time = times[0], times[1]
    short_tracks = [
        (name, first, last)
        for name, (first, last) in files["track_times"].items()
        if (start_time is not None and first > start_time + COVERAGE_TOLERANCE)
        or (end_time is not None and last < end_time - COVERAGE_TOLERANCE)
    ]
    for name, first, last in short_tracks:
        collector.problem(
            f"{folder}/movement/{name}_movement_T{number:03d}.csv",
            f"truncated: the track spans {first:.3f}-{last:.3f} s, the trial "
            f"{start_time}-{end_time} s ({RESULTS_FILE}): trial skipped",
        )
    if short_tracks:
        return False
    strangers = _strangers(files["interactions"], files["objects_layout"])
    if strangers:
        line, name = strangers[0]
        collector.problem(
            f"{folder}/movement/interaction_log_T{number:03d}.csv",
            f"line {line}: names {short(name, 40)!r}, which the scene does not have: trial skipped",
        )
        return False
    return True


def _strangers(interactions: list[list], objects_layout: list[list]) -> list[tuple[int, str]]:
    """(line, name) of every name the interaction log gives that is not the scene's (the acting
    body may also be one of ``ARM_PARTS``); lines count the header."""
    objects = {row[0] for row in objects_layout}
    return [
        (line, name)
        for line, (_, _, dominant, non_dominant, _) in enumerate(interactions, start=2)
        for name, known in ((dominant, objects | set(ARM_PARTS)), (non_dominant, objects))
        if name not in known
    ]


def _kept_tracks(blocks: list[np.ndarray], trials: list[dict[str, Any]]) -> np.ndarray:
    """The kept ``trials``' track blocks end to end in index order, their spans renumbered to match
    (so the spans tile the array exactly: ``check_index`` refuses an index with a trial removed)."""
    by_start, start = {}, 0
    for block in blocks:
        by_start[start], start = block, start + len(block)
    kept, rows = [], 0
    for entry in trials:
        for name, (first, count) in entry["tracks"].items():
            kept.append(by_start[first])
            entry["tracks"][name] = [rows, count]
            rows += count
    return np.concatenate(kept) if kept else np.empty((0, 7))


@contextmanager
def cache_lock(directory: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``directory``'s cache while it is checked and built (a second
    process waits, then finds it built); no lock where the folder cannot take one."""
    try:
        directory.parent.mkdir(parents=True, exist_ok=True)
        handle = open(directory.parent / f".{directory.name}.lock", "a+b")  # noqa: SIM115
    except OSError:
        yield
        return
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX)
        except OSError:
            pass
        yield


def build_cache(source: Source, directory: Path, *, progress: bool = True) -> None:
    """Parse the whole source once and write the cache into ``directory`` (atomically)."""
    collector = _Collector(source)
    with tqdm(
        desc="reading VR dataset (first load, cached afterwards)",
        unit="B",
        unit_scale=True,
        disable=bars_disabled(progress, sys.stderr),
        file=sys.stderr,
        mininterval=1.0,
    ) as bar:
        for relative, where, content in source.files(bar):
            collector.add(relative, where, content)
    trials = _assemble(collector)
    tracks = _kept_tracks(collector.blocks, trials)
    index = {
        "version": CACHE_VERSION,
        "source": source.describe_parts(),
        "rows": int(tracks.shape[0]),
        "trials": trials,
        "problems": collector.problems,
        "notes": collector.notes,
    }
    directory.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{directory.name}.", dir=directory.parent))
    try:
        np.save(staging / "tracks.npy", tracks)
        text = json.dumps(index).encode("utf-8")
        (staging / "index.json").write_bytes(text)
        (staging / INDEX_DIGEST).write_text(hashlib.sha256(text).hexdigest(), encoding="utf-8")
        if directory.exists():
            try:
                load_cache(directory)
                return  # another process wrote it meanwhile: keep theirs, which they may be reading
            except ValueError:
                stale = Path(tempfile.mkdtemp(prefix=f".{directory.name}.stale.", dir=directory.parent))
                os.rename(directory, stale / "cache")
                shutil.rmtree(stale, ignore_errors=True)
        os.rename(staging, directory)
    except OSError:
        if not (directory / "index.json").exists():
            raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def load_cache(directory: Path) -> tuple[dict[str, Any], np.ndarray]:
    """Read a cache; raise ``ValueError`` if it is absent, stale or damaged (an index whose digest
    or structure is wrong, spans past the track array, a track array of another shape)."""
    try:
        text = (directory / "index.json").read_bytes()
        recorded = (directory / INDEX_DIGEST).read_text(encoding="utf-8").strip()
        if hashlib.sha256(text).hexdigest() != recorded:
            raise ValueError("the index does not match its digest")
        index = json.loads(text)
        tracks = np.load(directory / "tracks.npy", mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError, RecursionError) as error:
        raise ValueError(f"unreadable cache: {short(str(error), 120)}") from None
    if not isinstance(index, dict) or index.get("version") != CACHE_VERSION:
        raise ValueError("cache version differs")
    if tracks.ndim != 2 or tracks.dtype != np.float64 or tracks.shape != (index.get("rows"), 7):
        raise ValueError("track array does not match the index")
    check_index(index)
    return index, tracks
