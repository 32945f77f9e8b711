"""The human ceiling: how well people predict each other's decisions.

Each held-out person's rows are planned by the other people's choices in the same situation, from
the trials a model of the split learns from (``pool``: the training people's), and scored as any
planner is. Two ways to find the same situation:

- **The same layout**: where pool trials have the held-out trial's very layout (the table, start,
  target and obstacles, named and placed to the millimetre), a row's choice is the consensus of the
  pool's choices at that row. In the VR dataset 30 structured layouts are shared by 16-24 people
  (612 of the 1802 successful structured trials); the other structured trials and every
  unstructured one have a layout of their own.
- **Matched rows** (``match=True``): a row without a shared layout is matched to the nearest row of
  another person with the same candidates (as many gaps and obstacles, in the same order),
  nearest in the row-choice features Xr (``features.row_choice``: every candidate as the person met
  it, from the hand's keypoint at the row before; no left-arm mirroring, since geometry is
  compared), standardised by the pool's candidates; the distance is the root mean square of the
  standardised differences over every candidate and feature. A row is matched when its nearest row
  lies within ``threshold``, chosen on the pool's structured rows alone: the median distance from a
  structured row to its nearest row of another person on another layout. The matched row's choice
  (the candidate at the same place; rows at exactly the nearest distance vote) is the ceiling's.

The consensus of several choices (decision, element): the one the others' choices score highest
under sHLP, which gives a row half for the decision and half more for the element: the largest
n(decision) + n(decision, element). Ties: the larger n(decision, element), then a gap before an
obstacle, then the leftmost (the larger world y). A person agreeing with a unanimous consensus
scores 1. Rows without a shared layout or a match are not scored by the ceiling; the other
planners are scored on the ceiling's rows too, for the comparison on the same rows.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from hlp_drake.dataset.records import STRUCTURED, category_of
from hlp_drake.evaluation.baselines import choice_plan
from hlp_drake.features.row_choice import ROW_CHOICE_FEATURES
from hlp_drake.features.training import row_situations
from hlp_drake.planner.plan import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT, Demonstration
from hlp_drake.taskspace import TaskSpace

Choice = tuple[str, str]
"""A row's choice: ("gap", the gap's index as text) or ("object", the obstacle's name)."""
LAYOUT = "layout"
MATCHED = "matched"


def layout_key(scene: Scene) -> tuple:
    """The scene's layout to the millimetre (table, start, target, named obstacles), not its name."""

    def mm(*values: float) -> tuple[int, ...]:
        return tuple(round(1000.0 * v) for v in values)

    def placed(o) -> tuple:
        return (o.name, o.shape, mm(o.x, o.y, *o.size[:2]), round(1000.0 * o.yaw))

    return (
        mm(scene.table.length, scene.table.width),
        mm(*scene.start),
        placed(scene.target),
        tuple(sorted(placed(o) for o in scene.obstacles)),
    )


def consensus(votes: Iterable[Choice], lateral: Mapping[Choice, float]) -> Choice:
    """The consensus of ``votes`` (at least one): the largest n(decision) + n(decision, element);
    ties: the larger n(decision, element), then a gap before an obstacle, then the larger
    ``lateral`` (world y: further left)."""
    pairs = Counter(votes)
    if not pairs:
        raise ValueError("a consensus needs at least one choice")
    decisions = Counter(decision for decision, _ in pairs.elements())
    return max(
        pairs,
        key=lambda c: (decisions[c[0]] + pairs[c], pairs[c], c[0] == GAP, lateral.get(c, 0.0)),
    )


@dataclass(frozen=True)
class _Row:
    """A pool row as its person met it: whose, on which layout, the candidates' standardised
    features (flattened) and the position of the person's choice."""

    subject: str
    layout: tuple
    structured: bool
    vector: np.ndarray
    chosen: int


@dataclass
class RowMatcher:
    """Nearest rows of other people in the row-choice features (see the module's description).

    Attributes:
        scale: per feature, the pool's candidates' standard deviation (1 where it is 0).
        threshold: a row is matched when its nearest row lies within this distance.
        groups: the pool's rows by their candidates' kinds.
    """

    scale: np.ndarray
    threshold: float
    groups: dict[tuple[str, ...], list[_Row]] = field(default_factory=dict)
    _vectors: dict[tuple[str, ...], np.ndarray] = field(default_factory=dict, repr=False)

    @classmethod
    def of(cls, pool: Sequence[Demonstration]) -> RowMatcher:
        situations = [(demo, row_situations(demo, TaskSpace(demo.scene))) for demo in pool]
        candidates = [c.X[:, : len(ROW_CHOICE_FEATURES)] for _, rows in situations for _, c, _ in rows]
        if not candidates:
            return cls(np.ones(1), 0.0)
        scale = np.std(np.vstack(candidates), axis=0)
        scale[scale <= 1e-12] = 1.0
        matcher = cls(scale, 0.0)
        for demo, rows in situations:
            layout, structured = layout_key(demo.scene), category_of(demo.trial) == STRUCTURED
            for _, c, k in rows:
                row = _Row(demo.subject, layout, structured, matcher._vector(c.X), k)
                matcher.groups.setdefault(tuple(c.kinds), []).append(row)
        matcher._vectors = {k: np.array([r.vector for r in rows]) for k, rows in matcher.groups.items()}
        matcher.threshold = matcher._calibrate()
        return matcher

    def _vector(self, X: np.ndarray) -> np.ndarray:
        return (X[:, : len(ROW_CHOICE_FEATURES)] / self.scale).ravel()

    def _distances(self, kinds: tuple[str, ...], vector: np.ndarray) -> np.ndarray:
        if kinds not in self._vectors:
            return np.zeros(0)
        return np.sqrt(np.mean((self._vectors[kinds] - vector) ** 2, axis=1))

    def _calibrate(self) -> float:
        """The median distance from a structured pool row to its nearest row of another person on
        another layout (0 when there is none)."""
        nearest, index = [], {}
        for kinds, rows in self.groups.items():
            subjects = np.array([r.subject for r in rows], dtype=object)
            layouts = np.array([index.setdefault(r.layout, len(index)) for r in rows])
            for row, layout in zip(rows, layouts):
                if not row.structured:
                    continue
                d = self._distances(kinds, row.vector)
                other = (subjects != row.subject) & (layouts != layout)
                if other.any():
                    nearest.append(float(d[other].min()))
        return float(np.median(nearest)) if nearest else 0.0

    def nearest(self, kinds: tuple[str, ...], X: np.ndarray, subject: str) -> tuple[list[int], float]:
        """The choices (candidate positions) of the nearest rows of people other than ``subject``
        with candidates of ``kinds`` (every row at the nearest distance), and that distance (inf:
        none)."""
        rows = self.groups.get(kinds, [])
        d = self._distances(kinds, self._vector(X))
        d[np.array([r.subject == subject for r in rows], dtype=bool)] = np.inf
        if not len(d) or not np.isfinite(d.min()):
            return [], float("inf")
        best = float(d.min())
        return [rows[i].chosen for i in np.flatnonzero(d <= best + 1e-12)], best


@dataclass
class Ceiling:
    """The others' choices a held-out person's rows are planned by.

    Attributes:
        layouts: per layout (``layout_key``), per row: the (subject, choice) of every pool trial.
        matcher: matches rows without a shared layout (None: only shared layouts count).
    """

    layouts: dict[tuple, dict[int, list[tuple[str, Choice]]]]
    matcher: RowMatcher | None = None

    @classmethod
    def of(cls, pool: Sequence[Demonstration], *, match: bool = False) -> Ceiling:
        """The ceiling from the trials ``pool`` (those a model of the split learns from);
        ``match``: match rows without a shared layout too."""
        layouts: dict[tuple, dict[int, list[tuple[str, Choice]]]] = defaultdict(lambda: defaultdict(list))
        for demo in pool:
            rows = layouts[layout_key(demo.scene)]
            for d in demo.decisions:
                if d.decision != NONE:
                    rows[d.row].append((demo.subject, (d.decision, d.element)))
        return cls({k: dict(v) for k, v in layouts.items()}, RowMatcher.of(pool) if match and pool else None)

    @property
    def threshold(self) -> float | None:
        """The matching threshold (None: no matching)."""
        return self.matcher.threshold if self.matcher is not None else None

    def choices(self, demo: Demonstration) -> dict[int, tuple[Choice, tuple[float, float], str]]:
        """Per row of ``demo`` the others agree on: their choice, its keypoint and how it was found
        (``LAYOUT`` or ``MATCHED``). The person's own trials never vote."""
        space = TaskSpace(demo.scene)
        centres = {(OBJECT, n): space.rects[n].center for n in space.obstacle_names}
        centres.update({(GAP, str(g.index)): g.center for gaps in space.gaps for g in gaps})
        lateral = {c: float(p[1]) for c, p in centres.items()}
        shared = self.layouts.get(layout_key(demo.scene), {})
        result = {}
        for d in demo.decisions:
            votes = [c for subject, c in shared.get(d.row, []) if subject != demo.subject and c in centres]
            if d.decision != NONE and votes:
                choice = consensus(votes, lateral)
                result[d.row] = (choice, centres[choice], LAYOUT)
        if self.matcher is None:
            return result
        names = space.obstacle_names
        for decision, candidates, _ in row_situations(demo, space):
            if decision.row in result:
                continue
            chosen, distance = self.matcher.nearest(tuple(candidates.kinds), candidates.X, demo.subject)
            if distance > self.matcher.threshold:
                continue
            options = {k: (candidates.kinds[k], candidates.element(k, names)) for k in chosen}
            side = {options[k]: float(candidates.points[k][1]) for k in chosen}
            choice = consensus([options[k] for k in chosen], side)
            k = next(k for k in chosen if options[k] == choice)
            result[decision.row] = (choice, tuple(float(v) for v in candidates.points[k]), MATCHED)
        return result

    def plan(self, demo: Demonstration) -> tuple[HighLevelPlan, dict[int, str]]:
        """The plan of the others' choices for ``demo``'s scene (rows without one are left out), and
        how each row's choice was found."""
        choices = self.choices(demo)
        plan = choice_plan(
            demo.scene,
            TaskSpace(demo.scene),
            [(row, c[0], c[1], position) for row, (c, position, _) in sorted(choices.items())],
        )
        return plan, {row: how for row, (_, _, how) in choices.items()}
