"""The initialisers by name: ``INITIALISERS``, the one list the scenario (``planner.initial``),
``--planner`` and the planning diagram read.

An initialiser gives the low-level planner its start: a high-level plan on the ``scene`` input
(``hlp``: the human-like planner's; ``line``: the straight line from the start to the target, the
paper's baseline start). ``sto`` is accepted for ``line`` (``ALIASES``): the paper calls the
straight-line baseline "STO". Reading the names imports nothing else; each block's module is
imported when a diagram is built.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from hlp_drake.errors import HlpError


@dataclass(frozen=True)
class InitialiserEntry:
    """One initialiser: its ``name``, a line on what it is, and its block's class (``"module:name"``;
    made with ``models`` and ``config``, the decision models and the HLP's settings, when
    ``uses_models``; without arguments otherwise)."""

    name: str
    about: str
    block: str
    uses_models: bool = False

    def block_class(self) -> type:
        module, _, name = self.block.partition(":")
        return getattr(importlib.import_module(module), name)


INITIALISERS = {
    "hlp": InitialiserEntry(
        "hlp",
        "the human-like planner's plan (learned from people)",
        "hlp_drake.systems.planning.initialiser_blocks:HlpPlannerSystem",
        uses_models=True,
    ),
    "line": InitialiserEntry(
        "line",
        "the straight line from the start to the target (the paper's STO baseline start)",
        "hlp_drake.systems.planning.initialiser_blocks:StraightLinePlanSystem",
    ),
}
ALIASES = {"sto": "line"}
"""Other names accepted for an initialiser: ``sto`` (the paper's name of the straight-line baseline)."""
PAPER_LABELS = {("hlp", "sto"): "hlp", ("line", "sto"): "sto"}
"""The paper's names of the two STO runs, kept as the ``planner`` of rows and JSON."""


def initialiser_name(name: str) -> str:
    """``name``, an alias resolved (``sto`` -> ``line``).

    Raises:
        HlpError: no initialiser has that name.
    """
    name = ALIASES.get(name, name)
    if name not in INITIALISERS:
        known = ", ".join([*INITIALISERS, *(f"{a} (= {t})" for a, t in ALIASES.items())])
        raise HlpError(f"unknown initialiser {name!r} (known: {known})")
    return name


def planner_label(initial: str, low_level: str) -> str:
    """The name of an (initialiser, low-level planner) pair in rows and JSON (``planner``): the
    paper's ``hlp`` and ``sto`` for the STO, ``initial+low_level`` for any other planner."""
    return PAPER_LABELS.get((initial, low_level), f"{initial}+{low_level}")


__all__ = ["ALIASES", "INITIALISERS", "InitialiserEntry", "initialiser_name", "planner_label"]
