"""Adapting the prior to one person, measured leave one person out: sHLP on their held-out trials.

    python benchmarks/adapt_person.py [--dataset PATH] [--out DIR] [--ks 5 10 20] [--seed 0]
        [--subjects sub_01 ...]

For each participant: the pooled models are trained on everyone else's successful structured and
unstructured trials (the default preset, as ``python -m hlp_drake.train``; the arm regressor Ra is
the bundled one, which saw everyone: it only breaks ties between equally likely plans, and the
pooled and adapted models share it). The participant's successful trials are shuffled (seed
``--seed`` and the participant); the first ``max(ks)`` are their demonstrations, the rest their
held-out trials, the same for every k. The models adapted on the first k demonstrations
(``learners.adapt``: the person's bias and the added trees chosen by cross-validation on those k trials
only) and the pooled models plan each held-out trial's scene; sHLP scores each plan against the
person (as ``python -m hlp_drake.evaluate`` does). Nothing is tuned on the held-out trials.

Beside them, two in-sample ceilings on the same trials (diagnostics, not results): the bundled
models (trained on everyone, the scored trials too), and the pooled models with 40 trees boosted
on the scored trials themselves: how far the learner and the added trees get when they have seen
the answers.

Writes ``DIR/adapt_person.json`` (per participant and k; the means over participants) and
``DIR/adapt_person.png``; the pooled models of each participant are kept in ``DIR/pooled/`` so a
rerun goes on where it stopped. One process.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from hlp_drake.commands.parsing import run_cli
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED
from hlp_drake.evaluation.protocol import _majority, score_plans
from hlp_drake.features import training_data
from hlp_drake.files.atomic import write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.learners import PRESETS, DecisionModels
from hlp_drake.learners.adapt import adapt_models
from hlp_drake.learners.bundled import default_models
from hlp_drake.segmentation import segment_dataset

CEILINGS = {
    "in_sample": "in sample: the bundled models, trained on the scored trials too",
    "self_fit": "in sample: the pooled models with 40 trees boosted on the scored trials",
}
SELF_FIT_TREES = 40
"""Trees of the self-fit ceiling (the most the cross-validation may choose)."""


def without(subject: str):
    """Which trials (keys) are not ``subject``'s."""
    return lambda key: not key.startswith(subject + "/")


def pooled_models(data, subject: str, folder: Path) -> DecisionModels:
    """The default preset's Cr and Cd fitted without ``subject`` (kept in ``folder``), Ra bundled."""
    if (folder / "models.json").is_file():
        return DecisionModels.load(folder)
    models = DecisionModels(PRESETS["boosted"])
    models.arm = default_models().arm
    models.fit(data.where(without(subject)), only=("row", "direction"))
    models.save(folder)
    return models


def shlp(models: DecisionModels, demonstrations, majority: str) -> list[float]:
    outcomes = score_plans(models, demonstrations, majority)[0]
    return [o.shlp for o in outcomes]


