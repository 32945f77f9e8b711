"""How often the bundled decision models know something about a scene's candidates, per scene kind.

    python benchmarks/classifier_evidence.py [--scenes 30] [--models DIR] [--json OUT]

Row-by-row models (the default presets): a candidate carries evidence when its row-choice
features lie within the demonstrations' range (``RowChoiceClassifier.novelty`` <= 1); counted over
every candidate the planner scores on its chosen way (the rows' gaps and obstacles as the hand
meets them). Paper-preset models: an RBF SVM scores a case far from every demonstration with its
intercept alone; a gap or obstacle score within ``PlannerConfig.min_evidence`` of it carries none.
Per kind (generated VR and unstructured scenes, Generalization I, Generalization II with 5, 7 and
9 objects; seeds 0..N-1) this prints the share of candidates with evidence.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from hlp_drake.commands.parsing import run_cli
from hlp_drake.features import gap_features, object_features
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.learners import DecisionModels
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import PlannerConfig, plan
from hlp_drake.planner.candidates import informed
from hlp_drake.scene.generators import generate_scene
from hlp_drake.taskspace import TaskSpace

KINDS = (("vr", None), ("unstructured", None), ("gen1", None), ("gen2", 5), ("gen2", 7), ("gen2", 9))


def row_evidence(models: DecisionModels, kind: str, objects: int | None, scenes: int) -> dict[str, float]:
    """Share of the chosen way's candidates (and rows) with evidence, and the median novelty."""
    novelty, rows = [], []
    for seed in range(scenes):
        result = plan(generate_scene(kind, seed, objects), models)
        for values in result.details["novelty"].values():
            novelty += values
            rows.append(min(values, default=np.inf) <= 1.0)
    novelty = np.array(novelty)
    return {
        "candidates": len(novelty),
        "with_evidence": float(np.mean(novelty <= 1.0)),
        "rows_with_evidence": float(np.mean(rows)),
        "median_novelty": float(np.median(novelty)),
    }


def paper_evidence(models: DecisionModels, kind: str, objects: int | None, scenes: int) -> dict[str, float]:
    """Share of gap and obstacle candidates whose Cg/Co score carries evidence."""
    min_evidence = PlannerConfig().min_evidence
    margins: dict[str, list[np.ndarray]] = {"gap": [], "object": []}
    for seed in range(scenes):
        space = TaskSpace(generate_scene(kind, seed, objects))
        margins["gap"].append(models.gap.decision_function(gap_features(space)) - models.gap.intercept_)
        margins["object"].append(
            models.object.decision_function(object_features(space)) - models.object.intercept_
        )
    values = np.concatenate(margins["gap"] + margins["object"])
    out = {"candidates": len(values), "with_evidence": float(np.mean(informed(values, 0.0, min_evidence)))}
    for name, parts in margins.items():
        out[f"{name}_with_evidence"] = float(np.mean(informed(np.concatenate(parts), 0.0, min_evidence)))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=30, help="seeds 0..N-1 per kind")
    parser.add_argument("--models", help="a model directory (default: the bundled models)")
    parser.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args()
    check_writable(args.json)
    models = DecisionModels.load(args.models) if args.models else default_models()
    measure = row_evidence if models.planner == "rows" else paper_evidence
    results = {}
    print(
        f"{models.planner} planner's models ({models.settings.row_learner if models.planner == 'rows' else 'paper'})"
    )
    print(f"{'scenes':<14} {'candidates':>10} {'with evidence':>14}")
    for kind, objects in KINDS:
        label = kind if objects is None else f"{kind}-{objects}"
        row = results[label] = measure(models, kind, objects, args.scenes)
        print(f"{label:<14} {row['candidates']:>10d} {row['with_evidence']:>14.1%}")
    if args.json:
        write_text_atomic(
            args.json,
            json.dumps({"scenes": args.scenes, "planner": models.planner, **results}, indent=2) + "\n",
        )


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
