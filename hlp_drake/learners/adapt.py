"""Adapting trained decision models to one person: the prior's row-choice trees, boosted on.

The row-choice classifier Cr of the default models is a sum of boosted trees on the candidates'
features, turned into a probability by a Platt calibration: p = expit(a * F(x) + b). Adapting
starts from those models (the prior, trained on the 24 people of the VR study) and can add, fitted
to the person's own choices: first the person's bias (one tree of depth 1 on the candidate's kind:
a logit offset for gaps and one for obstacles, the ridge-regularised log-loss optimum from the
prior's logits; people differ most in how often they move an obstacle), then a few shallow trees
by the same log-loss boosting, each a Newton step from where the prior and the trees before it left
the person's candidates. Which (``CHOICES``: the prior, with or without the bias, with 0 to 40
trees) is chosen by cross-validation on the person's own trials only (folds of whole trials): the
choice whose held-out rows the classifier chooses best, scored per row as sHLP scores a row (the
decision, then the element); a tie goes to the simpler choice, so the prior stands unless the
person's trials show it should move.

The direction classifier Cd and the arm regressor Ra are the prior's; the arm priors (the start
arm and the link lengths) become the person's own medians. The result is ordinary
``DecisionModels`` (``models.json`` + ``models.npz``): the added trees are more trees of the same
arrays, the settings' ``n_estimators`` counting them.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace
from types import SimpleNamespace

import numpy as np
from scipy.special import expit
from sklearn.model_selection import GroupKFold
from sklearn.tree import DecisionTreeRegressor

from hlp_drake.errors import ModelError
from hlp_drake.features.training import row_choice_rows
from hlp_drake.learners.models import DecisionModels
from hlp_drake.learners.trees import LEAF, BoostedTrees
from hlp_drake.segmentation.demonstration import Demonstration
from hlp_drake.segmentation.person_file import StatedTrial
from hlp_drake.taskspace import TaskSpace

MIN_TRIALS = 5
"""Fewest usable trials of a person that models are adapted on (fewer: refused)."""
TREE_CHOICES = (0, 5, 10, 20, 40)
"""The numbers of added trees the person's cross-validation chooses from."""
CHOICES = tuple(
    sorted(((bias, n) for bias in (False, True) for n in TREE_CHOICES), key=lambda c: (c[1], c[0]))
)
"""(the person's kind bias first, trees added after it) choices, simplest first ((False, 0): the prior)."""
BIAS_L2 = 1.0
"""Ridge on each of the kind bias's two offsets (logit units)."""
BIAS_STEPS = 20
"""Newton steps of the kind bias (to convergence)."""
TREE_DEPTH = 2
"""Depth of each added tree."""
LEARNING_RATE = 0.1
"""Shrinkage of each added tree's Newton step."""
L2 = 1.0
"""Ridge on each leaf's Newton step (a leaf of few rows moves little)."""
MIN_LEAF = 5
"""Fewest candidates in a leaf of an added tree."""
MAX_FOLDS = 10
"""Most folds of the person's cross-validation (leave one trial out up to this many trials)."""


@dataclass(frozen=True)
class PersonRows:
    """The row choices of one person's trials: per scored row its candidates' features and which
    candidate the person took, and the trial it came from."""

    X: list[np.ndarray]
    taken: list[int]
    trials: list[str]

    @classmethod
    def of(cls, demonstrations: list[Demonstration | StatedTrial], n_features: int) -> PersonRows:
        """The rows of ``demonstrations``, each candidate's first ``n_features`` of Xr."""
        X, taken, trials = [], [], []
        for demo in demonstrations:
            for features, labels in row_choice_rows(demo, TaskSpace(demo.scene)):
                X.append(features[:, :n_features])
                taken.append(int(np.argmax(labels)))
                trials.append(demo.key)
        return cls(X, taken, trials)

    def __len__(self) -> int:
        return len(self.X)

    def select(self, rows: np.ndarray) -> PersonRows:
        return PersonRows(
            [self.X[i] for i in rows], [self.taken[i] for i in rows], [self.trials[i] for i in rows]
        )

    def stacked(self) -> tuple[np.ndarray, np.ndarray]:
        """All candidates (n, k) and their 0/1 labels (n,)."""
        y = [np.arange(len(x)) == t for x, t in zip(self.X, self.taken)]
        return np.vstack(self.X), np.concatenate(y).astype(float)


@dataclass(frozen=True)
class Adaptation:
    """What adapting did: the person, their trials and rows, the trees added (after the kind bias
    if ``bias``), and the cross-validated per-row score (sHLP's row score) of each choice tried
    (``choice_name``)."""

    person: str
    trials: int
    rows: int
    trees: int
    folds: int
    scores: dict[str, float]
    bias: bool = False


