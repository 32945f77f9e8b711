"""The ranges of settings, declared on the fields of config dataclasses, and the one walker that checks them.

A field's range is part of its annotation, so each setting has one source of truth::

    @dataclass(frozen=True)
    class MotionConfig:
        tcp_speed: Annotated[float, Positive(MIN_SPEED, 10.0)] = 0.1
        attempts: Annotated[int, Count(1, 1000)] = 5

``config_problems(config)`` walks any tree of config dataclasses (tuples of them too) and returns one
line per value out of range, naming the field's path (``motion.tcp_speed must be between 0.01 and
10, got 1e-09``). A section's rules across its own fields are its method ``problems(where)``; they
follow its fields' lines. ``None`` is in range wherever the field's type allows it (``X | None``).
``Fields`` declares the ranges of a class that declares none (Drake's ``MultibodyPlantConfig``);
``First(n)`` walks only the first n configs of a tuple.
Types are the loader's business (``hlp_drake.config.typed_yaml``): a range sees values of the declared type,
or whatever a config made in Python holds. Drake-free, like the rest of ``hlp_drake``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any

MAX_SEED = 2**32 - 1
"""Seeds lie in [0, MAX_SEED] (numpy's seeds are non-negative)."""
MAX_SETTING = 1e9
"""Largest value of any number in the settings (a stiffness of 1e6 N/m is typical)."""
MAX_TIME_STEP = 0.01
"""s: the largest plant time step: from 15 ms on, cylinders resting untouched on the table bounce
and walk off it (Gen II scenes), and at 40 ms the state turns non-finite (docs/results.md, "One
execution model")."""
MIN_TIME_STEP = 1e-4
"""s: the smallest plant time step (a simulated second then takes 10,000 steps)."""
MIN_PERIOD = 1e-3
"""s: the shortest control step, sampling and re-planning period (each one is work per period)."""
MAX_DURATION = 60.0
"""s: the longest segment, settling, grasp phase or period: the simulated time of a run stays bounded."""


def join_path(where: str, name: str) -> str:
    """The path of the field ``name`` below ``where`` ("" at the top), as messages name it."""
    return f"{where}.{name}" if where else name


class Check:
    """A range: ``problems(where, value)`` are the lines saying how ``value``, at ``where``, is out of it."""

    def problem(self, where: str, value: Any) -> str | None:
        raise NotImplementedError

    def problems(self, where: str, value: Any) -> list[str]:
        problem = self.problem(where, value)
        return [] if problem is None else [problem]


@dataclass(frozen=True)
class Positive(Check):
    """A finite number > 0 (>= 0 with ``zero_ok``), at least ``lower`` and at most ``upper``."""

    lower: float = 0.0
    upper: float = MAX_SETTING
    zero_ok: bool = False

    def problem(self, where: str, value: float) -> str | None:
        if not math.isfinite(value) or value < 0 or (value == 0 and not self.zero_ok):
            return f"{where} must be {'>= 0' if self.zero_ok else '> 0'}, got {value}"
        if value < self.lower:
            return f"{where} must be between {self.lower:g} and {self.upper:g}, got {value:g}"
        if value > self.upper:
            return f"{where} must be <= {self.upper:g}, got {value:g}"
        return None


@dataclass(frozen=True)
class Count(Check):
    """An integer from ``low`` to ``high``."""

    low: int
    high: int

    def problem(self, where: str, value: int) -> str | None:
        ok = self.low <= value <= self.high
        return None if ok else f"{where} must be between {self.low} and {self.high}, got {value}"


@dataclass(frozen=True)
class Between(Check):
    """A number from ``low`` to ``high`` (NaN is not), in ``unit`` (named in the message)."""

    low: float
    high: float
    unit: str = ""

    def problem(self, where: str, value: float) -> str | None:
        if self.low <= value <= self.high:
            return None
        unit = f" {self.unit}" if self.unit else ""
        return f"{where} must be between {_text(self.low)} and {_text(self.high)}{unit}, got {_text(value)}"


def _text(number: float) -> str:
    return str(number) if isinstance(number, int) else f"{number:g}"


@dataclass(frozen=True)
class Rule(Check):
    """A value ``test`` accepts; else ``message`` formatted with ``where`` and ``value`` (``show(value)``)."""

    test: Callable[[Any], bool]
    message: str
    show: Callable[[Any], Any] = lambda value: value

    def problem(self, where: str, value: Any) -> str | None:
        return None if self.test(value) else self.message.format(where=where, value=self.show(value))


@dataclass(frozen=True)
class Fields(Check):
    """Ranges of the named attributes of a value whose class declares none (e.g. a Drake config struct)."""

    checks: dict[str, Check]

    def problems(self, where: str, value: Any) -> list[str]:
        return [
            p
            for name, check in self.checks.items()
            for p in check.problems(join_path(where, name), getattr(value, name))
        ]


@dataclass(frozen=True)
class First:
    """Walk only the first ``count`` items of a tuple of configs (the section's rule refuses the rest)."""

    count: int


PositiveFloat = Annotated[float, Positive()]
NonNegativeFloat = Annotated[float, Positive(zero_ok=True)]
PERIOD = Positive(MIN_PERIOD, MAX_DURATION)
"""A control step, sampling or re-planning period, s."""


@dataclass(frozen=True)
class _Field:
    """A field the walker visits: its ranges, and whether it holds configs to walk (one, or items)."""

    name: str
    checks: tuple[Check, ...]
    optional: bool
    walk: str | None  # "config", "items" or None
    first: int | None


def _unwrap(kind: Any) -> tuple[Any, list[Any], bool]:
    """(the type inside ``Annotated`` and ``X | None``, the annotations' extras, whether None is allowed)."""
    extras, optional = [], False
    while True:
        origin, args = typing.get_origin(kind), typing.get_args(kind)
        if origin is Annotated:
            extras += kind.__metadata__
            kind = args[0]
        elif origin in (typing.Union, types.UnionType) and type(None) in args and len(args) == 2:
            optional = True
            kind = next(a for a in args if a is not type(None))
        else:
            return kind, extras, optional


def _has_rules(kind: type) -> bool:
    """Whether the config class ``kind`` has rules across its fields (a method ``problems(where)``)."""
    return callable(getattr(kind, "problems", None))


def _is_config(kind: Any) -> bool:
    """Whether ``kind`` is a dataclass with ranges or rules somewhere in it (else it is not walked)."""
    if not (isinstance(kind, type) and dataclasses.is_dataclass(kind)):
        return False
    return bool(_fields(kind)) or _has_rules(kind)


@functools.cache
def _fields(schema: type) -> tuple[_Field, ...]:
    """The fields of the dataclass ``schema`` that have ranges or hold configs (from the annotations)."""
    hints = typing.get_type_hints(schema, include_extras=True)
    found = []
    for f in dataclasses.fields(schema):
        kind, extras, optional = _unwrap(hints[f.name])
        checks = tuple(e for e in extras if isinstance(e, Check))
        first = next((e.count for e in extras if isinstance(e, First)), None)
        items = typing.get_args(kind) if typing.get_origin(kind) is tuple else ()
        walk = None
        if _is_config(kind):
            walk = "config"
        elif items and _is_config(_unwrap(items[0])[0]):
            walk = "items"
        if checks or walk:
            found.append(_Field(f.name, checks, optional, walk, first))
    return tuple(found)


def config_problems(config: Any, where: str = "") -> list[str]:
    """Every value of the config dataclass ``config`` (and of the configs it holds) out of its
    declared range, then every broken rule of a section, one line each (empty when all is fine).

    Args:
        where: the path of ``config`` in its tree ("" at the top).
    """
    problems: list[str] = []
    for spec in _fields(type(config)):
        value, path = getattr(config, spec.name), join_path(where, spec.name)
        if value is None and spec.optional:
            continue
        for check in spec.checks:
            problems += check.problems(path, value)
        if spec.walk == "config":
            problems += config_problems(value, path)
        elif spec.walk == "items":
            for i, item in enumerate(value[: spec.first]):
                problems += config_problems(item, f"{path}[{i}]")
    return problems + (config.problems(where) if _has_rules(type(config)) else [])


__all__ = [
    "MAX_DURATION",
    "MAX_SETTING",
    "MAX_TIME_STEP",
    "MIN_PERIOD",
    "MIN_TIME_STEP",
    "PERIOD",
    "Between",
    "Check",
    "Count",
    "Fields",
    "First",
    "NonNegativeFloat",
    "Positive",
    "PositiveFloat",
    "Rule",
    "config_problems",
]
