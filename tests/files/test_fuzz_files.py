"""Fuzzing the file boundaries: model files (models.json, models.npz) and the VR dataset's files
and cache, damaged at random.

Model files: every damaged copy either loads (its values still usable: it then plans the default
scene) or is refused with one ``ModelError``, never a numpy or zip error. Dataset: every damaged
file is a problem naming its file and its trial is left out; every kept trial loads; a damaged
cache is rebuilt.
"""

from __future__ import annotations

import functools
import hashlib
import io
import json
import shutil
import tempfile
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fuzz_support import PROFILES, STATS, check_error, junk, run
from hypothesis import strategies as st
from synthetic_dataset import write_dataset

from hlp_drake.dataset import Dataset
from hlp_drake.errors import DatasetError, HlpError, ModelError
from hlp_drake.learners.bundled import BUNDLED_DIRECTORY
from hlp_drake.learners.models import DecisionModels, model_digest
from hlp_drake.planner import plan
from hlp_drake.scene.io import default_scene


@functools.cache
def _bundled_arrays() -> dict[str, np.ndarray]:
    with np.load(BUNDLED_DIRECTORY / "models.npz", allow_pickle=False) as npz:
        return {name: npz[name] for name in npz.files}


def _npz(arrays: dict[str, np.ndarray]) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def _huge_header(arrays: dict[str, np.ndarray], name: str, *, unclosed: bool = False) -> bytes:
    """An npz whose member ``name`` declares 10^12 elements (or, with ``unclosed``, has a header
    whose shape's parenthesis is never closed), every member's CRC right."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for key, value in arrays.items():
            member = io.BytesIO()
            if key == name and not unclosed:
                header = {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)}
                np.lib.format.write_array_header_1_0(member, header)
                member.write(value.tobytes())
            else:
                np.lib.format.write_array(member, value)
            data = member.getvalue()
            if key == name and unclosed:
                data = data.replace(b"), }", b",  }", 1)
            archive.writestr(f"{key}.npy", data)
    return buffer.getvalue()


_VALUES = st.sampled_from([np.nan, np.inf, -1.0, 0.0, 1e300, -(2**31), 2**31 - 1, 10**6])


@st.composite
def damaged_models(draw) -> tuple[bytes, bytes]:
    """(models.json, models.npz) of the bundled models, damaged one way or another."""
    arrays = dict(_bundled_arrays())
    meta = json.loads((BUNDLED_DIRECTORY / "models.json").read_text())
    names = sorted(arrays)
    how = draw(
        st.sampled_from(["value", "dtype", "shape", "drop", "extra", "header", "bytes", "json", "truncate"])
    )
    name = names[draw(st.integers(0, len(names) - 1))]
    if how == "value":
        values = arrays[name].copy()
        with warnings.catch_warnings():  # nan or inf into an integer: whatever the cast gives
            warnings.simplefilter("ignore", RuntimeWarning)
            if values.ndim:
                values.flat[draw(st.integers(0, values.size - 1))] = np.asarray(draw(_VALUES)).astype(
                    values.dtype
                )
            else:
                values = np.asarray(draw(_VALUES)).astype(values.dtype)
        arrays[name] = values
    elif how == "dtype":
        arrays[name] = arrays[name].astype(
            draw(st.sampled_from([np.float32, np.int64, np.int8, np.complex128, "U3"]))
        )
    elif how == "shape":
        value = arrays[name]
        arrays[name] = draw(
            st.sampled_from(
                [
                    value.ravel()[:-1] if value.size > 1 else value.reshape(1),
                    value.T.copy(),
                    value[None],
                    np.zeros((0,) + value.shape[1:]),
                ]
            )
        )
    elif how == "drop":
        arrays.pop(name)
    elif how == "extra":
        arrays["extra.array"] = np.zeros(3)
    payload = _huge_header(arrays, name) if how == "header" else _npz(arrays)
    if how == "bytes":
        data = bytearray(payload)
        for _ in range(draw(st.integers(1, 8))):
            data[draw(st.integers(0, len(data) - 1))] = draw(st.integers(0, 255))
        payload = bytes(data)
    if how == "truncate":
        payload = payload[: draw(st.integers(0, len(payload) - 1))]
    meta["sha256"] = hashlib.sha256(payload).hexdigest()  # the checksum catches damage, not tampering
    if how == "json":
        field = draw(
            st.sampled_from(
                [
                    "format",
                    "version",
                    "mode",
                    "settings",
                    "subjects",
                    "sha256",
                    "planner",
                    "row_learner",
                    "n_estimators",
                ]
            )
        )
        target = meta["settings"] if field in ("planner", "row_learner", "n_estimators") else meta
        target[field] = draw(junk)
    text = json.dumps(meta).encode()
    if draw(st.integers(0, 15)) == 0:
        text = text[: draw(st.integers(0, len(text)))]
    return text, payload


def _check_models(files: tuple[bytes, bytes]) -> None:
    STATS["model files"] += 1
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "models.json").write_bytes(files[0])
        (Path(folder) / "models.npz").write_bytes(files[1])
        try:
            models = DecisionModels.load(folder)
        except ModelError as error:
            check_error(error)
            STATS["model files refused"] += 1
            return
    STATS["model files loaded"] += 1
    result = plan(default_scene(), models)
    assert result.ok or result.reason


@pytest.mark.parametrize("profile", PROFILES)
def test_damaged_model_files_load_or_are_one_model_error(profile):
    run(profile, (80, 400), damaged_models(), _check_models)


def _edited_models(folder: Path, how: str) -> None:
    """The bundled models in ``folder`` with one of the issue's edits, the checksum updated to match."""
    arrays, meta = dict(_bundled_arrays()), json.loads((BUNDLED_DIRECTORY / "models.json").read_text())
    if how == "subjects: 5":
        meta["subjects"] = 5
    elif how == "n_estimators: -5":
        meta["settings"]["n_estimators"] = -5
    elif how == "faithful rows models":
        meta["mode"] = "faithful"
    elif how == "an extra field":
        meta["extra"] = 1
    elif how == "row.learner.feature as float":
        arrays["row.learner.feature"] = arrays["row.learner.feature"].astype(float)
    elif how == "row.novelty.points of 3 features":
        arrays["row.novelty.points"] = arrays["row.novelty.points"][:, :3]
    elif how == "row.learner.left past the nodes":
        arrays["row.learner.left"] = arrays["row.learner.left"] + 10**6
    if how in ("10^12 elements", "an unclosed header"):  # the second: numpy raised TokenError
        payload = _huge_header(arrays, "arm.train", unclosed=how == "an unclosed header")
    else:
        payload = _npz(arrays)
    meta["sha256"] = hashlib.sha256(payload).hexdigest()
    folder.mkdir()
    (folder / "models.npz").write_bytes(payload)
    (folder / "models.json").write_text(json.dumps(meta))


