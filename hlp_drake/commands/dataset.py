"""``python -m hlp_drake.dataset summary``: trial and success counts per category of the VR dataset."""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from typing import Any

from hlp_drake.commands.parsing import DATASET_DEFAULT, add_quiet, make_parser
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import CATEGORIES
from hlp_drake.files.atomic import check_writable, write_text_atomic


def summarise(dataset: Dataset) -> dict[str, Any]:
    """``{"categories": {name: {"trials", "successes"}}, "subjects": N, "problems": [...]}``."""
    categories = {}
    for category in CATEGORIES:
        records = dataset.select(category=category)
        categories[category] = {"trials": len(records), "successes": sum(r.success for r in records)}
    return {
        "source": dataset.source.describe_parts(),
        "subjects": len(dataset.subjects),
        "categories": categories,
        "problems": dataset.problems,
        "notes": dataset.notes,
    }


def format_summary(summary: dict[str, Any]) -> str:
    lines = [
        f"VR dataset at {summary['source']}: {summary['subjects']} subjects",
        f"{'category':<14}{'trials':>8}{'successes':>11}{'rate':>8}",
    ]
    for name, counts in summary["categories"].items():
        rate = f"{100.0 * counts['successes'] / counts['trials']:.1f}%" if counts["trials"] else "-"
        lines.append(f"{name:<14}{counts['trials']:>8}{counts['successes']:>11}{rate:>8}")
    if summary["problems"]:
        lines.append(f"{len(summary['problems'])} unreadable or invalid files (their trials are left out)")
    if summary["notes"]:
        lines.append(f"{len(summary['notes'])} corrections (see the notes above)")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = make_parser("python -m hlp_drake.dataset", __doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    summary = commands.add_parser("summary", help="trial and success counts per category")
    summary.add_argument("--dataset", help="the archive or the unpacked dataset/ folder " + DATASET_DEFAULT)
    summary.add_argument("--json", help="also write the summary as JSON to this file")
    add_quiet(summary)
    args = parser.parse_args(argv)
    check_writable(args.json)  # a bad path: exit 2, before the dataset is read
    dataset = Dataset(args.dataset, progress=not args.quiet)
    result = summarise(dataset)
    for problem in result["problems"]:
        print(f"warning: {problem['path']}: {problem['reason']}", file=sys.stderr)
    for note in result["notes"]:
        print(f"note: {note['path']}: {note['reason']}", file=sys.stderr)
    print(format_summary(result))
    if args.json:
        write_text_atomic(args.json, json.dumps(result, indent=2) + "\n")
    return 0
