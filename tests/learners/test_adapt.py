"""Adapting the prior to one person (``learners.adapt``): the added trees, their file, the refusals."""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pytest

from hlp_drake.errors import ModelError
from hlp_drake.features.row_choice import ROW_CHOICE_FEATURES
from hlp_drake.learners import PRESETS, DecisionModels
from hlp_drake.learners.adapt import (
    CHOICES,
    MIN_TRIALS,
    _appended,
    _boost,
    _calibrated_logit,
    _fitted,
    _kind_bias,
    _logits_after,
    adapt_models,
    choice_name,
    row_score,
)
from hlp_drake.learners.bundled import default_models
from hlp_drake.learners.trees import BoostedTrees


def _candidates(n: int = 200, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    X = rng.uniform(0.0, 1.0, (n, len(ROW_CHOICE_FEATURES)))
    X[:, 0] = rng.integers(0, 2, n)  # the candidate is an obstacle
    return X, (X[:, 0] > 0.5).astype(float)  # this person always moves an obstacle


def test_added_trees_add_their_steps_to_the_calibrated_score_and_move_it_towards_the_person():
    prior = default_models()
    X, y = _candidates()
    z = _calibrated_logit(prior, X)
    fitted = _boost(z, X, y, 10, seed=0)
    a, b = prior.row.calibration_
    arrays = _appended(prior.row._learner_.arrays, fitted, float(a))
    assert arrays["feature"].shape[0] == prior.settings.n_estimators + 10
    adapted = a * BoostedTrees(arrays).decision_function(X) + b
    np.testing.assert_allclose(adapted, _logits_after(z, X, fitted), atol=1e-6)
    loss = lambda logits: np.mean(np.logaddexp(0.0, logits) - y * logits)
    assert loss(adapted) < loss(z) - 0.01


def test_adapted_models_save_and_load_as_the_usual_format(tmp_path):
    prior = default_models()
    X, y = _candidates()
    fitted = _boost(_calibrated_logit(prior, X), X, y, 5, seed=0)
    models = copy.deepcopy(prior)
    models.row._learner_ = BoostedTrees(
        _appended(prior.row._learner_.arrays, fitted, float(prior.row.calibration_[0]))
    )
    models.settings = replace(prior.settings, n_estimators=prior.settings.n_estimators + 5)
    models.save(tmp_path)
    loaded = DecisionModels.load(tmp_path)
    assert loaded.settings.n_estimators == prior.settings.n_estimators + 5
    np.testing.assert_allclose(loaded.row.predict_proba(X), models.row.predict_proba(X))
    assert not np.allclose(loaded.row.predict_proba(X), prior.row.predict_proba(X))


@pytest.mark.parametrize(
    ("p", "taken", "score"),
    [
        ([0.7, 0.2, 0.1], 0, 1.0),  # the person's candidate, above one half
        ([0.4, 0.35, 0.25], 0, 0.5),  # the person's, but not above one half: the decision only
        ([0.2, 0.7, 0.1], 0, 0.5),  # another gap: the decision (a gap) is right
        ([0.1, 0.2, 0.7], 0, 0.0),  # the obstacle: the wrong decision
    ],
)
def test_the_row_score_is_shlps_of_the_row(p, taken, score):
    is_object = np.array([False, False, True])
    assert row_score(np.array(p), taken, is_object) == score


def test_only_boosted_row_models_are_adapted():
    with pytest.raises(ModelError, match="the base models must be the boosted preset's"):
        adapt_models(DecisionModels(PRESETS["svm"]), [])


def test_fewer_than_the_minimum_of_trials_are_refused():
    with pytest.raises(ModelError) as error:
        adapt_models(default_models(), [], person="sub_99")
    assert error.value.problems == (f"0 usable trial(s) of sub_99; adapting needs at least {MIN_TRIALS}",)


def test_the_kind_bias_moves_a_person_who_always_moves_obstacles_towards_obstacles(tmp_path):
    prior = default_models()
    X, y = _candidates()
    z = _calibrated_logit(prior, X)
    stump, values = _kind_bias(z, X, y)
    assert values[2] > 0.5 and values[1] < -0.5  # obstacles up, gaps down, in logit units
    loss = lambda logits: np.mean(np.logaddexp(0.0, logits) - y * logits)
    biased = _logits_after(z, X, [(stump, values)])
    assert loss(biased) < loss(z) - 0.05
    np.testing.assert_allclose(biased - z, np.where(X[:, 0] > 0.5, values[2], values[1]))
    # in the model file: one more tree of depth 1, the same logits once loaded
    fitted = _fitted(z, X, y, True, 5, seed=0)
    models = copy.deepcopy(prior)
    a, b = prior.row.calibration_
    models.row._learner_ = BoostedTrees(_appended(prior.row._learner_.arrays, fitted, float(a)))
    models.settings = replace(prior.settings, n_estimators=prior.settings.n_estimators + len(fitted))
    models.save(tmp_path)
    loaded = DecisionModels.load(tmp_path)
    np.testing.assert_allclose(
        a * loaded.row._learner_.decision_function(X) + b, _logits_after(z, X, fitted), atol=1e-6
    )


def test_the_choices_run_from_the_prior_to_the_most_trees_and_are_named():
    assert CHOICES[0] == (False, 0) and CHOICES[1] == (True, 0) and CHOICES[-1] == (True, 40)
    names = [choice_name(*c) for c in CHOICES]
    assert names[:4] == ["prior", "bias", "5 trees", "bias + 5 trees"] and len(set(names)) == len(names)
