"""The learners as scikit-learn estimators, and the safe model files."""

from __future__ import annotations

import json
import warnings
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.utils.estimator_checks import check_estimator

from hlp_drake.errors import ModelError
from hlp_drake.features.augment import mirror_features
from hlp_drake.features.row_choice import ROW_CHOICE_FEATURES, ROW_CONTEXT_FEATURES
from hlp_drake.features.training import LabelledSet
from hlp_drake.learners import (
    ArmRegressor,
    DecisionModels,
    DirectionClassifier,
    RbfSvmClassifier,
    RowChoiceClassifier,
    expected_failed_checks,
)
from hlp_drake.learners.bundled import BUNDLED_DIRECTORY, default_models
from hlp_drake.learners.models import PRESETS
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene


def _blobs(n: int = 300, seed: int = 0):
    rng = np.random.default_rng(seed)
    X = np.vstack([rng.normal(0.0, 0.3, (n, 3)), rng.normal(1.0, 0.3, (n // 5, 3))])
    y = np.r_[np.zeros(n), np.ones(n // 5)]
    return X, y


def test_rbf_svm_learns_separable_classes_and_follows_the_estimator_api():
    X, y = _blobs()
    model = RbfSvmClassifier(kernel_scale=1.0)
    assert model.fit(X, y) is model
    assert (model.predict(X) == y).mean() > 0.95
    assert clone(model).get_params() == model.get_params()
    with pytest.raises(ValueError, match="two classes"):
        RbfSvmClassifier().fit(X, np.zeros(len(X)))
    with pytest.raises(ValueError, match="NaN"):
        model.decision_function(np.full((1, 3), np.nan))


def test_svm_decision_function_matches_scikit_learn():
    from sklearn.svm import SVC

    X, y = _blobs()
    model = RbfSvmClassifier(kernel_scale=0.5, balance=False).fit(X, y)
    reference = SVC(C=1.0, gamma=4.0).fit((X - model.mean_) / model.scale_, y)
    assert model.decision_function(X) == pytest.approx(
        reference.decision_function((X - model.mean_) / model.scale_)
    )


@pytest.mark.filterwarnings("error::sklearn.exceptions.ConvergenceWarning")  # every fit converges
def test_direction_classifier_and_arm_regressor_learn():
    rng = np.random.default_rng(1)
    free = rng.uniform(0, 1, (400, 8))
    label = np.argmax(free, axis=1)  # move towards the freest block
    X = np.column_stack([free, rng.integers(0, 8, 400), rng.integers(0, 8, 400)])
    assert (DirectionClassifier(categorical=(8, 9)).fit(X, label).predict(X) == label).mean() > 0.8
    Xa = np.column_stack([rng.uniform(1, 2, (300, 2)), rng.normal(0, 0.3, (300, 2)), rng.integers(0, 8, 300)])
    # Angles measured with noise, as a person's tracked arm is: an exactly linear, noiseless target
    # would drive the GP's noise level to its lower bound and its amplitude to its upper bound (the
    # fit's ConvergenceWarnings), which the real demonstrations never do.
    ya = Xa[:, :2] + 0.5 * Xa[:, 2:4] + rng.normal(0, 0.02, (300, 2))
    arm = ArmRegressor(max_samples=200, categorical=(4,)).fit(Xa, ya)
    assert np.sqrt(((arm.predict(Xa) - ya) ** 2).mean()) < 0.05


def test_bundled_models_load_and_round_trip(tmp_path):
    models = default_models()
    assert models.mode_ == "fixed" and len(models.subjects_) == 24 and models.planner == "rows"
    saved = models.save(tmp_path / "copy")
    again = DecisionModels.load(saved)
    X = np.random.default_rng(0).uniform(0, 3, (5, models.row.n_features_in_))
    assert again.row.predict_proba(X) == pytest.approx(models.row.predict_proba(X))
    assert again.row.novelty(X) == pytest.approx(models.row.novelty(X))


def test_tampered_or_foreign_model_files_are_refused(tmp_path):
    directory = default_models().save(tmp_path / "m")
    npz = directory / "models.npz"
    data = bytearray(npz.read_bytes())
    data[100] ^= 0xFF
    npz.write_bytes(bytes(data))
    with pytest.raises(ModelError, match="checksum mismatch"):
        DecisionModels.load(directory)
    (directory / "models.json").write_text("{not json")
    with pytest.raises(ModelError, match="not a model description"):
        DecisionModels.load(directory)
    (directory / "models.json").write_text(json.dumps({"format": "pickle"}))
    with pytest.raises(ModelError, match="not an hlp_drake model file"):
        DecisionModels.load(directory)
    with pytest.raises(ModelError, match="model file not found"):
        DecisionModels.load(tmp_path / "nowhere")
    assert (BUNDLED_DIRECTORY / "models.json").is_file()


@pytest.mark.parametrize(
    "estimator",
    [
        RowChoiceClassifier(n_estimators=20, novelty_samples=200),
        RowChoiceClassifier(learner="svm", novelty_samples=200),
        RbfSvmClassifier(),
        DirectionClassifier(),
        ArmRegressor(max_samples=200),
    ],
    ids=["row-boosted", "row-svm", "rbf-svm", "direction", "arm"],
)
def test_scikit_learn_conformance(estimator):
    # the estimator declares its known failures and their reasons; each must still fail, nothing else
    expected = expected_failed_checks(estimator)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = check_estimator(estimator, expected_failed_checks=expected, on_fail=None)
    assert len(results) > 40
    failed = {r["check_name"]: repr(r["exception"]) for r in results if r["status"] == "failed"}
    assert failed == {}
    assert {r["check_name"] for r in results if r["status"] == "xfail"} == set(expected)


def test_row_choice_trees_calibration_and_novelty():
    from sklearn.ensemble import GradientBoostingClassifier

    X, y = _blobs(600)
    model = RowChoiceClassifier(n_estimators=50, subsample=1.0).fit(X, y)
    reference = GradientBoostingClassifier(
        n_estimators=50, max_depth=3, learning_rate=0.1, random_state=0
    ).fit(X, y)
    assert model.decision_function(X) == pytest.approx(reference.decision_function(X))  # the trees as arrays
    p = model.predict_proba(X)[:, 1]
    assert (
        abs(p.mean() - y.mean()) < 0.02 and (model.predict(X) == y).mean() > 0.95
    )  # calibrated on held-out folds
    assert np.mean(model.novelty(X) <= 1.0) > 0.97  # the demonstrations lie within their own range
    assert np.all(model.novelty(X[:10] + 10.0) > 1.0)  # far away: outside it
    state = model.get_state()
    again = RowChoiceClassifier(n_estimators=50).set_state(state)
    assert again.predict_proba(X) == pytest.approx(model.predict_proba(X))
    with pytest.raises(NotFittedError):
        RowChoiceClassifier().predict(X)


def _with_row_classifier(width: int, *, row_context: bool) -> DecisionModels:
    """The bundled models with a small row-choice classifier on ``width`` random features, the
    settings saying whether it reads the context."""
    bundled = default_models()
    settings = replace(bundled.settings, n_estimators=5, row_context=row_context)
    models = DecisionModels(settings)
    models.direction, models.arm = bundled.direction, bundled.arm
    models.start_arm_, models.link_lengths_ = bundled.start_arm_, bundled.link_lengths_
    models.subjects_ = bundled.subjects_
    rng = np.random.default_rng(1)
    X = rng.uniform(0.0, 3.0, (200, width))
    models.row = RowChoiceClassifier(n_estimators=5, novelty_samples=50).fit(X, (X[:, 3] < 1.0).astype(float))
    return models


def test_a_row_classifier_with_the_context_saves_loads_and_plans(tmp_path):
    models = _with_row_classifier(len(ROW_CONTEXT_FEATURES), row_context=True)
    again = DecisionModels.load(models.save(tmp_path / "context"))
    assert again.settings.row_context and again.row.n_features_in_ == again.row_features == 31
    result = plan(generate_scene("unstructured", 4), again)
    assert result.reason is None and len(result.keypoints) > 2
    # A file whose classifier reads 27 columns but whose settings say it reads the context: refused.
    wrong = _with_row_classifier(len(ROW_CHOICE_FEATURES), row_context=True).save(tmp_path / "wrong")
    with pytest.raises(ModelError, match="row.novelty.mean"):
        DecisionModels.load(wrong)


def test_mirrored_training_doubles_the_row_examples_with_the_signed_columns_negated(monkeypatch):
    seen = {}

    def fit(self, X, y, sample_weight=None, groups=None):
        seen.update(X=X, y=y, weight=sample_weight, groups=groups)
        raise StopIteration

    monkeypatch.setattr(RowChoiceClassifier, "fit", fit)
    rng = np.random.default_rng(0)
    X = rng.normal(size=(6, len(ROW_CONTEXT_FEATURES)))
    y = np.array([1.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    keys = np.array(["s1/T050"] * 3 + ["s2/T101"] * 3, dtype=object)
    row = LabelledSet(
        ROW_CONTEXT_FEATURES, X, y, np.array(["s1"] * 3 + ["s2"] * 3, dtype=object), keys, y > -1
    )
    data = SimpleNamespace(mode="fixed", row=row)
    settings = replace(PRESETS["boosted"], row_mirror=True)
    with pytest.raises(StopIteration):
        DecisionModels(settings).fit(data)
    assert seen["X"].shape == (12, len(ROW_CHOICE_FEATURES))  # without the context: the first 27
    np.testing.assert_array_equal(seen["X"][6:], mirror_features(X[:, : len(ROW_CHOICE_FEATURES)]))
    assert seen["y"].tolist() == y.tolist() * 2 and seen["groups"].tolist() == row.subjects.tolist() * 2
    assert seen["weight"].tolist() == [0.25] * 3 + [1.0] * 3 + [0.25] * 3 + [1.0] * 3
