"""Fuzzing the VR dataset's files and cache: a damaged file's trial is left out, a damaged cache rebuilt."""

from __future__ import annotations

import hashlib
import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
from fuzz_support import PROFILES, STATS, check_error, damage_csv, junk, run
from hypothesis import strategies as st
from synthetic_dataset import write_dataset

from hlp_drake.dataset import Dataset
from hlp_drake.errors import DatasetError

_TRIALS = {5: "Success", 10: "Success", 11: "ArmInteraction"}


_FILES = [
    "sub_01/T{n:03d}/movement/HandTracker_movement_T{n:03d}.csv",
    "sub_01/T{n:03d}/movement/Target_movement_T{n:03d}.csv",
    "sub_01/T{n:03d}/movement/FailOnTouchObstacleMed_movement_T{n:03d}.csv",
    "sub_01/T{n:03d}/movement/interaction_log_T{n:03d}.csv",
    "sub_01/T{n:03d}/scene/grid_objects_layout_T{n:03d}.csv",
    "sub_01/T{n:03d}/scene/scene_layout_T{n:03d}.csv",
    "sub_01/trial_results.csv",
    "participant_list.csv",
]


def _load(root: Path, cache: Path) -> Dataset | None:
    """The dataset at ``root``, every kept trial loaded; None if it is refused (one short error)."""
    try:
        dataset = Dataset(root, cache_dir=cache, progress=False)
    except DatasetError as error:
        check_error(error)
        return None
    for record in dataset.records:
        dataset.trial(record.key)
    return dataset


def _check_dataset_damage(case) -> None:
    pattern, trial, data = case
    relative = pattern.format(n=trial)
    STATS["dataset files damaged"] += 1
    with tempfile.TemporaryDirectory() as folder:
        root = write_dataset(Path(folder) / "dataset", _TRIALS)
        path = root / relative
        path.write_text(damage_csv(path.read_text(), data.draw), encoding="utf-8", errors="surrogateescape")
        dataset = _load(root, Path(folder) / "cache")
        if dataset is None:
            STATS["datasets refused"] += 1
            return
        left_out = len(_TRIALS) - len(dataset.records)
        if left_out:
            assert dataset.problems and all(p["path"] and p["reason"] for p in dataset.problems)
        STATS["dataset trials left out"] += left_out


@pytest.mark.parametrize("profile", PROFILES)
def test_every_damaged_dataset_file_is_reported_and_every_kept_trial_loads(profile):
    strategy = st.tuples(st.sampled_from(_FILES), st.sampled_from(sorted(_TRIALS)), st.data())
    run(profile, (30, 300), strategy, _check_dataset_damage)


def _check_cache_damage(case) -> None:
    how, value, data = case
    STATS["caches damaged"] += 1
    with tempfile.TemporaryDirectory() as folder:
        root, cache = write_dataset(Path(folder) / "dataset", _TRIALS), Path(folder) / "cache"
        first = Dataset(root, cache_dir=cache, progress=False)
        index_path = first.cache_path / "index.json"
        index = json.loads(index_path.read_text())
        if how == "trials":
            index["trials"] = value
        elif how == "field" and index["trials"]:
            entry = index["trials"][0]
            entry[data.draw(st.sampled_from(sorted(entry)))] = value
        elif how == "span" and index["trials"]:
            spans = index["trials"][0]["tracks"]
            spans[min(spans)] = [index["rows"] - 1, data.draw(st.integers(2, 10**6))]
        elif how == "tracks":
            tracks = np.load(first.cache_path / "tracks.npy")
            tracks[data.draw(st.integers(0, len(tracks) - 1)), data.draw(st.integers(0, 6))] = np.nan
            np.save(first.cache_path / "tracks.npy", tracks)
        text = json.dumps(index)
        index_path.write_text(text)
        consistent = data.draw(st.booleans())
        if consistent:  # a tamper with the digest updated too
            (first.cache_path / "index.sha256").write_text(hashlib.sha256(text.encode()).hexdigest())
        try:
            dataset = _load(root, cache)
        except DatasetError as error:  # a damaged track found in use: dropped, rebuilt on the next load
            check_error(error)
            dataset = _load(root, cache)
        assert dataset is not None
        if not (consistent and how == "field"):  # a well-formed edit of one field cannot be told apart
            assert sorted(r.key for r in dataset.records) == sorted(r.key for r in first.records)
        STATS["caches rebuilt"] += dataset.cache_status == "built"


@pytest.mark.parametrize("profile", PROFILES)
def test_a_damaged_cache_is_rebuilt_never_trusted(profile):
    strategy = st.tuples(st.sampled_from(["trials", "field", "span", "tracks"]), junk, st.data())
    run(profile, (20, 100), strategy, _check_cache_damage)
