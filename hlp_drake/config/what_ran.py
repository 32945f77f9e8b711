"""What a run ran, said the same way in its header, its summary and its JSON.

``WhatRan`` names, for one run or every cell of a study, the robots, the initialisers and low-level
planners (and the pairs' names, ``planners``: the paper's ``hlp`` and ``sto`` for the STO), the
execution modes, the model errors' seeds (None: no model error), the perception sources, the
scenario file (None: the built-in default scenario) and, for an experiment on another robot's
tables (``--tables``), that robot. ``line()`` is the text a person reads; ``to_dict()`` the keys of
``run_scene``'s JSON and of the experiments' ``run.json`` and ``summary.json``: an axis with one
value under its singular key (``robot``, ``planner``, ``initial``, ``low_level``, ``execution``,
``model_error_seed``, ``perception_source``, ``world``), several under the plural.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from typing import Any

BUILT_IN_SCENARIO = "built-in default"
"""How the text names the scenario when no scenario file was given (JSON: ``scenario_file`` null)."""
KEYS = {
    "robots": ("robot", "robots"),
    "planners": ("planner", "planners"),
    "initials": ("initial", "initials"),
    "low_levels": ("low_level", "low_levels"),
    "executions": ("execution", "executions"),
    "model_errors": ("model_error_seed", "model_error_seeds"),
    "perceptions": ("perception_source", "perception_sources"),
    "worlds": ("world", "worlds"),
}
"""Each axis's JSON keys: (one value, several)."""
WORDS = {
    "robots": "robot",
    "initials": "initialiser",
    "low_levels": "low-level planner",
    "executions": "execution",
    "model_errors": "model error",
    "perceptions": "perception",
    "worlds": "world",
}


def distinct(values: Iterable[Any]) -> tuple[Any, ...]:
    """``values`` without repeats, in order."""
    return tuple(dict.fromkeys(values))


@dataclass(frozen=True)
class Labels:
    """One run's values as rows name them: the robot's name, the initialiser, the low-level
    planner, their pair's name (``planner``: the paper's ``hlp``/``sto`` for the STO), the
    execution mode, the perception source, the model error's seed (None: none) and the world the run
    is judged in."""

    robot: str
    initial: str
    low_level: str
    planner: str
    execution: str
    perception: str
    model_error: int | None
    world: str = "reference"


AXES = {
    "robots": "robot",
    "planners": "planner",
    "initials": "initial",
    "low_levels": "low_level",
    "executions": "execution",
    "model_errors": "model_error",
    "perceptions": "perception",
    "worlds": "world",
}
"""Each axis of ``WhatRan`` and the ``Labels`` field it collects."""


@dataclass(frozen=True)
class WhatRan:
    """What a run ran (see the module's docstring); every axis a tuple of its values."""

    robots: tuple[str, ...]
    planners: tuple[str, ...]
    initials: tuple[str, ...]
    low_levels: tuple[str, ...]
    executions: tuple[str, ...]
    model_errors: tuple[int | None, ...]
    perceptions: tuple[str, ...]
    worlds: tuple[str, ...] = ()
    scenario_file: str | None = None
    tables: str | None = None
    """The robot whose reach the generated tables were kept within, if not the run's own (None)."""

    @classmethod
    def of(
        cls, labels: Iterable[Labels], *, scenario_file: str | None = None, tables: str | None = None
    ) -> WhatRan:
        """What runs of ``labels`` ran (each axis its distinct values, in order)."""
        labels = list(labels)
        axes = {axis: distinct(getattr(x, name) for x in labels) for axis, name in AXES.items()}
        return cls(**axes, scenario_file=scenario_file, tables=tables)

    def line(self) -> str:
        """``robot mobile_ur5, initialiser hlp, low-level planner sto, execution open, model error
        none, perception truth, scenario built-in default``."""
        parts = []
        for axis, word in WORDS.items():
            values = [
                "none"
                if v is None and axis == "model_errors"
                else f"seed {v}"
                if axis == "model_errors"
                else v
                for v in getattr(self, axis)
            ]
            plural = (
                "s"
                if len(values) > 1 and axis not in ("model_errors", "executions", "perceptions", "worlds")
                else ""
            )
            parts.append(f"{word}{plural} {' and '.join(map(str, values))}")
        parts.append(f"scenario {self.scenario_file or BUILT_IN_SCENARIO}")
        return ", ".join(parts) + (f", tables of {self.tables}" if self.tables else "")

    def to_dict(self) -> dict[str, Any]:
        """The JSON keys (see the module's docstring)."""
        record: dict[str, Any] = {}
        for axis, (one, several) in KEYS.items():
            values = getattr(self, axis)
            record.update({one: values[0]} if len(values) == 1 else {several: list(values)})
        record["scenario_file"] = self.scenario_file
        return record | ({"tables": self.tables} if self.tables else {})

    @classmethod
    def from_dict(cls, record: Mapping[str, Any]) -> WhatRan | None:
        """The ``WhatRan`` whose ``to_dict()`` keys ``record`` holds (None if it holds no robot: a
        record written before they were)."""
        if "robot" not in record and "robots" not in record:
            return None
        axes = {}
        for axis, (one, several) in KEYS.items():
            axes[axis] = (
                tuple(record[several]) if several in record else ((record[one],) if one in record else ())
            )
        known = {f.name for f in fields(cls)}
        return cls(**axes, **{k: record.get(k) for k in ("scenario_file", "tables") if k in known})


__all__ = ["BUILT_IN_SCENARIO", "Labels", "WhatRan", "distinct"]
