"""``DecisionModels``: a planner's learners together, fitted from training sets, saved in a safe format.

Files: ``models.json`` (format, version, settings, checksum) and ``models.npz`` (plain arrays,
read with ``allow_pickle=False``). Nothing is ever unpickled; every field and every array's name,
dtype and shape is checked against the format (``learners.model_format``, which also states the
trust model) before use, and any damage is one ``ModelError``.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hlp_drake.config.typed_yaml import document_problems
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED, category_of
from hlp_drake.errors import ModelError
from hlp_drake.features.augment import mirrored_rows
from hlp_drake.features.training import TrainingData
from hlp_drake.files.atomic import atomic_path, write_text_atomic
from hlp_drake.files.documents import brief, parse_json, read_bytes
from hlp_drake.learners.arm import CATEGORICAL as ARM_CATEGORICAL
from hlp_drake.learners.arm import ArmRegressor
from hlp_drake.learners.choice import LEARNERS as ROW_LEARNERS
from hlp_drake.learners.choice import RowChoiceClassifier
from hlp_drake.learners.direction import CATEGORICAL as DIRECTION_CATEGORICAL
from hlp_drake.learners.direction import DirectionClassifier
from hlp_drake.learners.model_format import (
    MAX_MODEL_BYTES,
    check_declared,
    check_pin,
    check_values,
    digest,
    expected_arrays,
    fixed_sizes,
    read_arrays,
)
from hlp_drake.learners.svm import RbfSvmClassifier
from hlp_drake.segmentation.modes import Mode, is_faithful

FORMAT = "hlp_drake.decision_models"
VERSION = 2
PLANNERS = ("rows", "paper")
MAX_META_BYTES = 2**20
"""Largest ``models.json`` read, bytes."""
# The learners each planner uses: the row-by-row planner (Cr, Cd, Ra) or the paper's Algorithm 1
# (Cg, Co, Cc, Cd, Ra).
LEARNERS = {"rows": ("row", "direction", "arm"), "paper": ("gap", "object", "segment", "direction", "arm")}


@dataclass(frozen=True)
class LearnerSettings:
    """Hyper-parameters of the learners ("paper" preset: reference section 5).

    Attributes:
        planner: which planner the models serve: "rows" (row by row with the row-choice
            classifier, any layout) or "paper" (Algorithm 1 with the paper's Cg, Co and Cc).
        row_learner: the row-choice classifier's learner: "boosted" trees or "svm" (the paper's
            RBF SVM) (``RowChoiceClassifier``).
        n_estimators, max_depth, learning_rate: the boosted trees'.
        structured_weight: weight of a structured trial's row-choice examples where unstructured
            trials are in the training set too (the structured trials are three times as many,
            and their people moved obstacles more often in the same situations).
        row_context: the row-choice classifier reads the way the hand came too
            (``features.row_choice.CONTEXT_FEATURES``), not only the row's candidates.
        row_mirror: the row-choice classifier learns every example and its mirror image too
            (``features.augment``).
        C, kernel_scale: the RBF SVMs' (the original: 1, 0.25).
        segment_max_per_class: caps the segment classifier's balanced training set (the full grid
            has ~70k rows of which 2 % positive; an RBF SVM on 140k oversampled rows takes many
            minutes, on 2 x 4000 rows about a second, with the same validation accuracy).
        arm_max_samples: the arm regressor's subset.
        balance_gap_object, gap_object_from_all_trials: the paper planner's gap and object SVMs.
        random_state: the seed of every subsample and fold.
    """

    planner: str = "paper"
    row_learner: str = "boosted"
    n_estimators: int = 150
    max_depth: int = 3
    learning_rate: float = 0.1
    structured_weight: float = 0.25
    row_context: bool = False
    row_mirror: bool = False
    C: float = 1.0
    kernel_scale: float = 0.25
    segment_max_per_class: int = 4000
    arm_max_samples: int = 1500
    balance_gap_object: bool = True
    gap_object_from_all_trials: bool = False
    random_state: int = 0


PRESETS = {
    # The default: row by row, gradient-boosted row-choice trees on the transferable features.
    "boosted": LearnerSettings(planner="rows", row_learner="boosted"),
    # The paper's RBF SVM (and GP) on the transferable features, row by row.
    "svm": LearnerSettings(planner="rows", row_learner="svm"),
    # Reference section 5: Algorithm 1, the paper's features, oversampled RBF SVMs, gap/object
    # examples from the original's trials only.
    "paper": LearnerSettings(planner="paper"),
}
DEFAULT_PRESET = "boosted"


@dataclass(frozen=True)
class ModelDescription:
    """The fields of ``models.json`` (the schema it is checked against)."""

    format: str
    version: int
    mode: Mode
    settings: LearnerSettings
    subjects: tuple[str, ...]
    sha256: str


SETTING_RANGES = {
    "n_estimators": (1, 10_000),
    "max_depth": (1, 64),
    "learning_rate": (1e-6, 10.0),
    "structured_weight": (1e-6, 1e6),
    "C": (1e-9, 1e9),
    "kernel_scale": (1e-9, 1e9),
    "segment_max_per_class": (1, 10_000_000),
    "arm_max_samples": (1, 10_000_000),
    "random_state": (0, 2**32 - 1),
}
"""The range of each numeric learner setting a model file may state (its arrays were trained so)."""


def _settings(meta: Any, where: Path) -> LearnerSettings:
    """The learner settings of the ``models.json`` document ``meta``, once every field is checked."""
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ModelError(f"{where}: not an hlp_drake model file")
    version = meta.get("version")
    if version != VERSION:
        if isinstance(version, int) and not isinstance(version, bool) and version > VERSION:
            raise ModelError(
                f"{where}: written by a newer hlp_drake: format {version}, this release reads {VERSION}"
            )
        raise ModelError(
            f"{where}: model format version {brief(version)}, this release reads {VERSION} (train them again)"
        )
    problems = document_problems(ModelDescription, meta, top="top level")
    settings = meta.get("settings") if isinstance(meta.get("settings"), dict) else {}
    if settings.get("planner", "paper") not in PLANNERS:
        problems.append(
            f"settings.planner: expected one of {', '.join(PLANNERS)}, got {brief(settings['planner'])}"
        )
    if settings.get("row_learner", "boosted") not in ROW_LEARNERS:
        problems.append(
            f"settings.row_learner: expected one of {', '.join(ROW_LEARNERS)}, "
            f"got {brief(settings['row_learner'])}"
        )
    for name, (low, high) in SETTING_RANGES.items():
        value = settings.get(name)
        if isinstance(value, int | float) and not isinstance(value, bool) and not low <= value <= high:
            problems.append(f"settings.{name}: expected {low:,} to {high:,}, got {value!r}")
    if settings.get("planner") == "rows" and meta.get("mode", "fixed") != "fixed":
        problems.append(
            f"mode: the rows planner's models are trained in fixed mode, got {brief(meta['mode'])}"
        )
    subjects = meta.get("subjects")
    if isinstance(subjects, list) and (
        len(subjects) > 1000 or any(isinstance(s, str) and len(s) > 100 for s in subjects)
    ):
        problems.append("subjects: more than 1000 subjects or a name longer than 100 characters")
    if isinstance(meta.get("sha256"), str) and not re.fullmatch(r"[0-9a-f]{64}", meta["sha256"]):
        problems.append("sha256: expected 64 hexadecimal digits")
    if problems:
        raise ModelError(*(f"{where}: {p}" for p in problems))
    return LearnerSettings(**settings)


def model_digest(directory: str | os.PathLike[str]) -> str:
    """The SHA-256 (hex) of the ``models.json`` in ``directory``: what ``DecisionModels.load``'s
    ``sha256`` pins (``sha256sum models.json`` prints the same)."""
    path = Path(directory) / "models.json"
    return digest(read_bytes(path, ModelError, missing="model file not found", limit=MAX_META_BYTES))


def _category_weights(keys: np.ndarray, structured_weight: float) -> np.ndarray | None:
    """Per row: ``structured_weight`` for structured trials where unstructured ones are present too."""
    categories = np.array([category_of(int(str(k).split("/T")[1])) for k in keys])
    if not np.any(categories == UNSTRUCTURED):
        return None
    return np.where(categories == STRUCTURED, structured_weight, 1.0)


class DecisionModels:
    """The learners of one planner (``LEARNERS``), plus human arm priors.

    Attributes (after ``fit`` or ``load``):
        row, gap, object, segment, direction, arm: the estimators (those of the planner).
        mode_: the segmentation/feature mode the training data was made in.
        subjects_: the subjects trained on.
        start_arm_: median (q1, q2) of the demonstrators at the start.
        link_lengths_: median (upper arm, forearm) lengths, m (on the VR table).
    """

    def __init__(self, settings: LearnerSettings | None = None) -> None:
        self.settings = settings or PRESETS[DEFAULT_PRESET]
        s = self.settings
        if s.planner not in PLANNERS:
            raise ModelError(f"unknown planner {s.planner!r}; choose one of {', '.join(PLANNERS)}")
        self.learners = LEARNERS[s.planner]
        self.direction = DirectionClassifier(
            C=s.C, categorical=DIRECTION_CATEGORICAL, random_state=s.random_state
        )
        self.arm = ArmRegressor(
            max_samples=s.arm_max_samples, categorical=ARM_CATEGORICAL, random_state=s.random_state
        )
        if s.planner == "rows":
            self.row = RowChoiceClassifier(
                learner=s.row_learner,
                n_estimators=s.n_estimators,
                max_depth=s.max_depth,
                learning_rate=s.learning_rate,
                C=s.C,
                kernel_scale=s.kernel_scale,
                random_state=s.random_state,
            )
        else:
            self.gap = RbfSvmClassifier(
                C=s.C, kernel_scale=s.kernel_scale, balance=s.balance_gap_object, random_state=s.random_state
            )
            self.object = RbfSvmClassifier(
                C=s.C, kernel_scale=s.kernel_scale, balance=s.balance_gap_object, random_state=s.random_state
            )
            self.segment = RbfSvmClassifier(
                C=s.C,
                kernel_scale=s.kernel_scale,
                max_per_class=s.segment_max_per_class,
                random_state=s.random_state,
            )
        self.mode_ = "fixed"
        self.subjects_: list[str] = []

    @property
    def planner(self) -> str:
        return self.settings.planner

    @property
    def row_features(self) -> int:
        """The columns of Xr (``ROW_CONTEXT_FEATURES``, the first ones) the row-choice classifier reads."""
        return fixed_sizes(self.settings.row_context)["row.n_features"]

    def fit(self, data: TrainingData, *, only: tuple[str, ...] | None = None) -> DecisionModels:
        """Fit the planner's learners on ``data``.

        Args:
            only: fit only these learners; the others stay as they are (e.g. taken from other
                fitted models).
        """
        if self.planner == "rows" and is_faithful(data.mode):
            raise ModelError(
                "the row-by-row planner's learners need fixed-mode data (the paper preset reads faithful)"
            )
        for name in self.learners if only is None else [n for n in self.learners if n in only]:
            labelled = getattr(data, name)
            if name in ("gap", "object") and not self.settings.gap_object_from_all_trials:
                labelled = labelled.original_rows()
            if len(labelled) == 0:
                raise ModelError(f"no training rows for the {name} learner")
            estimator = getattr(self, name)
            if name == "row":
                X, y, groups = labelled.X[:, : self.row_features], labelled.y, labelled.subjects
                weight = _category_weights(labelled.keys, self.settings.structured_weight)
                if self.settings.row_mirror:
                    weight = np.ones(len(y)) if weight is None else weight
                    X, y, groups, weight = mirrored_rows(X, y, groups, weight)
                estimator.fit(X, y, groups=groups, sample_weight=weight)
            else:
                estimator.fit(labelled.X, labelled.y)
        self.mode_ = data.mode
        self.subjects_ = sorted(set(data.people.subjects))
        self.start_arm_ = np.median(data.people.y, axis=0)
        self.link_lengths_ = np.median(data.people.X, axis=0)
        return self

    # -- persistence ---------------------------------------------------------------------------

    def _arrays(self) -> dict[str, np.ndarray]:
        arrays = {
            f"{name}.{key}": np.asarray(value)
            for name in self.learners
            for key, value in getattr(self, name).get_state().items()
        }
        arrays["priors.start_arm"] = np.asarray(self.start_arm_)
        arrays["priors.link_lengths"] = np.asarray(self.link_lengths_)
        return arrays

    def save(self, directory: str | os.PathLike[str]) -> Path:
        """Write ``models.npz`` and ``models.json`` into ``directory`` (atomically, each)."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        buffer = io.BytesIO()
        np.savez_compressed(buffer, **self._arrays())
        payload = buffer.getvalue()
        with atomic_path(directory / "models.npz") as tmp:
            Path(tmp).write_bytes(payload)
        meta = {
            "format": FORMAT,
            "version": VERSION,
            "mode": self.mode_,
            "settings": asdict(self.settings),
            "subjects": self.subjects_,
            "sha256": hashlib.sha256(payload).hexdigest(),
        }
        write_text_atomic(directory / "models.json", json.dumps(meta, indent=2) + "\n")
        return directory

    @classmethod
    def load(cls, directory: str | os.PathLike[str], *, sha256: str | None = None) -> DecisionModels:
        """Read models saved by ``save``; refuse anything else with a ``ModelError``.

        Args:
            sha256: the SHA-256 (hex) of the trusted ``models.json`` (``model_digest``); given, any
                other files are refused (see ``learners.model_format`` for the trust model).
        """
        directory = Path(directory)
        meta_path, npz_path = directory / "models.json", directory / "models.npz"
        meta_bytes = read_bytes(meta_path, ModelError, missing="model file not found", limit=MAX_META_BYTES)
        if not npz_path.is_file():
            raise ModelError(f"{npz_path}: model file not found")
        check_pin(meta_bytes, sha256, str(meta_path))
        try:
            meta = parse_json(meta_bytes.decode("utf-8"), str(meta_path), ModelError)
        except (UnicodeDecodeError, ModelError) as error:
            reason = (
                error.problems[0].removeprefix(f"{meta_path}: ")
                if isinstance(error, ModelError)
                else "not UTF-8"
            )
            raise ModelError(f"{meta_path}: not a model description ({reason})") from None
        settings = _settings(meta, meta_path)
        payload = read_bytes(npz_path, ModelError, missing="model file not found", limit=MAX_MODEL_BYTES)
        if hashlib.sha256(payload).hexdigest() != meta["sha256"]:
            raise ModelError(f"{npz_path}: checksum mismatch (the file was modified or damaged)")
        try:
            arrays = read_arrays(
                payload,
                expected_arrays(settings.planner, settings.row_learner),
                fixed_sizes(settings.row_context),
            )
            check_values(arrays)
            check_declared(arrays, settings)
        except ValueError as error:
            raise ModelError(f"{npz_path}: {error}") from None
        models = cls(settings)
        for name in models.learners:
            prefix = f"{name}."
            getattr(models, name).set_state(
                {k[len(prefix) :]: v for k, v in arrays.items() if k.startswith(prefix)}
            )
        models.start_arm_ = arrays["priors.start_arm"]
        models.link_lengths_ = arrays["priors.link_lengths"]
        models.mode_ = meta["mode"]
        models.subjects_ = list(meta["subjects"])
        return models

    def describe(self) -> dict[str, Any]:
        return {"mode": self.mode_, "subjects": self.subjects_, "settings": asdict(self.settings)}