def _ceilings(record: dict, folder: Path, held_out, data, subject: str) -> dict:
    """In-sample ceilings on the held-out trials (diagnostics, not results): ``in_sample``, the
    bundled models, which learnt from everyone's trials, these too (the pooled learner having seen
    the very trials it is scored on); ``self_fit``, the pooled models with ``SELF_FIT_TREES`` trees
    boosted on the held-out trials themselves (how far the added trees can move the prior towards
    this person's choices, given every answer)."""
    out = {}
    majority = _majority(data.where(without(subject)))
    if "in_sample" not in record:
        out["in_sample"] = float(np.mean(shlp(default_models(), held_out, majority)))
    if "self_fit" not in record:
        fitted, _ = adapt_models(DecisionModels.load(folder), held_out, person=subject, trees=SELF_FIT_TREES)
        out["self_fit"] = float(np.mean(shlp(fitted, held_out, majority)))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", help="the dataset (default: HLP_DATASET, else ../shared/data)")
    parser.add_argument("--out", type=Path, default=Path("benchmark-results"), help="output folder")
    parser.add_argument("--ks", type=int, nargs="+", default=[5, 10, 20], help="demonstrations adapted on")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--subjects", nargs="+", help="the held-out participants (default: all)")
    args = parser.parse_args()
    args.out.mkdir(exist_ok=True)
    report_path = args.out / "adapt_person.json"
    done = json.loads(report_path.read_text())["participants"] if report_path.is_file() else {}
    dataset = Dataset(args.dataset, progress=False)
    demonstrations = segment_dataset(
        dataset, mode="fixed", categories=(STRUCTURED, UNSTRUCTURED)
    ).demonstrations
    data = training_data(demonstrations, mode="fixed")
    subjects = args.subjects or sorted({d.subject for d in demonstrations})
    n_demos = max(args.ks)
    for index, subject in enumerate(subjects):
        started = time.perf_counter()
        own = sorted((d for d in demonstrations if d.subject == subject), key=lambda d: d.key)
        order = np.random.default_rng([args.seed, int(subject.split("_")[1])]).permutation(len(own))
        shown, held_out = [own[i] for i in order[:n_demos]], [own[i] for i in order[n_demos:]]
        if subject in done:
            done[subject].update(
                _ceilings(done[subject], args.out / "pooled" / subject, held_out, data, subject)
            )
            continue
        pooled = pooled_models(data, subject, args.out / "pooled" / subject)
        majority = _majority(data.where(without(subject)))
        base = shlp(pooled, held_out, majority)
        record = {"trials": len(own), "held_out": len(held_out), "pooled": float(np.mean(base)), "k": {}}
        record.update(_ceilings(record, args.out / "pooled" / subject, held_out, data, subject))
        for k in args.ks:
            adapted, adaptation = adapt_models(pooled, shown[:k], person=subject, seed=args.seed)
            scores = shlp(adapted, held_out, majority)
            record["k"][str(k)] = {
                "adapted": float(np.mean(scores)),
                "trees": adaptation.trees,
                "bias": adaptation.bias,
                "cv_row_score": adaptation.scores,
            }
        done[subject] = record
        gains = ", ".join(f"k={k} {record['k'][str(k)]['adapted']:.3f}" for k in args.ks)
        print(
            f"[{index + 1}/{len(subjects)}] {subject}: {len(held_out)} held out, pooled {record['pooled']:.3f}, "
            f"adapted {gains} ({time.perf_counter() - started:.0f} s)",
            flush=True,
        )
        write_text_atomic(report_path, json.dumps(_report(done, args), indent=2) + "\n")
        _plot(_report(done, args), args.out / "adapt_person.png")  # a stopped run keeps its chart
    report = _report(done, args)
    write_text_atomic(report_path, json.dumps(report, indent=2) + "\n")
    _plot(report, args.out / "adapt_person.png")
    for k, row in report["summary"].items():
        if k in CEILINGS:
            print(
                f"{CEILINGS[k]}: {row['shlp']:.3f} (pooled {row['pooled']:.3f}, {row['participants']} participants)"
            )
            continue
        print(
            f"k={k}: pooled {row['pooled']:.3f}, adapted {row['adapted']:.3f}, gain {row['gain']:+.3f} "
            f"(SE {row['gain_se']:.3f}; {row['improved']} better, {row['worse']} worse of {row['participants']})"
        )
    print(f"wrote {report_path} and {args.out / 'adapt_person.png'}")
    return 0


def _report(done: dict, args) -> dict:
    summary = {}
    for k in args.ks:
        rows = [(r["pooled"], r["k"][str(k)]["adapted"]) for r in done.values() if str(k) in r["k"]]
        if not rows:
            continue
        pooled, adapted = np.array(rows).T
        gain = adapted - pooled
        summary[str(k)] = {
            "participants": len(rows),
            "pooled": float(pooled.mean()),
            "adapted": float(adapted.mean()),
            "gain": float(gain.mean()),
            "gain_se": float(gain.std(ddof=1) / np.sqrt(len(gain))) if len(gain) > 1 else 0.0,
            "improved": int(np.sum(gain > 1e-9)),
            "worse": int(np.sum(gain < -1e-9)),
            "trees_median": float(np.median([r["k"][str(k)]["trees"] for r in done.values()])),
            "bias_chosen": sum(bool(r["k"][str(k)].get("bias")) for r in done.values()),
        }
    for name in ("in_sample", "self_fit"):
        ceiling = [r[name] for r in done.values() if name in r]
        if ceiling:
            summary[name] = {
                "participants": len(ceiling),
                "shlp": float(np.mean(ceiling)),
                "pooled": float(np.mean([r["pooled"] for r in done.values() if name in r])),
            }
    return {
        "protocol": "leave one person out; adapted on k of the person's trials, scored on the rest",
        "seed": args.seed,
        "ks": args.ks,
        "summary": summary,
        "participants": done,
    }


def _plot(report: dict, path: Path) -> None:
    figure, axes = new_figure(6.0, 4.0)
    ks = [k for k in report["summary"] if k not in CEILINGS]
    pooled = [report["summary"][k]["pooled"] for k in ks]
    adapted = [report["summary"][k]["adapted"] for k in ks]
    errors = [report["summary"][k]["gain_se"] for k in ks]
    x = np.arange(len(ks))
    axes.bar(x - 0.2, pooled, 0.4, label="pooled (without the person)")
    axes.bar(x + 0.2, adapted, 0.4, yerr=errors, capsize=3, label="adapted on k of their trials")
    axes.set_xticks(x, [f"k = {k}" for k in ks])
    axes.set_ylabel("held-out sHLP (mean over participants)")
    for name, style in (("in_sample", "--"), ("self_fit", ":")):
        if name in report["summary"]:
            axes.axhline(report["summary"][name]["shlp"], color="grey", linestyle=style, label=CEILINGS[name])
    axes.set_ylim(min(pooled + adapted) - 0.1, 1.0)
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), fontsize="small")
    n = report["summary"][ks[0]]["participants"] if ks else 0
    axes.set_title(f"One person's own demonstrations, leave one person out ({n} participants)")
    save_png(figure, path)


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main()))