def row_score(p: np.ndarray, taken: int, is_object: np.ndarray) -> float:
    """sHLP's score of one row from Cr's probabilities ``p`` of its candidates: I(D) * (I(D) + I(E)) / 2,
    I(D) the kind (gap or object) of the most likely candidate being the person's, I(E) the person's
    candidate the only one above one half (the evaluation's raw labels) once ``p`` is normalised."""
    p = p / max(float(p.sum()), 1e-300)
    best = int(np.argmax(p))
    decision = int(is_object[best] == is_object[taken])
    element = int(best == taken and p[taken] > 0.5)
    return decision * (decision + element) / 2.0


def _calibrated_logit(models: DecisionModels, X: np.ndarray) -> np.ndarray:
    a, b = models.row.calibration_
    return a * models.row.decision_function(X) + b


def _boost(z: np.ndarray, X: np.ndarray, y: np.ndarray, trees: int, seed: int) -> list[tuple]:
    """``trees`` log-loss boosting steps from the logits ``z``: per tree the fitted regressor and
    its leaves' values (in logit units)."""
    z = z.copy()
    fitted = []
    for k in range(trees):
        p = expit(z)
        residual = y - p
        tree = DecisionTreeRegressor(max_depth=TREE_DEPTH, min_samples_leaf=MIN_LEAF, random_state=seed + k)
        tree.fit(X, residual)
        leaves = tree.apply(X)
        values = np.zeros(tree.tree_.node_count)
        for leaf in np.unique(leaves):
            mask = leaves == leaf
            hessian = float(np.sum(p[mask] * (1.0 - p[mask])))
            values[leaf] = LEARNING_RATE * float(residual[mask].sum()) / (hessian + L2)
        z += values[leaves]
        fitted.append((tree, values))
    return fitted


class _KindStump:
    """A tree of depth 1 on the candidate's kind (column 0 of Xr: an obstacle), laid out as a
    fitted ``DecisionTreeRegressor``'s: node 1 the gaps, node 2 the obstacles."""

    tree_ = SimpleNamespace(
        feature=np.array([0, -2, -2]),
        threshold=np.array([0.5, -2.0, -2.0]),
        children_left=np.array([1, LEAF, LEAF]),
        children_right=np.array([2, LEAF, LEAF]),
        node_count=3,
    )

    def apply(self, X: np.ndarray) -> np.ndarray:
        return np.where(X[:, 0] <= 0.5, 1, 2)

    def get_depth(self) -> int:
        return 1


def _kind_bias(z: np.ndarray, X: np.ndarray, y: np.ndarray) -> tuple[_KindStump, np.ndarray]:
    """The person's bias from the logits ``z``: a logit offset for gaps and one for obstacles,
    minimising the log loss plus ``BIAS_L2`` / 2 times each offset squared (Newton steps)."""
    stump = _KindStump()
    leaves = stump.apply(X)
    values = np.zeros(3)
    for _ in range(BIAS_STEPS):
        p = expit(z + values[leaves])
        for leaf in (1, 2):
            mask = leaves == leaf
            gradient = float(np.sum(y[mask] - p[mask])) - BIAS_L2 * values[leaf]
            values[leaf] += gradient / (float(np.sum(p[mask] * (1.0 - p[mask]))) + BIAS_L2)
    return stump, values


def _fitted(z: np.ndarray, X: np.ndarray, y: np.ndarray, bias: bool, trees: int, seed: int) -> list[tuple]:
    """The added trees of a choice: the kind bias (if ``bias``), then ``trees`` boosted trees."""
    fitted = [_kind_bias(z, X, y)] if bias else []
    return fitted + _boost(_logits_after(z, X, fitted), X, y, trees, seed)


def choice_name(bias: bool, trees: int) -> str:
    """How a choice of ``CHOICES`` is shown: "prior", "bias", "5 trees", "bias + 5 trees"."""
    parts = (["bias"] if bias else []) + ([f"{trees} trees"] if trees else [])
    return " + ".join(parts) or "prior"


def _logits_after(z: np.ndarray, X: np.ndarray, fitted: list[tuple]) -> np.ndarray:
    return z + sum((values[tree.apply(X)] for tree, values in fitted), np.zeros(len(X)))


def _cross_validated(models: DecisionModels, rows: PersonRows, seed: int) -> tuple[dict[tuple, float], int]:
    """Mean row score of each of ``CHOICES`` over folds of the person's trials, and the folds."""
    trials = np.array(rows.trials)
    folds = min(MAX_FOLDS, len(set(rows.trials)))
    totals = {choice: [] for choice in CHOICES}
    for train, test in GroupKFold(n_splits=folds).split(trials, groups=trials):
        X, y = rows.select(train).stacked()
        held = rows.select(test)
        Xt, _ = held.stacked()
        z, zt = _calibrated_logit(models, X), _calibrated_logit(models, Xt)
        for bias in (False, True):
            fitted = _fitted(z, X, y, bias, max(TREE_CHOICES), seed)
            for n in TREE_CHOICES:
                p = expit(_logits_after(zt, Xt, fitted[: n + bias]))
                start = 0
                for x, taken in zip(held.X, held.taken):
                    totals[bias, n].append(row_score(p[start : start + len(x)], taken, x[:, 0] > 0.5))
                    start += len(x)
    return {choice: float(np.mean(v)) for choice, v in totals.items()}, folds


