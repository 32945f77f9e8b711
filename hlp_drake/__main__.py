"""hlp-drake: human-like planning for reaching in clutter, executed in Drake.

    hlp-drake COMMAND [ARGS ...]      (or: python -m hlp_drake COMMAND [ARGS ...])

Without a command it is a usage error, as for the commands that take a subcommand (scene, dataset):
one error: line on stderr and exit status 2; --help prints this help on stdout (exit status 0).

Commands (each takes --help; the same as python -m hlp_drake.MODULE):
    run-scene     plan a scene (initialiser, low-level planner) and run it in Drake (python -m hlp_drake.run_scene)
    scene         generate, validate and draw scene files (python -m hlp_drake.scene)
    experiments   a study of scenes under conditions (bundled: gen1, gen2: Tables II, III) (python -m hlp_drake.experiments)
    train         train the decision models on the VR dataset (python -m hlp_drake.train)
    evaluate      the cross-subject evaluation, Table I (python -m hlp_drake.evaluate)
    segment       segment the VR demonstrations into per-row decisions (python -m hlp_drake.segment)
    dataset       summarise the VR dataset (python -m hlp_drake.dataset)
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from hlp_drake import __version__
from hlp_drake.commands import COMMANDS, command_main
from hlp_drake.commands.parsing import invoked_as, plain, run_cli

PROG, PYTHON_M = "hlp-drake", "python -m hlp_drake"
"""The console script's name, and how ``python -m`` runs the same (named as the user typed)."""


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``hlp-drake``'s command ``argv[0]`` with the rest of ``argv``."""
    args = list(sys.argv[1:] if argv is None else argv)
    name = PYTHON_M if argv is None and Path(sys.argv[0]).name == "__main__.py" else PROG
    if not args:  # as a command without its required argument: one line, exit status 2
        print(f"error: the following arguments are required: command (see {name} --help)", file=sys.stderr)
        return 2
    if args[0] in ("-h", "--help"):
        print(plain(__doc__).strip())
        return 0
    if args[0] == "--version":
        print(f"{name} {__version__}")
        return 0
    if args[0] not in COMMANDS:
        print(
            f"error: unknown command {args[0]!r}; choose one of {', '.join(COMMANDS)} (see {name} --help)",
            file=sys.stderr,
        )
        return 2
    with invoked_as(f"{name} {args[0]}"):
        return run_cli(command_main(args[0]), args[1:])


if __name__ == "__main__":
    raise SystemExit(main())
