"""``python -m hlp_drake.segment``: segment the VR demonstrations into per-row decisions.

python -m hlp_drake.segment [--dataset PATH] [--mode fixed|faithful] [--category structured|unstructured]
    --out demos.csv
python -m hlp_drake.segment --trial sub_01/T050 --png OUT.png [--mode ...]
"""

from __future__ import annotations

import csv
import io
import json
import time
from collections import Counter
from collections.abc import Sequence

from hlp_drake.commands.parsing import DATASET_DEFAULT, add_quiet, make_parser
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED
from hlp_drake.errors import HlpError
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.segmentation import (
    DEFAULT_MODE,
    MODES,
    Rejected,
    SegmentationResult,
    segment_dataset,
    segment_trial,
)
from hlp_drake.segmentation.batch import log_agreement
from hlp_drake.segmentation.plot import save_segmentation_png

CSV_COLUMNS = ("subject", "trial", "row", "decision", "element", "direction", "keypoints", "handedness")


def demonstrations_csv(result: SegmentationResult) -> str:
    """One row per kept trial and row."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for demo in result.demonstrations:
        for d in demo.decisions:
            writer.writerow(
                [
                    demo.subject,
                    demo.trial,
                    d.row,
                    d.decision,
                    d.element,
                    d.direction or "",
                    len(demo.keypoints),
                    "left" if demo.left_handed else "right",
                ]
            )
    return out.getvalue()


def report(result: SegmentationResult, total: int, seconds: float, category: str, agreement: float) -> str:
    kept = len(result.demonstrations)
    lines = [f"kept {kept} of {total} successful {category} trials ({result.mode} mode, {seconds:.1f} s)"]
    if category == STRUCTURED:
        flags = result.flag_counts()
        lines.append("object-row flags: " + ", ".join(f"{list(k)} {v}" for k, v in sorted(flags.items())))
    decisions = Counter(d.decision for demo in result.demonstrations for d in demo.decisions)
    rows = Counter(len(demo.decisions) for demo in result.demonstrations)
    lines.append(
        "rows per trial: "
        + ", ".join(f"{k}: {v}" for k, v in sorted(rows.items()))
        + "; row decisions: "
        + ", ".join(f"{k} {v}" for k, v in sorted(decisions.items()))
    )
    lines.append(f"agreement with the interaction logs (first PickedUp obstacle per row): {agreement:.1%}")
    for reason, count in result.reasons().most_common():
        lines.append(f"rejected {count}: {reason}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = make_parser("python -m hlp_drake.segment", __doc__)
    parser.add_argument("--dataset", help="the archive or the unpacked dataset/ folder " + DATASET_DEFAULT)
    parser.add_argument(
        "--mode",
        choices=MODES,
        default=DEFAULT_MODE,
        help="fixed: what the paper says (default); faithful: the released code, bugs included",
    )
    parser.add_argument("--out", help="CSV of the per-row decisions of every kept trial")
    parser.add_argument("--json", help="also write the counts and every rejection as JSON")
    parser.add_argument(
        "--category",
        choices=(STRUCTURED, UNSTRUCTURED),
        default=STRUCTURED,
        help="the successful trials to segment (default structured; unstructured: fixed mode)",
    )
    parser.add_argument("--trial", help="segment one trial, e.g. sub_01/T050 (with --png)")
    parser.add_argument("--png", help="picture of --trial's segmentation")
    add_quiet(parser)
    args = parser.parse_args(argv)
    if args.trial is None and args.out is None:
        parser.error("give --out CSV (all trials) or --trial KEY --png FILE (one trial)")
    if args.trial is not None and args.png is None:
        parser.error("--trial needs --png")
    if args.category == UNSTRUCTURED and args.mode == "faithful":
        parser.error(
            "unstructured trials are segmented in fixed mode only (the released code reads two rows)"
        )
    check_writable(args.out, args.json, args.png)
    dataset = Dataset(args.dataset)
    if args.trial is not None:
        if args.trial not in dataset:
            problem = dataset.left_out().get(args.trial)
            if problem is not None:
                raise HlpError(
                    f"{args.trial} was left out of the dataset: {problem['path']}: {problem['reason']}"
                )
            raise HlpError(f"no trial {args.trial!r} in the dataset (expected e.g. sub_01/T050)")
        try:
            demo = segment_trial(dataset.trial(args.trial), mode=args.mode)
        except Rejected as rejected:
            raise HlpError(f"{args.trial} cannot be segmented: {rejected.reason}") from None
        save_segmentation_png(demo, args.png)
        for d in demo.decisions:
            print(f"row {d.row}: {d.decision} {d.element}" + (f" moved {d.direction}" if d.direction else ""))
        print(f"wrote {args.png}")
        return 0
    started = time.perf_counter()
    result = segment_dataset(dataset, mode=args.mode, categories=(args.category,), progress=not args.quiet)
    seconds = time.perf_counter() - started
    agreement = log_agreement(dataset, result)
    total = len(result.demonstrations) + len(result.rejections)
    if total == 0:
        raise HlpError(f"the dataset has no successful {args.category} trials to segment (--category)")
    write_text_atomic(args.out, demonstrations_csv(result))
    if args.json:
        summary = {
            "mode": result.mode,
            "category": args.category,
            "trials": total,
            "kept": len(result.demonstrations),
            "log_agreement": agreement,
            "flags": {"".join(map(str, k)): v for k, v in sorted(result.flag_counts().items())},
            "rejection_reasons": dict(result.reasons()),
            "rejections": [{"trial": r.key, "reason": r.reason} for r in result.rejections],
        }
        write_text_atomic(args.json, json.dumps(summary, indent=2) + "\n")
    print(report(result, total, seconds, args.category, agreement))
    print(f"wrote {args.out}")
    return 0
