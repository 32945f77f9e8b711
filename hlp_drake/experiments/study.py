"""``Study``: an experiment as data, a grid of conditions each run on the same seeded scenes.

A study names its scene generators and object counts, how many scenes and from which seed, and the
axes of its grid: robots, initialisers, low-level planners, execution modes, perception sources,
model-error seeds and the worlds the runs are judged in. An axis left empty is the scenario's own setting (one cell). Every (scene, cell)
is one job, one row of ``results.csv``; the summary, the plots and resuming work on any grid. The
paper's Tables II and III are the bundled studies ``gen1`` and ``gen2`` (``studies/*.yaml``)::

    name: gen2
    title: "Table III: Generalization II"
    generators: [gen2]
    objects: [5, 7, 9]
    initialisers: [hlp, line]
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Annotated, Any

from hlp_drake.config.ranges import MAX_SEED, Count, config_problems
from hlp_drake.errors import HlpError
from hlp_drake.scene.constants import KINDS, MAX_GENERATED

STUDIES = Path(__file__).resolve().parent / "studies"
"""The bundled studies, ``NAME.yaml``."""
MAX_SCENES = 100_000
EXECUTORS = ("local", "dask")
"""Where a study's jobs run: this process or a local process pool, or a dask cluster (``executors``)."""
FIXED_COUNT_KINDS = ("vr", "gen1")
"""Generators whose scenes always have the same number of obstacles (``objects`` does not apply)."""
AXES = ("robots", "initialisers", "low_level", "execution", "perception", "model_error", "world")
"""The grid's axes, in the order of a cell's fields."""


@dataclass(frozen=True)
class Cell:
    """One cell of a study's grid: what it lays over the scenario (None: the scenario's own)."""

    robot: str | None = None
    initial: str | None = None
    low_level: str | None = None
    execution: str | None = None
    perception: str | None = None
    model_error: int | None = None
    world: str | None = None


