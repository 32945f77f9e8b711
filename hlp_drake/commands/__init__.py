"""The command lines, one module each (its parser and ``main``), and the plumbing they share (``parsing``).

Every command runs as ``python -m hlp_drake.NAME`` (``run_scene``, ``scene``, ``experiments``,
``train``, ``evaluate``, ``segment``, ``dataset``) and as ``hlp-drake NAME`` (with ``run-scene``);
each ``python -m`` module is three lines calling ``run_command``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence

COMMANDS = {
    "run-scene": "run_scene",
    "scene": "scene",
    "experiments": "experiments",
    "train": "train",
    "evaluate": "evaluate",
    "segment": "segment",
    "dataset": "dataset",
}
"""``hlp-drake``'s commands, each the name of its module in ``hlp_drake.commands``."""


def command_main(name: str) -> Callable[[Sequence[str] | None], int]:
    """The ``main(argv)`` of the command ``name`` (a key of ``COMMANDS``), its module imported now."""
    return importlib.import_module(f"hlp_drake.commands.{COMMANDS[name]}").main


def run_command(name: str, argv: Sequence[str] | None = None) -> int:
    """Run the command ``name`` on ``argv`` (default: the process's arguments) as a command line does:
    bad input one line and exit 2 (``run_cli``)."""
    from hlp_drake.commands.parsing import run_cli

    return run_cli(command_main(name), argv)


__all__ = ["COMMANDS", "command_main", "run_command"]
