"""``DecisionModels``: the five learners together, fitted from training sets, saved in a safe format.

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
from hlp_drake.errors import ModelError
from hlp_drake.features.training import TrainingData
from hlp_drake.learners.arm import ArmRegressor
from hlp_drake.learners.direction import DirectionClassifier
from hlp_drake.learners.svm import RbfSvmClassifier

FORMAT = "hlp_drake.decision_models"
VERSION = 1
LEARNERS = ("gap", "object", "segment", "direction", "arm")


@dataclass(frozen=True)
class LearnerSettings:
    """Hyper-parameters of the five learners ("paper" preset: reference section 5).

    ``segment_max_per_class`` caps the segment classifier's balanced training set (the full grid
    has ~70k rows of which 2 % positive; an RBF SVM on 140k oversampled rows takes many minutes,
    on 2 x 4000 rows about a second, with the same validation accuracy within noise).
    """

    C: float = 1.0
    kernel_scale: float = 0.25
    segment_max_per_class: int = 4000
    arm_max_samples: int = 1500
    balance_gap_object: bool = True
    gap_object_from_all_trials: bool = False
    random_state: int = 0


PRESETS = {
    # Reference section 5: oversampled RBF SVMs, gap/object examples from the original's trials only.
    "paper": LearnerSettings(),
    # Gap and object SVMs see every trial (a row where the person moved an obstacle teaches that its
    # gaps were not taken) at their natural class mix, so they stop accepting most gaps.
    "strong": LearnerSettings(balance_gap_object=False, gap_object_from_all_trials=True),
}


class DecisionModels:
    """Cg (gap), Co (object), Cc (segment), Cd (direction), Ra (arm), plus human arm priors.

    Attributes (after ``fit`` or ``load``):
        mode: the segmentation/feature mode the training data was made in.
        start_arm_: median (q1, q2) of the demonstrators at the start.
        link_lengths_: median (upper arm, forearm) lengths, m (on the VR table).
    """

    def __init__(self, settings: LearnerSettings | None = None) -> None:
        self.settings = settings or LearnerSettings()
        s = self.settings
        self.gap = RbfSvmClassifier(C=s.C, kernel_scale=s.kernel_scale, balance=s.balance_gap_object,
                                    random_state=s.random_state)
        self.object = RbfSvmClassifier(C=s.C, kernel_scale=s.kernel_scale, balance=s.balance_gap_object,
                                       random_state=s.random_state)
        self.segment = RbfSvmClassifier(C=s.C, kernel_scale=s.kernel_scale, max_per_class=s.segment_max_per_class,
                                        random_state=s.random_state)
        self.direction = DirectionClassifier(C=s.C, random_state=s.random_state)
        self.arm = ArmRegressor(max_samples=s.arm_max_samples, random_state=s.random_state)
        self.mode = "fixed"
        self.subjects: list[str] = []

    def fit(self, data: TrainingData) -> DecisionModels:
        """Fit all five learners on ``data``."""
        for name in LEARNERS:
            labelled = getattr(data, name)
            if name in ("gap", "object") and not self.settings.gap_object_from_all_trials:
                labelled = labelled.original_rows()
            if len(labelled) == 0:
                raise ModelError(f"no training rows for the {name} learner")
            getattr(self, name).fit(labelled.X, labelled.y)
        self.mode = data.mode
        self.subjects = sorted(set(data.people.subjects))
        self.start_arm_ = np.median(data.people.y, axis=0)
        self.link_lengths_ = np.median(data.people.X, axis=0)
        return self

    # -- persistence ---------------------------------------------------------------------------

    def _arrays(self) -> dict[str, np.ndarray]:
        arrays = {f"{name}.{key}": np.asarray(value) for name in LEARNERS
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
        meta = {"format": FORMAT, "version": VERSION, "mode": self.mode, "settings": asdict(self.settings),
                "subjects": self.subjects, "sha256": hashlib.sha256(payload).hexdigest()}
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
        models = cls(settings)
        try:
            for name in LEARNERS:
                prefix = f"{name}."
                getattr(models, name).set_state({k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)})
            models.start_arm_ = arrays["priors.start_arm"]
            models.link_lengths_ = arrays["priors.link_lengths"]
        except KeyError as missing:
            raise ModelError(f"{npz_path}: missing array {missing}") from None
        if not all(np.all(np.isfinite(v)) for v in arrays.values() if v.dtype.kind == "f"):
            raise ModelError(f"{npz_path}: non-finite model parameters")
        models.mode = meta.get("mode", "fixed")
        models.subjects = list(meta.get("subjects", []))
        return models

    def describe(self) -> dict[str, Any]:
        return {"mode": self.mode, "subjects": self.subjects, "settings": asdict(self.settings)}