@pytest.mark.parametrize(
    ("how", "problem"),
    [
        ("subjects: 5", "models.json: subjects: expected a list"),
        ("n_estimators: -5", "models.json: settings.n_estimators: expected 1 to 10,000, got -5"),
        ("faithful rows models", "models.json: mode: the rows planner's models are trained in fixed mode"),
        ("an extra field", "models.json: top level: unknown field 'extra'"),
        ("10^12 elements", "array 'arm.train' has shape (1000000, 1000000)"),
        (
            "row.learner.feature as float",
            "array 'row.learner.feature' has dtype float64, the format has int32",
        ),
        ("row.novelty.points of 3 features", "array 'row.novelty.points' has shape"),
        ("row.learner.left past the nodes", "array 'row.learner.left' has values outside"),
        ("an unclosed header", "unreadable .npy header (TokenError)"),
    ],
)
def test_an_edited_model_file_is_one_model_error_naming_the_field(tmp_path, how, problem):
    _edited_models(tmp_path / "m", how)
    with pytest.raises(ModelError) as error:
        DecisionModels.load(tmp_path / "m")
    check_error(error.value)
    assert problem in str(error.value), str(error.value)


def test_a_pinned_model_refuses_other_files_with_a_valid_checksum(tmp_path):
    folder = tmp_path / "m"
    shutil.copytree(BUNDLED_DIRECTORY, folder)
    pin = model_digest(folder)
    arrays = dict(_bundled_arrays())
    arrays["row.calibration"] = arrays["row.calibration"] * 2.0
    text, payload = json.loads((folder / "models.json").read_text()), _npz(arrays)
    text["sha256"] = hashlib.sha256(payload).hexdigest()
    (folder / "models.npz").write_bytes(payload)
    (folder / "models.json").write_text(json.dumps(text))
    DecisionModels.load(folder)  # consistent files: the checksum alone cannot tell
    with pytest.raises(ModelError, match="is not the pinned"):
        DecisionModels.load(folder, sha256=pin)


def test_a_scenario_pins_its_models_by_the_sha256_of_models_json(tmp_path):
    from hlp_drake.systems import load_scenario
    from hlp_drake.systems.planning.diagram import scenario_models

    folder = tmp_path / "m"
    shutil.copytree(BUNDLED_DIRECTORY, folder)
    digest = hashlib.sha256((folder / "models.json").read_bytes()).hexdigest()  # what sha256sum prints
    assert model_digest(folder) == digest
    trusted = load_scenario(data=f"planner: {{models: '{folder}', models_sha256: {digest}}}")
    assert scenario_models(trusted).planner == "rows"
    other = load_scenario(data=f"planner: {{models: '{folder}', models_sha256: '{'0' * 64}'}}")
    with pytest.raises(ModelError, match="is not the pinned"):
        scenario_models(other)


