"""``DecisionModels``: a planner's learners together, fitted from training sets, saved in a safe format.

Files: ``models.json`` (format, version, settings, checksum) and ``models.npz`` (plain arrays,
read with ``allow_pickle=False``). Nothing is ever unpickled; a file whose checksum, format,
version or arrays do not match is refused with a ``ModelError``.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import zipfile
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hlp_drake.atomic import atomic_path, write_text_atomic
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED, category_of
from hlp_drake.errors import ModelError
from hlp_drake.features.training import TrainingData
from hlp_drake.learners.arm import CATEGORICAL as ARM_CATEGORICAL
from hlp_drake.learners.arm import ArmRegressor
from hlp_drake.learners.choice import RowChoiceClassifier
from hlp_drake.learners.direction import CATEGORICAL as DIRECTION_CATEGORICAL
from hlp_drake.learners.direction import DirectionClassifier
from hlp_drake.learners.svm import RbfSvmClassifier
from hlp_drake.segmentation.modes import is_faithful

FORMAT = "hlp_drake.decision_models"
VERSION = 2
PLANNERS = ("rows", "paper")
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
        self.direction = DirectionClassifier(C=s.C, categorical=DIRECTION_CATEGORICAL, random_state=s.random_state)
        self.arm = ArmRegressor(max_samples=s.arm_max_samples, categorical=ARM_CATEGORICAL,
                                random_state=s.random_state)
        if s.planner == "rows":
            self.row = RowChoiceClassifier(learner=s.row_learner, n_estimators=s.n_estimators, max_depth=s.max_depth,
                                           learning_rate=s.learning_rate, C=s.C, kernel_scale=s.kernel_scale,
                                           random_state=s.random_state)
        else:
            self.gap = RbfSvmClassifier(C=s.C, kernel_scale=s.kernel_scale, balance=s.balance_gap_object,
                                        random_state=s.random_state)
            self.object = RbfSvmClassifier(C=s.C, kernel_scale=s.kernel_scale, balance=s.balance_gap_object,
                                           random_state=s.random_state)
            self.segment = RbfSvmClassifier(C=s.C, kernel_scale=s.kernel_scale,
                                            max_per_class=s.segment_max_per_class, random_state=s.random_state)
        self.mode_ = "fixed"
        self.subjects_: list[str] = []

    @property
    def planner(self) -> str:
        return self.settings.planner

    def fit(self, data: TrainingData) -> DecisionModels:
        """Fit the planner's learners on ``data``."""
        if self.planner == "rows" and is_faithful(data.mode):
            raise ModelError("the row-by-row planner's learners need fixed-mode data (the paper preset reads faithful)")
        for name in self.learners:
            labelled = getattr(data, name)
            if name in ("gap", "object") and not self.settings.gap_object_from_all_trials:
                labelled = labelled.original_rows()
            if len(labelled) == 0:
                raise ModelError(f"no training rows for the {name} learner")
            estimator = getattr(self, name)
            if name == "row":
                estimator.fit(labelled.X, labelled.y, groups=labelled.subjects,
                              sample_weight=_category_weights(labelled.keys, self.settings.structured_weight))
            else:
                estimator.fit(labelled.X, labelled.y)
        self.mode_ = data.mode
        self.subjects_ = sorted(set(data.people.subjects))
        self.start_arm_ = np.median(data.people.y, axis=0)
        self.link_lengths_ = np.median(data.people.X, axis=0)
        return self

    # -- persistence ---------------------------------------------------------------------------

    def _arrays(self) -> dict[str, np.ndarray]:
        arrays = {f"{name}.{key}": np.asarray(value) for name in self.learners
                  for key, value in getattr(self, name).get_state().items()}
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
        meta = {"format": FORMAT, "version": VERSION, "mode": self.mode_, "settings": asdict(self.settings),
                "subjects": self.subjects_, "sha256": hashlib.sha256(payload).hexdigest()}
        write_text_atomic(directory / "models.json", json.dumps(meta, indent=2) + "\n")
        return directory

    @classmethod
    def load(cls, directory: str | os.PathLike[str]) -> DecisionModels:
        """Read models saved by ``save``; refuse anything else with a ``ModelError``."""
        directory = Path(directory)
        meta_path, npz_path = directory / "models.json", directory / "models.npz"
        for path in (meta_path, npz_path):
            if not path.is_file():
                raise ModelError(f"{path}: model file not found")
        try:
            meta = json.loads(meta_path.read_text())
        except (UnicodeDecodeError, json.JSONDecodeError) as error:
            raise ModelError(f"{meta_path}: not a model description ({error.__class__.__name__})") from None
        if not isinstance(meta, dict) or meta.get("format") != FORMAT:
            raise ModelError(f"{meta_path}: not an hlp_drake model file")
        if meta.get("version") != VERSION:
            raise ModelError(f"{meta_path}: model format version {meta.get('version')!r}, this hlp_drake reads {VERSION}")
        payload = npz_path.read_bytes()
        if hashlib.sha256(payload).hexdigest() != meta.get("sha256"):
            raise ModelError(f"{npz_path}: checksum mismatch (the file was modified or damaged)")
        try:
            with np.load(io.BytesIO(payload), allow_pickle=False) as npz:
                arrays = {key: npz[key] for key in npz.files}
        except (ValueError, OSError, zipfile.BadZipFile) as error:
            raise ModelError(f"{npz_path}: unreadable model arrays ({error})") from None
        try:
            settings = LearnerSettings(**meta["settings"])
        except (KeyError, TypeError) as error:
            raise ModelError(f"{meta_path}: bad settings ({error})") from None
        if settings.planner not in PLANNERS:
            raise ModelError(f"{meta_path}: unknown planner {settings.planner!r}")
        models = cls(settings)
        try:
            for name in models.learners:
                prefix = f"{name}."
                getattr(models, name).set_state({k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)})
            models.start_arm_ = arrays["priors.start_arm"]
            models.link_lengths_ = arrays["priors.link_lengths"]
        except KeyError as missing:
            raise ModelError(f"{npz_path}: missing array {missing}") from None
        if not all(np.all(np.isfinite(v)) for v in arrays.values() if v.dtype.kind == "f"):
            raise ModelError(f"{npz_path}: non-finite model parameters")
        models.mode_ = meta.get("mode", "fixed")
        models.subjects_ = list(meta.get("subjects", []))
        return models

    def describe(self) -> dict[str, Any]:
        return {"mode": self.mode_, "subjects": self.subjects_, "settings": asdict(self.settings)}
