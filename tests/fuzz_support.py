"""The fuzz suite's profiles and hostile values (hypothesis).

Every fuzz test runs twice: the ``fast`` profile in the default run (few examples, derandomized so
CI sees the same inputs every time) and the ``long`` profile marked ``slow`` (``pytest -m slow``;
thousands of random examples: the figures of docs/method.md#hostile-input). ``STATS`` counts what
the checks saw; ``conftest.py`` prints it at the end of a run.
"""

from __future__ import annotations

import collections
import contextlib
import functools
import json
import math
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hlp_drake.errors import MAX_LINE, MAX_PROBLEMS, HlpError
from hlp_drake.scene.generators import KINDS, generate_scene
from hlp_drake.scene.io import scene_to_dict
from hlp_drake.scene.model import Scene

PROFILES = [pytest.param("fast", id="fast"), pytest.param("long", id="long", marks=pytest.mark.slow)]
STATS: collections.Counter[str] = collections.Counter()


def run(
    profile: str, examples: tuple[int, int], strategy: st.SearchStrategy, check: Callable[[Any], None]
) -> None:
    """Run ``check`` on ``examples[0]`` (fast) or ``examples[1]`` (long) values of ``strategy``."""
    fast = profile == "fast"
    options = settings(
        max_examples=examples[0] if fast else examples[1],
        deadline=None,
        derandomize=fast,
        database=None,
        print_blob=not fast,
        suppress_health_check=[
            HealthCheck.too_slow,
            HealthCheck.data_too_large,
            HealthCheck.filter_too_much,
            HealthCheck.large_base_example,
        ],
    )

    def example(value: Any) -> None:  # a new function per run: settings apply to one function once
        check(value)

    given(strategy)(options(example))()


def check_error(error: HlpError) -> None:
    """A user error is a few short lines (the README's promise)."""
    assert 1 <= len(error.problems) <= MAX_PROBLEMS + 1
    assert all(len(line) <= MAX_LINE and "\n" not in line for line in error.problems), error.problems


def flip_bytes(draw: Callable, data: bytes) -> bytes:
    """``data`` with 1 to 8 drawn bytes set to drawn values."""
    data = bytearray(data)
    for _ in range(draw(st.integers(1, 8))):
        data[draw(st.integers(0, len(data) - 1))] = draw(st.integers(0, 255))
    return bytes(data)


@contextlib.contextmanager
def scene_file(case: tuple[str, str]) -> Iterator[Path]:
    """A temporary file ``scene<suffix>`` holding ``text`` (a ``scene_texts`` case), even invalid UTF-8."""
    suffix, text = case
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"scene{suffix}"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        yield path


HUGE_INT = 10**400
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([HUGE_INT, -HUGE_INT, 2**63, -(2**63) - 1, 1e160, 1e308, -1e308, 5e-324, -0.0, 0, 1, -1]),
    st.integers(min_value=-(10**30), max_value=10**30),
)
junk = st.one_of(
    numbers,
    st.none(),
    st.booleans(),
    st.text(max_size=30),
    st.text(min_size=290, max_size=400),
    st.lists(st.integers(), max_size=5),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=3),
)
"""Values that do not belong where they are put."""


def _places(value: Any):
    """Every (container, key) in a parsed document, depth first."""
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, sub in items:
        yield value, key
        yield from _places(sub)


def mutate(document: dict, draw: Callable, most: int = 3) -> dict:
    """Up to ``most`` random edits of the parsed ``document`` (in place): a value replaced by junk
    or nudged (valid-looking documents the generators would not make), a key deleted or added."""
    for _ in range(draw(st.integers(0, most))):
        places = list(_places(document))
        if not places:
            break
        container, key = places[draw(st.integers(0, len(places) - 1))]
        operation = draw(st.sampled_from(["junk", "nudge", "nudge", "delete", "unknown"]))
        value = container[key]
        if operation == "junk":
            container[key] = draw(junk)
        elif operation == "nudge" and isinstance(value, int | float) and not isinstance(value, bool):
            factor = draw(st.floats(0.5, 1.5))
            try:
                container[key] = value * factor if math.isfinite(value) and value else factor - 1.0
            except OverflowError:  # an integer beyond floats (a junk value put there before): kept
                pass
        elif operation == "delete":
            container.pop(key)
        elif operation == "unknown" and isinstance(container, dict):
            container[draw(st.text(min_size=1, max_size=8))] = draw(junk)
    return document


@functools.cache
def generated(kind: str, seed: int) -> Scene:
    return generate_scene(kind, seed)


@st.composite
def _mutated_document(draw) -> dict:
    doc = scene_to_dict(generated(draw(st.sampled_from(KINDS)), draw(st.integers(0, 30))))
    mutate(doc, draw)
    if draw(st.integers(0, 5)) == 0 and isinstance(doc.get("obstacles"), list):
        doc["obstacles"] = doc["obstacles"] * draw(
            st.sampled_from([2, 10, 200])
        )  # names repeat, objects overlap
    return doc


_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
_HOSTILE_TEXTS = [
    "start: " + "[" * 5000 + "]" * 5000 + "\n",
    "a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\nstart: [*b, *b, *b, *b]\n",
    "name: one\nname: two\n",
    "table: {length: " + "9" * 400 + ", width: 0.7, height: 0.7}\n",
    "!!python/object/apply:os.system ['echo owned']\n",
    "--- {}\n--- {}\n",
    "",
    "\x00\xff",
]


@st.composite
def scene_texts(draw) -> tuple[str, str]:
    """(suffix, text) of a scene file: a generated scene mutated, or a hostile text."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.sampled_from([".yaml", ".json"])), draw(st.sampled_from(_HOSTILE_TEXTS))
    doc = draw(_mutated_document())
    suffix = draw(st.sampled_from([".yaml", ".json"]))
    text = json.dumps(doc) if suffix == ".json" else yaml.dump(doc, Dumper=_DUMPER, sort_keys=False)
    cut = draw(st.one_of(st.none(), st.integers(0, len(text))))
    return suffix, text if cut is None else text[:cut]


def damage_csv(text: str, draw) -> str:
    """``text`` (a CSV file's) damaged one drawn way: a bad number, rows reversed or swapped, the
    header alone, truncated, cut mid-line, invalid bytes, or empty."""
    lines = text.splitlines()
    how = draw(st.sampled_from(["nan", "reverse", "header", "truncate", "cut", "bytes", "empty", "swap"]))
    if how == "nan" and len(lines) > 1:
        row = draw(st.integers(1, len(lines) - 1))
        fields = lines[row].split(",")
        fields[draw(st.integers(0, len(fields) - 1))] = draw(
            st.sampled_from(["NaN", "inf", "", "x", "1e999"])
        )
        lines[row] = ",".join(fields)
    elif how == "reverse":
        lines = lines[:1] + lines[1:][::-1]
    elif how == "header":
        lines = lines[:1]
    elif how == "truncate":
        lines = lines[: max(1, len(lines) // 2)]
    elif how == "cut":
        joined = "\n".join(lines)
        return joined[: draw(st.integers(0, len(joined)))]
    elif how == "bytes":
        return text[: len(text) // 2] + "\udcff\x00" + text[len(text) // 2 :]
    elif how == "empty":
        return ""
    elif how == "swap" and len(lines) > 2:
        lines[1], lines[2] = lines[2], lines[1]
    return "\n".join(lines) + "\n"