def _appended(arrays: dict[str, np.ndarray], fitted: list[tuple], scale: float) -> dict[str, np.ndarray]:
    """The boosted-tree arrays with the ``fitted`` trees appended (their logit values divided by
    the calibration's slope ``scale``, so they add to the raw score)."""
    nodes = max([arrays["feature"].shape[1], *(tree.tree_.node_count for tree, _ in fitted)])
    out = {}
    for name, fill in (("feature", 0), ("threshold", 0.0), ("left", LEAF), ("right", LEAF), ("value", 0.0)):
        old = arrays[name]
        padded = np.full((old.shape[0] + len(fitted), nodes), fill, dtype=old.dtype)
        padded[: old.shape[0], : old.shape[1]] = old
        for k, (tree, values) in enumerate(fitted):
            t, n, row = tree.tree_, tree.tree_.node_count, old.shape[0] + k
            padded[row, :n] = {
                "feature": np.maximum(t.feature, 0),
                "threshold": t.threshold,
                "left": t.children_left,
                "right": t.children_right,
                "value": values / scale,
            }[name]
        out[name] = padded
    depth = max([int(arrays["depth"]), *(tree.get_depth() for tree, _ in fitted)])
    out["depth"] = np.array(depth, dtype=arrays["depth"].dtype)
    out["offset"] = arrays["offset"]
    return out


def adapt_models(
    prior: DecisionModels,
    demonstrations: list[Demonstration | StatedTrial],
    *,
    person: str = "",
    seed: int = 0,
    trees: int | None = None,
) -> tuple[DecisionModels, Adaptation]:
    """``prior`` adapted to the person of ``demonstrations`` (fixed-mode, at least ``MIN_TRIALS``).

    Args:
        trees: add this many trees instead of the number the cross-validation chooses (a
            diagnostic: how far the trees can move the prior towards these trials).

    Raises:
        ModelError: the prior is not the row-by-row planner's with boosted trees, or too few trials.
    """
    if prior.planner != "rows" or prior.settings.row_learner != "boosted":
        raise ModelError(
            "adapting continues the row-choice classifier's boosted trees: the base models must be "
            f"the boosted preset's (these are the {prior.planner} planner's with the "
            f"{prior.settings.row_learner} row learner)"
        )
    trials = sorted({d.key for d in demonstrations})
    if len(trials) < MIN_TRIALS:
        raise ModelError(
            f"{len(trials)} usable trial(s) of {person or 'the person'}; adapting needs at least {MIN_TRIALS}"
        )
    rows = PersonRows.of(list(demonstrations), prior.row_features)
    if len(set(rows.trials)) < MIN_TRIALS:
        raise ModelError(
            f"{len(set(rows.trials))} of {person or 'the person'}'s trials have a row choice to learn from; "
            f"adapting needs at least {MIN_TRIALS}"
        )
    if trees is None:
        scores, folds = _cross_validated(prior, rows, seed)
        bias, best = max(CHOICES, key=lambda c: (round(scores[c], 9), -CHOICES.index(c)))
    else:
        scores, folds, bias, best = {}, 0, False, trees
    X, y = rows.stacked()
    fitted = _fitted(_calibrated_logit(prior, X), X, y, bias, best, seed)
    models = copy.deepcopy(prior)
    a = float(prior.row.calibration_[0])
    if fitted:
        if a <= 0:
            raise ModelError("the base models' row calibration is not increasing: cannot adapt them")
        arrays = _appended(prior.row._learner_.arrays, fitted, a)
        models.row._learner_ = BoostedTrees(arrays)
        models.settings = replace(
            prior.settings,
            n_estimators=prior.settings.n_estimators + len(fitted),
            max_depth=max(prior.settings.max_depth, int(arrays["depth"])),
        )
        models.row.n_estimators = models.settings.n_estimators
    recorded = [d for d in demonstrations if isinstance(d, Demonstration)]  # a stated trial has no arm
    if recorded:
        models.start_arm_ = np.median([d.keypoints[0].arm for d in recorded], axis=0)
        models.link_lengths_ = np.median(
            [(d.link_lengths.upper_arm, d.link_lengths.forearm) for d in recorded], axis=0
        )
    if person and person not in models.subjects_:
        models.subjects_ = [*models.subjects_, person]
    named = {choice_name(*choice): score for choice, score in scores.items()}
    return models, Adaptation(person, len(trials), len(rows), best, folds, named, bias)
