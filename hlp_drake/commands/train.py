"""``python -m hlp_drake.train``: fit the decision learners on the VR demonstrations and save them.

    python -m hlp_drake.train [--dataset PATH] [--preset boosted|svm|paper] [--mode fixed|faithful]
        [--categories structured unstructured] [--subjects sub_01 ...] --out DIR
    python -m hlp_drake.train --adapt DEMOS [--base DIR] --out DIR

By default every successful structured and unstructured trial there is (fixed mode; the faithful
mode reads structured trials only) trains the default preset: what the bundled models are.

With --adapt, no dataset: the bundled models (or --base DIR, the boosted preset's) are adapted to
one person, from DEMOS: a folder of that person's VR logs in the dataset's layout
(sub_XX/trial_results.csv, sub_XX/TYYY/scene and movement files; participant_list.csv for the
handedness), or a person file (.yaml: scene files and the gaps and obstacles the person chose; see
hlp_drake.segmentation.person_file). Trials that are damaged, empty, name an object their layout
lacks, failed or cannot be segmented are each named (file and line) and left out; fewer than 5 usable trials are refused (exit
2). The row-choice classifier learns the person's bias (gaps or obstacles) and boosts more trees
on their choices, as cross-validation on the person's own trials chooses (none: the base models
stand); see hlp_drake.learners.adapt. The models are the usual models.json and models.npz; pin them with the
SHA-256 printed (run_scene --models DIR --models-sha256 HEX, or planner.models_sha256).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from hlp_drake.commands.parsing import DATASET_DEFAULT, add_quiet, make_parser
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED, category_of
from hlp_drake.errors import HlpError
from hlp_drake.features import training_data
from hlp_drake.files.atomic import check_folder
from hlp_drake.learners import DEFAULT_PRESET, PRESETS, DecisionModels
from hlp_drake.learners.model_format import digest
from hlp_drake.segmentation import DEFAULT_MODE, MODES, demonstration_records, segment_dataset


def main(argv: Sequence[str] | None = None) -> int:
    parser = make_parser("python -m hlp_drake.train", __doc__)
    parser.add_argument("--dataset", help="the archive or the unpacked dataset/ folder " + DATASET_DEFAULT)
    parser.add_argument("--mode", choices=MODES, default=DEFAULT_MODE)
    parser.add_argument(
        "--preset",
        choices=sorted(PRESETS),
        default=DEFAULT_PRESET,
        help=f"{DEFAULT_PRESET} (default, the bundled models), svm, or paper (reference section 5)",
    )
    parser.add_argument(
        "--categories",
        nargs="+",
        choices=(STRUCTURED, UNSTRUCTURED),
        help="the trials to learn from (default: structured and unstructured; faithful: structured)",
    )
    parser.add_argument("--subjects", nargs="+", help="train on these subjects only (default: all)")
    parser.add_argument(
        "--out",
        required=True,
        help="directory for models.json and models.npz, made if missing (its parent must exist)",
    )
    parser.add_argument(
        "--adapt",
        metavar="DEMOS",
        help="adapt the models to one person: a folder of their VR logs (the dataset's layout), or a "
        "person file (.yaml: scenes and the person's choices)",
    )
    parser.add_argument(
        "--base",
        metavar="DIR",
        help="with --adapt: the models to adapt (default: the bundled ones; the boosted preset's)",
    )
    add_quiet(parser)
    args = parser.parse_args(argv)
    if args.base and not args.adapt:
        parser.error("--base names the models --adapt starts from: give --adapt DEMOS too")
    if args.adapt:
        given = [f"--{n}" for n in ("dataset", "categories", "subjects") if getattr(args, n)]
        if given or args.preset != DEFAULT_PRESET or args.mode != DEFAULT_MODE:
            given += ["--preset"] * (args.preset != DEFAULT_PRESET) + ["--mode"] * (args.mode != DEFAULT_MODE)
            parser.error(f"--adapt reads DEMOS and the base models, not {', '.join(given)}")
        check_folder(args.out, "models.json", "models.npz")
        return adapt(args.adapt, args.base, args.out)
    check_folder(args.out, "models.json", "models.npz")
    dataset = Dataset(args.dataset)
    if args.subjects:
        unknown = sorted(set(args.subjects) - set(dataset.subjects))
        if unknown:
            raise HlpError(f"unknown subjects: {', '.join(unknown)}")
    categories = args.categories or ((STRUCTURED, UNSTRUCTURED) if args.mode == "fixed" else (STRUCTURED,))
    if args.mode == "faithful" and UNSTRUCTURED in categories:
        raise HlpError("the faithful mode reads structured trials only (the released code's two rows)")
    started = time.perf_counter()
    records = demonstration_records(dataset, args.subjects, categories)
    result = segment_dataset(dataset, mode=args.mode, records=records, progress=not args.quiet)
    data = training_data(result.demonstrations, mode=args.mode)
    segmented = time.perf_counter()
    models = DecisionModels(PRESETS[args.preset]).fit(data)
    models.save(args.out)
    print(
        f"segmented {len(result.demonstrations)} demonstrations of {len(models.subjects_)} subjects "
        f"({args.mode} mode) in {segmented - started:.1f} s; fitted {args.preset} models in "
        f"{time.perf_counter() - segmented:.1f} s"
    )
    counts = Counter(category_of(d.trial) for d in result.demonstrations)
    print(
        "trials: "
        + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
        + "; rows: "
        + ", ".join(f"{name} {len(getattr(data, name))}" for name in models.learners)
    )
    print(f"wrote {args.out}/models.json and models.npz")
    return 0


def adapt(demos: str, base: str | None, out: str) -> int:
    """``--adapt``: the base models adapted to the person of the folder ``demos``, saved in ``out``."""
    import sys

    from hlp_drake.learners.adapt import adapt_models, choice_name
    from hlp_drake.learners.bundled import default_models
    from hlp_drake.segmentation.person import read_person
    from hlp_drake.segmentation.person_file import is_person_file, read_person_file

    prior = DecisionModels.load(base) if base else default_models()  # a bad model file: before any work
    person = read_person_file(demos) if is_person_file(demos) else read_person(demos)
    for line in person.left_out:
        print(f"left out: {line}", file=sys.stderr)
    models, adaptation = adapt_models(prior, person.demonstrations, person=person.person)
    models.save(out)
    tried = ", ".join(f"{name} {score:.3f}" for name, score in adaptation.scores.items())
    chosen = choice_name(adaptation.bias, adaptation.trees)
    print(
        f"adapted to {person.person} from {adaptation.trials} trials ({adaptation.rows} row choices, "
        f"{len(person.left_out)} left out): {'the prior kept' if chosen == 'prior' else chosen + ' added'}"
    )
    print(f"cross-validated row score ({adaptation.folds} folds of the person's trials): {tried}")
    sha = digest((Path(out) / "models.json").read_bytes())
    print(f"wrote {out}/models.json and models.npz (models.json SHA-256 {sha})")
    return 0
