"""``Dataset``: the VR study's trials, loaded lazily from a cache built on first use."""

from __future__ import annotations

import os
import re
import sys
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from hlp_drake.dataset.cache import (
    CACHE_ENV_VAR,
    CACHE_VERSION,
    INDEX_DIGEST,
    build_cache,
    cache_lock,
    default_cache_root,
    load_cache,
)
from hlp_drake.dataset.convert import TableFrame, scene_from_layouts
from hlp_drake.dataset.parse import check_track
from hlp_drake.dataset.records import TRACKERS, Interaction, Trial, TrialRecord, trial_key
from hlp_drake.dataset.source import Source, resolve_source
from hlp_drake.errors import DatasetError, SceneError
from hlp_drake.scene.model import Scene

_TRIAL_IN_TEXT = re.compile(r"(sub_\d+)[/\\]T(\d{3})")


def _check_cache_root(root: Path) -> None:
    """Make the cache folder ``root`` and probe that a file can be written in it."""
    try:
        root.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=root).close()
    except OSError as error:
        raise _cache_error(root, error) from None


def _cache_error(root: Path, error: OSError) -> DatasetError:
    reason = "not a folder" if root.exists() and not root.is_dir() else error.strerror or str(error)
    return DatasetError(
        f"cannot write the dataset cache in {root} ({reason}); set {CACHE_ENV_VAR} to a writable folder"
    )


