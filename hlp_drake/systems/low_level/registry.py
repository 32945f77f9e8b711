"""The low-level planners by name: ``LOW_LEVEL_PLANNERS``, the one list the scenario
(``planner.low_level.kind``), ``--low-level`` and the planning diagram read.

An entry names the planner's settings class and its planner (``"module:name"`` strings, imported on
first use, so reading the names imports nothing else; or the objects themselves) and says whether
it rolls out (then it needs a ``RolloutPool``) and whether it can re-plan from a measured state
(then it can run closed loop). Register a planner of your own with ``register_low_level``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from hlp_drake.errors import HlpError

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.protocol import LowLevelConfig, LowLevelContext, LowLevelPlanner


def _resolve(reference: str | Any) -> Any:
    """The object ``"module:name"`` names (imported now), or ``reference`` itself."""
    if not isinstance(reference, str):
        return reference
    module, _, name = reference.partition(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class LowLevelEntry:
    """One low-level planner.

    Attributes:
        name: its name (``planner.low_level.kind``, ``--low-level``).
        config: its settings class (a ``LowLevelConfig`` whose ``kind`` defaults to ``name``).
        planner: makes it: ``planner(config, context)`` with a ``LowLevelContext``.
        about: one line on what it is.
        rolls_out: it simulates in a rollout pool (``RolloutPool``), whose size is its ``workers``.
        replans: it re-plans from a measured state (``replan``): closed-loop execution can use it.
        step: what the progress line calls its run ("": its name; the STO's: "optimise").
        called: what a failure calls it ("" : "the low-level planner NAME"; the STO's: "the optimiser").
    """

    name: str
    config: str | type
    planner: str | Callable[..., Any]
    about: str
    rolls_out: bool = False
    replans: bool = False
    step: str = ""
    called: str = ""

    def __post_init__(self) -> None:
        if not self.step:
            object.__setattr__(self, "step", self.name)

    @property
    def noun(self) -> str:
        """What a failure calls it (``called``, or "the low-level planner NAME")."""
        return self.called or f"the low-level planner {self.name}"

    def config_class(self) -> type[LowLevelConfig]:
        return _resolve(self.config)

    def make(self, config: LowLevelConfig, context: LowLevelContext) -> LowLevelPlanner:
        """The planner of ``config`` (this entry's settings) with ``context``."""
        return _resolve(self.planner)(config, context)


LOW_LEVEL_PLANNERS: dict[str, LowLevelEntry] = {}
"""The registered low-level planners, by name."""


def register_low_level(entry: LowLevelEntry) -> LowLevelEntry:
    """Add ``entry`` (its name must be new) and return it."""
    if entry.name in LOW_LEVEL_PLANNERS:
        raise ValueError(f"a low-level planner named {entry.name!r} is registered already")
    LOW_LEVEL_PLANNERS[entry.name] = entry
    return entry


def low_level_entry(name: str) -> LowLevelEntry:
    """The entry named ``name``.

    Raises:
        HlpError: no planner has that name (the message names the known ones).
    """
    entry = LOW_LEVEL_PLANNERS.get(name)
    if entry is None:
        raise HlpError(f"unknown low-level planner {name!r} (known: {', '.join(LOW_LEVEL_PLANNERS)})")
    return entry


def check_closed_loop(name: str, *, closed: bool) -> None:
    """Refuse a closed loop (``closed``) with the planner named ``name`` when it cannot re-plan.

    Raises:
        HlpError: it cannot (the message names those that can).
    """
    entry = low_level_entry(name)
    if closed and not entry.replans:
        replanners = ", ".join(n for n, e in LOW_LEVEL_PLANNERS.items() if e.replans)
        raise HlpError(
            f"closed-loop execution re-plans from the measured state, which the low-level planner "
            f"{entry.name} cannot (one that can: {replanners})"
        )


register_low_level(
    LowLevelEntry(
        "sto",
        "hlp_drake.systems.low_level.sto.config:StoConfig",
        "hlp_drake.systems.low_level.sto.planner:StoPlanner",
        "the physics-based stochastic trajectory optimiser (the paper's): rollouts with contact",
        rolls_out=True,
        replans=True,
        step="optimise",
        called="the optimiser",
    )
)

register_low_level(
    LowLevelEntry(
        "trajopt",
        "hlp_drake.systems.low_level.kinematic.trajopt:TrajoptConfig",
        "hlp_drake.systems.low_level.kinematic.trajopt:TrajoptPlanner",
        "Drake's kinematic trajectory optimisation: a B-spline clear of the objects it may not touch",
        step="trajopt",
    )
)
register_low_level(
    LowLevelEntry(
        "rrt",
        "hlp_drake.systems.low_level.kinematic.rrt:RrtConfig",
        "hlp_drake.systems.low_level.kinematic.rrt:RrtPlanner",
        "OMPL's RRT-Connect in configuration space, clear of the objects it may not touch",
        step="rrt",
    )
)

__all__ = [
    "LOW_LEVEL_PLANNERS",
    "LowLevelEntry",
    "check_closed_loop",
    "low_level_entry",
    "register_low_level",
]
