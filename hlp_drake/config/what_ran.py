"""What a run ran, said the same way in its header, its summary and its JSON.

``WhatRan`` names the robot, the initialiser(s) and low-level planner(s) (and the pairs' names,
``planners``: the paper's ``hlp`` and ``sto`` for the STO), the execution mode, the model error's
seed (None: no model error), the perception source, the scenario file (None: the built-in default
scenario) and, for an experiment on another robot's tables (``--tables``), that robot.
``line()`` is the text a person reads; ``to_dict()`` the keys of ``run_scene``'s JSON and of the
experiments' ``run.json`` and ``summary.json``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

BUILT_IN_SCENARIO = "built-in default"
"""How the text names the scenario when no scenario file was given (JSON: ``scenario_file`` null)."""


def _listed(values: tuple[str, ...]) -> str:
    return " and ".join(values)


def _plural(noun: str, values: tuple[str, ...]) -> str:
    return f"{noun}{'s' if len(values) > 1 else ''} {_listed(values)}"


@dataclass(frozen=True)
class WhatRan:
    """What a run ran (see the module's docstring)."""

    robot: str
    planners: tuple[str, ...]
    execution: str
    model_error_seed: int | None
    perception_source: str
    scenario_file: str | None = None
    tables: str | None = None
    """The robot whose reach the generated tables were kept within, if not the run's own (None)."""
    initials: tuple[str, ...] = ()
    """The initialisers (``hlp``, ``line``)."""
    low_levels: tuple[str, ...] = ()
    """The low-level planners (``sto``, ...)."""

    def line(self) -> str:
        """``robot mobile_ur5, initialiser hlp, low-level planner sto, execution open, model error
        none, perception truth, scenario built-in default``."""
        roles = (
            f"{_plural('initialiser', self.initials)}, {_plural('low-level planner', self.low_levels)}"
            if self.initials and self.low_levels
            else _plural("planner", self.planners)
        )
        error = "none" if self.model_error_seed is None else f"seed {self.model_error_seed}"
        return (
            f"robot {self.robot}, {roles}, execution {self.execution}, model error {error}, "
            f"perception {self.perception_source}, scenario {self.scenario_file or BUILT_IN_SCENARIO}"
            + (f", tables of {self.tables}" if self.tables else "")
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON keys: ``planner``, ``initial``, ``low_level`` (one each) or ``planners``,
        ``initials``, ``low_levels`` (lists), and the rest by name."""
        one = len(self.planners) == 1 and len(self.initials) <= 1 and len(self.low_levels) <= 1
        if one:
            roles = {"planner": self.planners[0]}
            roles |= {"initial": self.initials[0]} if self.initials else {}
            roles |= {"low_level": self.low_levels[0]} if self.low_levels else {}
        else:
            roles = {"planners": list(self.planners), "initials": list(self.initials)}
            roles["low_levels"] = list(self.low_levels)
        return {
            "robot": self.robot,
            **roles,
            "execution": self.execution,
            "model_error_seed": self.model_error_seed,
            "perception_source": self.perception_source,
            "scenario_file": self.scenario_file,
            **({"tables": self.tables} if self.tables else {}),
        }

    @classmethod
    def from_dict(cls, record: Mapping[str, Any]) -> WhatRan | None:
        """The ``WhatRan`` whose ``to_dict()`` keys ``record`` holds (None if it holds none: a record
        written before they were; one written before the roles were named has none of them)."""
        if "robot" not in record:
            return None

        def values(many: str, one: str) -> tuple[str, ...]:
            found = record.get(many) or ([record[one]] if record.get(one) is not None else [])
            return tuple(found)

        return cls(
            robot=record["robot"],
            planners=values("planners", "planner"),
            execution=record["execution"],
            model_error_seed=record["model_error_seed"],
            perception_source=record["perception_source"],
            scenario_file=record["scenario_file"],
            tables=record.get("tables"),
            initials=values("initials", "initial"),
            low_levels=values("low_levels", "low_level"),
        )