class Dataset:
    """The VR dataset: trial metadata at once, each trial's tracks and scene on request.

    Args:
        path: the archive or the unpacked folder, or several laid over each other
            (``resolve_source``); None reads ``HLP_DATASET``.
        cache_dir: where caches live (default ``$HLP_CACHE`` or ``~/.cache/hlp_drake``).
        progress: show a progress bar while the cache is built.

    Attributes:
        source: where the data was read from.
        cache_status: "warm" (read from an existing cache) or "built" (parsed now).
        problems: unreadable, missing or invalid files as ``{"path", "reason"}``; their trials are
            left out of ``records`` and ``trials``.
        notes: corrections made to kept trials, as ``{"path", "reason"}`` (e.g. a stale start
            point in a scene file, replaced by ``trial_results.csv``'s).

    Raises:
        DatasetError: no dataset at ``path``, or the archive cannot be read.
    """

    def __init__(
        self,
        path: str | os.PathLike[str] | Sequence[str | os.PathLike[str]] | None = None,
        *,
        cache_dir: str | os.PathLike[str] | None = None,
        progress: bool = True,
    ) -> None:
        self.source: Source = resolve_source(path)
        root = Path(cache_dir) if cache_dir is not None else default_cache_root()
        self.cache_path = root / f"vr-v{CACHE_VERSION}-{self.source.fingerprint()[:16]}"
        try:
            index, tracks = load_cache(self.cache_path)
            self.cache_status = "warm"
        except ValueError:
            with cache_lock(self.cache_path):  # processes loading at once parse the source once
                try:
                    index, tracks = load_cache(self.cache_path)
                    self.cache_status = "warm"
                except ValueError as error:
                    if self.cache_path.exists():
                        print(f"rebuilding the dataset cache at {self.cache_path} ({error})", file=sys.stderr)
                    _check_cache_root(root)  # before parsing: a bad folder fails fast
                    try:
                        build_cache(self.source, self.cache_path, progress=progress)
                    except OSError as error:
                        raise _cache_error(root, error) from None
                    try:
                        index, tracks = load_cache(self.cache_path)
                    except ValueError as again:
                        raise DatasetError(
                            f"{self.cache_path}: cannot write a usable cache: {again}"
                        ) from None
                    self.cache_status = "built"
        self._tracks = tracks
        self._entries: dict[str, dict[str, Any]] = {
            trial_key(e["subject"], e["trial"]): e for e in index["trials"]
        }
        self.problems: list[dict[str, str]] = index["problems"]
        self.notes: list[dict[str, str]] = index["notes"]
        self.records: list[TrialRecord] = [_record(e) for e in self._entries.values()]

    def __len__(self) -> int:
        return len(self.records)

    def left_out(self) -> dict[str, dict[str, str]]:
        """The trials the loader left out, by key ("sub_01/T050"): the first problem naming each
        (in its file's path, or in its reason for a problem of ``trial_results.csv``)."""
        trials: dict[str, dict[str, str]] = {}
        for problem in self.problems:
            match = _TRIAL_IN_TEXT.search(problem["path"]) or _TRIAL_IN_TEXT.search(problem["reason"])
            if match:
                trials.setdefault(trial_key(match.group(1), int(match.group(2))), problem)
        return trials

    def __contains__(self, key: str) -> bool:
        return key in self._entries

    @property
    def subjects(self) -> list[str]:
        return sorted({r.subject for r in self.records})

    def select(
        self,
        *,
        category: str | None = None,
        success: bool | None = None,
        subjects: Iterable[str] | None = None,
    ) -> list[TrialRecord]:
        """Records filtered by category, outcome and subject."""
        wanted = set(subjects) if subjects is not None else None
        return [
            r
            for r in self.records
            if (category is None or r.category == category)
            and (success is None or r.success == success)
            and (wanted is None or r.subject in wanted)
        ]

    def scene(self, key: str) -> Scene:
        """The Scene of one trial, without loading its tracks."""
        entry = self._entry(key)
        try:
            return scene_from_layouts(
                entry["scene_layout"], entry["objects_layout"], key, start_x=entry["start_x"]
            )
        except (ValueError, SceneError) as error:  # it was valid when the cache was built
            raise self._damaged(f"{key}'s scene: {error}") from None

    def _entry(self, key: str) -> dict[str, Any]:
        entry = self._entries.get(key)
        if entry is None:
            raise KeyError(f"no trial {key!r} in the dataset")
        return entry

    def trial(self, key: str) -> Trial:
        """Load one trial, e.g. ``dataset.trial("sub_01/T050")``.

        Raises:
            KeyError: no such trial (or it was left out as a problem).
            DatasetError: the cache is found damaged (it is rebuilt on the next load).
        """
        entry = self._entry(key)
        frame = TableFrame(entry["scene_layout"], entry["start_x"])
        tracks = {
            name: frame.track(TRACKERS.get(name, name), self._block(span))
            for name, span in entry["tracks"].items()
        }
        return Trial(
            record=_record(entry),
            scene=self.scene(key),
            trackers={TRACKERS[n]: t for n, t in tracks.items() if n in TRACKERS},
            objects={n: t for n, t in tracks.items() if n not in TRACKERS},
            interactions=tuple(Interaction(*row) for row in entry["interactions"]),
        )

    def trials(self, records: Iterable[TrialRecord] | None = None) -> Iterator[Trial]:
        """Load the trials of ``records`` (default: all) one at a time."""
        for record in self.records if records is None else records:
            yield self.trial(record.key)

    def _block(self, span: list[int]) -> np.ndarray:
        start, rows = span
        try:
            return check_track(np.asarray(self._tracks[start : start + rows]))
        except ValueError as error:  # it was valid when the cache was built
            raise self._damaged(f"a track: {error}") from None

    def _damaged(self, reason: str) -> DatasetError:
        """The error of a cache found damaged in use; the cache is dropped, so the next load rebuilds it."""
        (self.cache_path / INDEX_DIGEST).unlink(missing_ok=True)
        return DatasetError(
            f"{self.cache_path}: the dataset cache is damaged ({reason}); it is rebuilt on the next load"
        )


def _record(entry: dict[str, Any]) -> TrialRecord:
    start, end, moved, reached = entry["times"]
    return TrialRecord(
        subject=entry["subject"],
        trial=entry["trial"],
        category=entry["category"],
        outcome=entry["outcome"],
        handedness=entry["handedness"],
        trial_name=entry["trial_name"],
        start_time=start,
        end_time=end,
        start_moved_time=moved,
        target_reached_time=reached,
    )
