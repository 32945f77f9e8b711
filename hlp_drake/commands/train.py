"""``python -m hlp_drake.train``: fit the decision learners on the VR demonstrations and save them.

    python -m hlp_drake.train [--dataset PATH] [--preset boosted|svm|paper] [--mode fixed|faithful]
        [--categories structured unstructured] [--subjects sub_01 ...] --out DIR

By default every successful structured and unstructured trial there is (fixed mode; the faithful
mode reads structured trials only) trains the default preset: what the bundled models are.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence

from hlp_drake.commands.parsing import DATASET_DEFAULT, add_quiet, make_parser
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED, category_of
from hlp_drake.errors import HlpError
from hlp_drake.features import training_data
from hlp_drake.files.atomic import check_folder
from hlp_drake.learners import DEFAULT_PRESET, PRESETS, DecisionModels
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
    add_quiet(parser)
    args = parser.parse_args(argv)
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
