"""Shared command-line plumbing: one parser style, one progress flag, user errors as one line and exit 2.

Every command (``python -m hlp_drake.X`` or ``hlp-drake X``) builds its parser with ``make_parser``:
the help and ``--version`` name the command as the user typed it (``invoked_as``: ``hlp-drake X``
or ``python -m hlp_drake.X``), the help shows the module's docstring without reStructuredText
markup or a second usage, ``--version`` prints one line, the name and the version, and a usage error is one ``error: ...`` line with exit status 2. Commands with
progress bars take ``--quiet`` (``add_quiet``) to turn them off; commands that run Drake take
``--quiet`` or ``--verbose`` (``add_verbosity``: Drake's INFO lines only with ``--verbose``,
``drake_logging``); commands that plan take ``--perception`` (``add_perception``).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import NoReturn

from hlp_drake import DRAKE_LOG, __version__
from hlp_drake.config.ranges import MAX_SEED
from hlp_drake.errors import FormerName, HlpError
from hlp_drake.files.atomic import output_streams
from hlp_drake.models import SHIPPED_ROBOTS
from hlp_drake.runtime.processes import Terminated, terminations_raised
from hlp_drake.systems.names import EXECUTIONS, PERCEPTION_SOURCES, WORLDS

EXIT_TERMINATED = 143  # 128 + SIGTERM


def plain(text: str) -> str:
    """``text`` (a docstring) without reStructuredText's double backticks."""
    return text.replace("``", "")


class Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one-line ``HlpError``s (exit 2 through ``run_cli``)."""

    def error(self, message: str) -> NoReturn:
        raise HlpError(f"{message} (see {self.prog} --help)")


_INVOKED_AS: ContextVar[str | None] = ContextVar("invoked_as", default=None)


@contextmanager
def invoked_as(name: str) -> Iterator[None]:
    """Name the commands whose parsers are made inside ``name``: what the user typed to run them
    (``hlp-drake run-scene`` rather than the module's own ``python -m hlp_drake.run_scene``)."""
    token = _INVOKED_AS.set(name)
    try:
        yield
    finally:
        _INVOKED_AS.reset(token)


def _without_usage(text: str, prog: str) -> str:
    """``text`` without its paragraphs that show how to call ``prog`` (argparse prints the usage)."""
    paragraphs = text.split("\n\n")
    return "\n\n".join(p for p in paragraphs if not p.strip().startswith(f"{prog} ")).strip()


def make_parser(prog: str, doc: str | None, **kwargs) -> Parser:
    """A ``Parser`` for the command ``prog`` (the module's ``python -m`` name): named as the user typed
    it (``invoked_as``), the first paragraph of the docstring ``doc`` as its description and the rest,
    without the usage argparse prints, as the epilog (plain text, the command named as typed), and
    ``--version`` (one line: the name and the version)."""
    name = _INVOKED_AS.get() or prog
    head, _, rest = (doc or "").strip().partition("\n\n")
    parser = Parser(
        prog=name,
        description=plain(head).replace(prog, name),
        epilog=plain(_without_usage(rest, prog)).replace(prog, name) or None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        **kwargs,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    return parser


DATASET_DEFAULT = (
    "(default: $HLP_DATASET, paths joined by ':'; else, in a source checkout, ../shared/data beside the "
    "project folder, the one holding pyproject.toml and hlp_drake/)"
)
"""How ``--dataset``'s help says where the dataset is read from without it (``default_dataset``)."""

MAX_WORKERS = 64
"""Most worker processes a command starts."""


def integer(low: int, high: int) -> Callable[[str], int]:
    """An argparse ``type``: an integer in [low, high] (else a one-line usage error)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text[:40]!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be between {low} and {high}, got {text[:40]}")
        return value

    parse.__name__ = "integer"
    return parse


def seconds(high: float) -> Callable[[str], float]:
    """An argparse ``type``: a number of seconds in [0, high] (else a one-line usage error)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text[:40]!r}") from None
        if not 0.0 <= value <= high:  # also refuses nan
            raise argparse.ArgumentTypeError(f"must be between 0 and {high:g} s, got {text[:40]}")
        return value

    parse.__name__ = "seconds"
    return parse


def add_quiet(parser: argparse.ArgumentParser) -> None:
    """``--quiet``: no progress bars (shown by default on stderr when it is a terminal)."""
    parser.add_argument("--quiet", action="store_true", help="no progress bars")


def add_verbosity(parser: argparse.ArgumentParser) -> None:
    """``--quiet`` (no progress bars) or ``--verbose`` (Drake's INFO lines too): for commands that run
    Drake (``drake_logging``)."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "--quiet",
        action="store_true",
        help="no progress bars (shown on stderr when it is a terminal) and no Drake INFO lines",
    )
    group.add_argument(
        "--verbose", action="store_true", help="Drake's INFO lines too (e.g. where MeshCat listens)"
    )


def drake_logging(verbose: bool) -> None:
    """Drake's INFO lines (e.g. ``Meshcat listening for connections at ...``) only when ``verbose``; its
    warnings and errors always; in this process and in the worker processes it starts, which inherit
    the choice through the environment (``hlp_drake.DRAKE_LOG``, applied by a filter on the "drake"
    logger wherever hlp_drake is imported). Imports pydrake, which sets its logger's level on import."""
    import logging
    import os

    import pydrake.common  # noqa: F401 - sets the "drake" logger's level: set it afterwards

    os.environ[DRAKE_LOG] = "info" if verbose else "warning"
    logging.getLogger("drake").setLevel(logging.INFO if verbose else logging.WARNING)


def add_planner_options(parser: argparse.ArgumentParser, *, several: bool = False) -> None:
    """``--planner`` (the initialiser; ``sto`` is accepted for ``line``) and ``--low-level`` (the
    low-level planner), from their registries; ``several``: each takes a list (an experiment's grid)."""
    from hlp_drake.systems.low_level.registry import LOW_LEVEL_PLANNERS
    from hlp_drake.systems.planning.initialisers import ALIASES, INITIALISERS

    many = {"nargs": "+"} if several else {}
    aliases = ", ".join(f"{alias}: {name}" for alias, name in ALIASES.items())
    default = "the study's; gen1, gen2: both" if several else "the scenario's, hlp"
    parser.add_argument(
        "--planner",
        choices=(*INITIALISERS, *ALIASES),
        metavar="|".join((*INITIALISERS, *ALIASES)),
        help=f"the initialiser{'s' if several else ''}: the human-like plan (hlp) or the baseline's "
        f"straight line (line; {aliases}, the paper's name of the baseline); default: {default}",
        **many,
    )
    parser.add_argument(
        "--low-level",
        choices=tuple(LOW_LEVEL_PLANNERS),
        metavar="|".join(LOW_LEVEL_PLANNERS),
        help="the low-level planner that turns the initialiser's plan into the robot's motion: "
        + "; ".join(f"{name}, {entry.about}" for name, entry in LOW_LEVEL_PLANNERS.items())
        + " (default: the scenario's, sto)",
        **many,
    )


def add_robot_option(parser: argparse.ArgumentParser, *, several: bool = False) -> None:
    """``--robot NAME|FILE``: run a shipped robot or a description file's (the scenario's ``robot``);
    ``several``: a list (an experiment's grid)."""
    parser.add_argument(
        "--robot",
        metavar="NAME|FILE",
        help=f"the robot: one of {', '.join(SHIPPED_ROBOTS)} (default: the scenario's, mobile_ur5) or a "
        "robot description .yaml file (see the README, 'Your own robot')",
        **({"nargs": "+"} if several else {}),
    )


def add_perception(parser: argparse.ArgumentParser, *, several: bool = False) -> None:
    """``--perception truth|camera``: override the scenario's ``perception.source``."""
    parser.add_argument(
        "--perception",
        choices=PERCEPTION_SOURCES,
        help="plan on the true scene (truth, the default) or on what the scenario's cameras see "
        "(camera: ScenePerception; the simulation still runs the true scene)",
        **({"nargs": "+"} if several else {}),
    )


def add_conditions(parser: argparse.ArgumentParser, *, several: bool = False) -> None:
    """``--execution open|closed``, ``--uncertainty [SEED]`` and ``--world model|reference``
    (``Scenario.closed_loop``, ``Scenario.uncertainty``, ``Scenario.world``; applied by
    ``hlp_drake.systems.Conditions``)."""
    parser.add_argument(
        "--execution",
        choices=EXECUTIONS,
        help="open: play the planned motion; closed: re-plan it every closed_loop.replan_period s "
        "of simulated time on the measured state (default: as the scenario says, open)",
        **({"nargs": "+"} if several else {}),
    )
    parser.add_argument(
        "--uncertainty",
        type=integer(0, MAX_SEED),
        nargs="?",
        const=0,
        metavar="SEED",
        help="execute in a world with seeded model error the planners do not know of (object poses, "
        "masses, friction: the scenario's uncertainty); SEED defaults to 0",
    )
    parser.add_argument(
        "--world",
        choices=WORLDS,
        help="what the robot acts in and the run is judged in: reference (finer physics than the "
        "planner's model: 2 ms steps, the full contact geometry) or model (the planner's own model; "
        "the execution replays its accepted rollout); default: the scenario's, reference",
        **({"nargs": "+"} if several else {}),
    )


def add_run_conditions(parser: argparse.ArgumentParser, *, several: bool = False) -> None:
    """The options that become a run's ``Conditions`` (``hlp_drake.systems.conditions``): ``--robot``,
    ``--planner``, ``--low-level``, ``--perception``, ``--execution``, ``--uncertainty``;
    ``several``: lists, an experiment's grid (``--uncertainty`` takes one seed either way)."""
    add_robot_option(parser, several=several)
    add_planner_options(parser, several=several)
    add_perception(parser, several=several)
    add_conditions(parser, several=several)


def _shown_as_note(show: Callable[..., None]) -> Callable[..., None]:
    """``show`` (``warnings.showwarning``), but a ``FormerName`` is one ``note:`` line on stderr."""

    def shown(message, category, *args, **kwargs) -> None:
        if issubclass(category, FormerName):
            print(f"note: {message}", file=sys.stderr)
        else:
            show(message, category, *args, **kwargs)

    return shown


def run_cli(main: Callable[[Sequence[str] | None], int], argv: Sequence[str] | None = None) -> int:
    """Run ``main(argv)``; print each problem of an ``HlpError`` as ``error: ...`` and return its
    ``exit_status`` (2, or 1 for a ``StorageError``: the run failed), standard output kept for an
    output ``-`` (``output_streams``); a Ctrl-C prints "interrupted"
    and returns 130, a SIGTERM "terminated" and 143 (its workers stopped)."""
    try:
        with terminations_raised(), warnings.catch_warnings(), output_streams():
            warnings.simplefilter("once", FormerName)
            warnings.showwarning = _shown_as_note(warnings.showwarning)
            return main(argv)
    except HlpError as error:
        for problem in error.problems:
            print(f"error: {problem}", file=sys.stderr)
        return error.exit_status
    except Terminated:
        print("terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
