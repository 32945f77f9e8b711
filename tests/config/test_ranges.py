"""The one walker over config dataclasses: ranges declared on the fields, rules of a section."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated

from hlp_drake.config.ranges import (
    Between,
    Count,
    Fields,
    First,
    NonNegativeFloat,
    Positive,
    Rule,
    config_problems,
)


@dataclass(frozen=True)
class _Part:
    width: Annotated[int, Between(8, 64, "pixels")] = 10
    name: str = "a"

    def problems(self, where: str) -> list[str]:
        return [f"{where}: name is empty"] if not self.name else []


class _Foreign:  # e.g. a Drake struct: no annotations of ours
    def __init__(self, time_step: float = 0.05) -> None:
        self.time_step = time_step


@dataclass(frozen=True)
class _Config:
    speed: Annotated[float, Positive(0.01, 10.0)] = 0.1
    margin: NonNegativeFloat = 0.0
    count: Annotated[int | None, Count(0, 3)] = None
    fraction: Annotated[float, Rule(lambda v: 0 <= v <= 1, "{where} must be in [0, 1], got {value}")] = 0.5
    parts: Annotated[tuple[_Part, ...], First(2)] = (_Part(),)
    foreign: Annotated[_Foreign, Fields({"time_step": Positive(upper=0.1)})] = field(default_factory=_Foreign)


def test_every_value_out_of_its_declared_range_is_one_line_naming_its_path():
    assert config_problems(_Config()) == []
    bad = _Config(
        speed=1e-9,
        margin=-1.0,
        count=4,
        fraction=2.0,
        parts=(_Part(width=4), _Part(name=""), _Part(width=1)),
        foreign=_Foreign(0.5),
    )
    assert config_problems(bad, "top") == [
        "top.speed must be between 0.01 and 10, got 1e-09",
        "top.margin must be >= 0, got -1.0",
        "top.count must be between 0 and 3, got 4",
        "top.fraction must be in [0, 1], got 2.0",
        "top.parts[0].width must be between 8 and 64 pixels, got 4",
        "top.parts[1]: name is empty",  # the third part is not walked (First(2))
        "top.foreign.time_step must be <= 0.1, got 0.5",
    ]