# --- The dataset ---------------------------------------------------------------------------------------

_TRIALS = {5: "Success", 10: "Success", 11: "ArmInteraction"}


def _damage_csv(text: str, draw) -> str:
    lines = text.splitlines()
    how = draw(st.sampled_from(["nan", "reverse", "header", "truncate", "cut", "bytes", "empty", "swap"]))
    if how == "nan" and len(lines) > 1:
        row = draw(st.integers(1, len(lines) - 1))
        fields = lines[row].split(",")
        fields[draw(st.integers(0, len(fields) - 1))] = draw(
            st.sampled_from(["NaN", "inf", "", "x", "1e999"])
        )
        lines[row] = ",".join(fields)
    elif how == "reverse":
        lines = lines[:1] + lines[1:][::-1]
    elif how == "header":
        lines = lines[:1]
    elif how == "truncate":
        lines = lines[: max(1, len(lines) // 2)]
    elif how == "cut":
        joined = "\n".join(lines)
        return joined[: draw(st.integers(0, len(joined)))]
    elif how == "bytes":
        return text[: len(text) // 2] + "\udcff\x00" + text[len(text) // 2 :]
    elif how == "empty":
        return ""
    elif how == "swap" and len(lines) > 2:
        lines[1], lines[2] = lines[2], lines[1]
    return "\n".join(lines) + "\n"


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
        path.write_text(_damage_csv(path.read_text(), data.draw), encoding="utf-8", errors="surrogateescape")
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


def _cheap_job(job):
    """A finished job's row without planning (the resume logic is what is fuzzed)."""
    from hlp_drake.experiments import make_row

    return make_row(
        job,
        success=job.seed % 2 == 0,
        failure_reason=None if job.seed % 2 == 0 else "the target is out of reach",
        plan_s=0.01,
        ik_s=0.1,
        optimise_s=1.0,
        verify_s=0.5,
        execute_s=2.0,
        rollouts=8,
        iterations=1,
        objects_moved=1,
        objects_dropped=0,
    )


def _run(out) -> None:
    """The cheap experiment (gen1 seeds 10 and 11, both initialisers) in ``out``, in this process."""
    from job_support import run_experiment, settings

    run_experiment(settings(scenes=2), out, job=_cheap_job)


@functools.cache
def _run_folder() -> dict[str, bytes]:
    """The records of a finished (cheap) experiment: results.csv, run.json, config.json."""
    with tempfile.TemporaryDirectory() as folder:
        _run(folder)
        return {
            name: (Path(folder) / name).read_bytes() for name in ("results.csv", "run.json", "config.json")
        }


@st.composite
def damaged_run_folder(draw) -> dict[str, bytes]:
    """A finished experiment folder's records, one damaged: bytes flipped or cut, a field of a row
    or a record replaced by junk."""
    files = _run_folder()
    name = draw(st.sampled_from(sorted(files)))
    data = files[name]
    how = draw(st.sampled_from(["bytes", "truncate", "field"]))
    if how == "bytes":
        data = bytearray(data)
        for _ in range(draw(st.integers(1, 8))):
            data[draw(st.integers(0, len(data) - 1))] = draw(st.integers(0, 255))
    elif how == "truncate":
        data = data[: draw(st.integers(0, len(data) - 1))]
    elif name == "results.csv":
        lines = data.decode().splitlines()
        row = draw(st.integers(1, len(lines) - 1))
        fields = lines[row].split(",")
        fields[draw(st.integers(0, len(fields) - 1))] = str(draw(junk)).replace("\n", " ")
        data = ("\n".join([*lines[:row], ",".join(fields), *lines[row + 1 :]]) + "\n").encode()
    else:
        record = json.loads(data)
        record[draw(st.sampled_from(sorted(record)))] = draw(junk)
        data = json.dumps(record).encode()
    return {**files, name: bytes(data)}


def _check_resume(files: dict[str, bytes]) -> None:
    from hlp_drake.experiments.results import COLUMNS, read_results

    STATS["run folders damaged"] += 1
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        for name, data in files.items():
            (out / name).write_bytes(data)
        try:
            _run(out)
        except HlpError as error:
            check_error(error)
            assert {name: (out / name).read_bytes() for name in files} == files  # left as it was
            STATS["run folders refused"] += 1
            return
        rows = read_results(out / "results.csv", ("gen1",))  # resumed: every job's row, well-formed
        assert sorted((r["scene"], r["planner"]) for r in rows) == [
            (f"gen1-{seed}", planner) for seed in (10, 11) for planner in ("hlp", "sto")
        ]
        assert all(list(r) == list(COLUMNS) for r in rows)
        STATS["run folders resumed"] += 1


@pytest.mark.parametrize("profile", PROFILES)
def test_damaged_run_folders_resume_or_are_refused_as_they_were(profile):
    run(profile, (40, 400), damaged_run_folder(), _check_resume)