@dataclass(frozen=True)
class Study:
    """An experiment's grid (see the module's docstring).

    Attributes:
        name: its name (the bundled ones: ``gen1``, ``gen2``).
        title: what the summary and the plots are headed (default: the name).
        generators: the scene generators (``vr``, ``gen1``, ``gen2``, ``unstructured``).
        objects: the object counts of the generators that take one (``gen2``, ``unstructured``),
            one condition each; ``gen1`` and ``vr`` have 6 obstacles always.
        scenes: scenes per condition; scene i has seed ``seed + i``.
        seed: the first scene's seed.
        robots: shipped robots' names or description files ([]: the scenario's robot).
        initialisers: ``hlp``, ``line`` ([]: the scenario's).
        low_level: the low-level planners ([]: the scenario's).
        execution: ``open``, ``closed`` ([]: the scenario's).
        perception: ``truth``, ``camera`` ([]: the scenario's).
        model_error: seeds of the model error the world has and the planners do not know of ([]:
            the scenario's).
        world: what the robot acts in and the runs are judged in: ``reference``, ``model`` ([]: the
            scenario's, reference).
        tables: generate the tables within this robot's reach instead of each robot's own (a name
            or a description file; "": each robot's own): the same scenes for every robot.
    """

    name: str = "study"
    title: str = ""
    generators: tuple[str, ...] = ("gen1",)
    objects: tuple[int, ...] = (5, 7, 9)
    scenes: Annotated[int, Count(1, MAX_SCENES)] = 100
    seed: Annotated[int, Count(0, MAX_SEED - MAX_SCENES)] = 0
    robots: tuple[str, ...] = ()
    initialisers: tuple[str, ...] = ("hlp", "line")
    low_level: tuple[str, ...] = ()
    execution: tuple[str, ...] = ()
    perception: tuple[str, ...] = ()
    model_error: tuple[int, ...] = ()
    world: tuple[str, ...] = ()
    tables: str = ""

    def problems(self, where: str = "") -> list[str]:
        """What cannot run, one line each (the names are checked against their registries)."""
        from hlp_drake.systems.low_level.registry import LOW_LEVEL_PLANNERS
        from hlp_drake.systems.names import EXECUTIONS, PERCEPTION_SOURCES, WORLDS
        from hlp_drake.systems.planning.initialisers import ALIASES, INITIALISERS

        prefix = f"{where}." if where else ""
        known = {
            "generators": KINDS,
            "initialisers": (*INITIALISERS, *ALIASES),
            "low_level": tuple(LOW_LEVEL_PLANNERS),
            "execution": EXECUTIONS,
            "perception": PERCEPTION_SOURCES,
            "world": WORLDS,
        }
        problems = [
            f"{prefix}{axis}: unknown {value!r} (known: {', '.join(names)})"
            for axis, names in known.items()
            for value in getattr(self, axis)
            if value not in names
        ]
        from hlp_drake.models import SHIPPED_ROBOTS

        for axis, values in (("robots", self.robots), ("tables", (self.tables,) if self.tables else ())):
            problems += [
                f"{prefix}{axis}: unknown robot {value!r} (shipped: {', '.join(SHIPPED_ROBOTS)}; or a .yaml "
                "description file)"
                for value in values
                if value not in SHIPPED_ROBOTS and not value.endswith((".yaml", ".yml"))
            ]
        if any(not 0 <= seed <= MAX_SEED for seed in self.model_error):
            problems.append(
                f"{prefix}model_error: each seed between 0 and {MAX_SEED}, got {list(self.model_error)}"
            )
        if not self.generators:
            problems.append(f"{prefix}generators: give at least one")
        if any(not 1 <= count <= MAX_GENERATED for count in self.objects):
            problems.append(f"{prefix}objects: each between 1 and {MAX_GENERATED}, got {list(self.objects)}")
        if any(g not in FIXED_COUNT_KINDS for g in self.generators) and not self.objects:
            problems.append(f"{prefix}objects: give the object counts of {', '.join(self.generators)}")
        return problems

    def cells(self) -> list[Cell]:
        """Every cell of the grid, in the order of ``AXES`` (an empty axis: the scenario's own)."""
        values = [getattr(self, axis) or (None,) for axis in AXES]
        return [Cell(*combination) for combination in itertools.product(*values)]

    def counts(self, generator: str) -> tuple[int | None, ...]:
        """The object counts of ``generator``'s conditions (None: its fixed count)."""
        return (None,) if generator in FIXED_COUNT_KINDS else tuple(sorted(set(self.objects)))

    @property
    def heading(self) -> str:
        return self.title or self.name

    def identity(self) -> dict[str, Any]:
        """What a run folder's rows depend on (a folder holding another study's rows is refused):
        every field but the name and the title, and the scene and object counts (a run extends
        to more scenes or counts: their rows are added)."""
        record = asdict(self)
        extensible = ("name", "title", "scenes", "objects")
        return {f.name: record[f.name] for f in fields(self) if f.name not in extensible}


def bundled_studies() -> tuple[str, ...]:
    """The names of the bundled studies."""
    return tuple(sorted(path.stem for path in STUDIES.glob("*.yaml")))


def load_study(name: str) -> Study:
    """The bundled study ``name`` (``bundled_studies``) or the study in the YAML file ``name``.

    Raises:
        HlpError: no such study or file, or the file is not a valid study (one line per problem).
    """
    if name in bundled_studies():
        path = STUDIES / f"{name}.yaml"
    elif Path(name).suffix in (".yaml", ".yml"):
        path = Path(name)
    else:
        raise HlpError(f"unknown study {name!r}: one of {', '.join(bundled_studies())} or a study .yaml file")
    from hlp_drake.config.typed_yaml import load_typed  # YAML: once a study is read, not for --help
    from hlp_drake.files.documents import parse_yaml, read_document

    text = read_document(path, missing="study file not found")
    document = parse_yaml(text, str(path))
    if document is None:
        raise HlpError(
            f"{path}: the file is empty; a study gives its scenes and the conditions to run on them"
        )
    study = load_typed(Study, document, defaults=Study(), where=str(path), top="study")
    problems = config_problems(study)  # the ranges, then the rules (Study.problems)
    if problems:
        raise HlpError(*(f"{path}: {p}" for p in problems))
    return study


__all__ = ["AXES", "Cell", "Study", "bundled_studies", "load_study"]
