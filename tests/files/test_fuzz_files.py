"""Fuzzing the model files (models.json, models.npz): every damaged copy loads or is one ModelError.

A damaged copy that loads keeps its values usable: it then plans the default scene; one that does
not is refused with one ``ModelError``, never a numpy or zip error.
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
from fuzz_support import PROFILES, STATS, check_error, flip_bytes, junk, run
from hypothesis import strategies as st

from hlp_drake.errors import ModelError
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
        payload = flip_bytes(draw, payload)
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
