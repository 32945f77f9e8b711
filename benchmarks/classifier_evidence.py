"""How often the bundled gap and obstacle classifiers (Cg, Co) know nothing about a scene's candidates.

    python benchmarks/classifier_evidence.py [--scenes 30] [--json OUT]

An RBF SVM scores a case far from every demonstration with its intercept alone; the planner treats
a score within ``PlannerConfig.min_evidence`` of the intercept as no evidence. Per scene kind
(generated VR, Generalization I, Generalization II with 5, 7 and 9 objects; seeds 0..N-1) this
prints the share of gap and obstacle candidates without evidence and the median |score - intercept|.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from hlp_drake.features import gap_features, object_features
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import PlannerConfig
from hlp_drake.planner.candidates import informed
from hlp_drake.scene.generators import generate_scene
from hlp_drake.taskspace import TaskSpace

KINDS = (("vr", None), ("gen1", None), ("gen2", 5), ("gen2", 7), ("gen2", 9))


def evidence(kind: str, objects: int | None, scenes: int, min_evidence: float) -> dict[str, float]:
    """Share of candidates without evidence and median |score - intercept|, for gaps and obstacles."""
    models = default_models()
    margins: dict[str, list[np.ndarray]] = {"gap": [], "object": []}
    for seed in range(scenes):
        space = TaskSpace(generate_scene(kind, seed, objects))
        margins["gap"].append(models.gap.decision_function(gap_features(space)) - models.gap.intercept_)
        margins["object"].append(models.object.decision_function(object_features(space)) - models.object.intercept_)
    out: dict[str, float] = {}
    for name, parts in margins.items():
        values = np.concatenate(parts)
        out[f"{name}_no_evidence"] = float(np.mean(~informed(values, 0.0, min_evidence)))
        out[f"{name}_median_margin"] = float(np.median(np.abs(values)))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=30, help="seeds 0..N-1 per kind")
    parser.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args()
    min_evidence = PlannerConfig().min_evidence
    results = {}
    print(f"{'scenes':<12} {'gaps w/o evidence':>18} {'median':>8} {'obstacles w/o evidence':>23} {'median':>8}")
    for kind, objects in KINDS:
        label = kind if objects is None else f"{kind}-{objects}"
        row = results[label] = evidence(kind, objects, args.scenes, min_evidence)
        print(f"{label:<12} {row['gap_no_evidence']:>18.0%} {row['gap_median_margin']:>8.3f} "
              f"{row['object_no_evidence']:>23.0%} {row['object_median_margin']:>8.3f}")
    if args.json:
        args.json.write_text(json.dumps({"scenes": args.scenes, "min_evidence": min_evidence, **results}, indent=2))


if __name__ == "__main__":
    main()
