"""What a run ran, said the same way in its header, its summary and its JSON.

``WhatRan`` names the robot, the planner(s), the execution mode, the model error's seed (None: no
model error), the perception source, the scenario file (None: the built-in default scenario) and,
for an experiment on another robot's tables (``--tables``), that robot.
``line()`` is the text a person reads; ``to_dict()`` the keys of ``run_scene``'s JSON and of the
experiments' ``run.json`` and ``summary.json``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

BUILT_IN_SCENARIO = "built-in default"
"""How the text names the scenario when no scenario file was given (JSON: ``scenario_file`` null)."""


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

    def line(self) -> str:
        """``robot mobile_ur5, planner hlp, execution open, model error none, perception truth,
        scenario built-in default``."""
        planners = f"planner{'s' if len(self.planners) > 1 else ''} {' and '.join(self.planners)}"
        error = "none" if self.model_error_seed is None else f"seed {self.model_error_seed}"
        return (
            f"robot {self.robot}, {planners}, execution {self.execution}, model error {error}, "
            f"perception {self.perception_source}, scenario {self.scenario_file or BUILT_IN_SCENARIO}"
            + (f", tables of {self.tables}" if self.tables else "")
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON keys: ``planner`` (one planner) or ``planners`` (a list), and the rest by name."""
        planners = (
            {"planner": self.planners[0]} if len(self.planners) == 1 else {"planners": list(self.planners)}
        )
        return {
            "robot": self.robot,
            **planners,
            "execution": self.execution,
            "model_error_seed": self.model_error_seed,
            "perception_source": self.perception_source,
            "scenario_file": self.scenario_file,
            **({"tables": self.tables} if self.tables else {}),
        }

    @classmethod
    def from_dict(cls, record: Mapping[str, Any]) -> WhatRan | None:
        """The ``WhatRan`` whose ``to_dict()`` keys ``record`` holds (None if it holds none: a record
        written before they were)."""
        if "robot" not in record:
            return None
        planners = record.get("planners") or [record["planner"]]
        return cls(
            robot=record["robot"],
            planners=tuple(planners),
            execution=record["execution"],
            model_error_seed=record["model_error_seed"],
            perception_source=record["perception_source"],
            scenario_file=record["scenario_file"],
            tables=record.get("tables"),
        )
