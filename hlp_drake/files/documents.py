"""User documents (scene, scenario and model files) read within limits, as plain data.

Every file is read at most ``MAX_DOCUMENT_BYTES``; a document may nest at most ``MAX_DEPTH``
levels and hold at most ``MAX_NODES`` values. YAML is read from libyaml's event stream (no alias
is ever expanded: an alias, a non-core tag, a duplicate key or a second document is refused at its
line), JSON with Python's parser (duplicate keys refused). Each refusal is one line naming the file.
"""

from __future__ import annotations

import json
import os
import re
import reprlib
from typing import Any

import yaml
from yaml import events
from yaml.constructor import SafeConstructor
from yaml.nodes import ScalarNode
from yaml.resolver import Resolver

from hlp_drake.errors import HlpError, short

MAX_DOCUMENT_BYTES = 8 * 2**20
"""Largest scene or scenario file read, bytes (a 10,000-object scene is about 1 MB of YAML)."""
MAX_DEPTH = 32
"""Deepest nesting of mappings and lists in a document (a scenario needs 4)."""
MAX_NODES = 250_000
"""Most values (keys, scalars, lists and mappings) in one document (10,000 objects need ~170,000)."""

_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_CORE = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_CORE + name for name in ("str", "int", "float", "bool", "null")}
_COLLECTION_TAGS = {None, "!", _CORE + "seq", _CORE + "map"}
_RESOLVER = Resolver()
_CONSTRUCTOR = SafeConstructor()
_FLOAT_NO_DOT = re.compile(r"[-+]?[0-9]+[eE][-+]?[0-9]+")
"""``1e-3``: a number in YAML 1.2 (and to Drake), text to YAML 1.1's resolver without a dot."""
_REPR = reprlib.Repr()
_REPR.maxstring, _REPR.maxother, _REPR.maxlong = 60, 60, 30
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = 4
_REPR.maxlevel = 2


class _Refused(Exception):
    """A document broke a limit (the message says which, and where)."""


def brief(value: Any) -> str:
    """A short repr of ``value`` for a message (long texts, numbers and lists cut)."""
    try:
        return _REPR.repr(value)
    except ValueError:  # an integer too long to print
        return "a very long integer"


def read_bytes(
    path: str | os.PathLike[str],
    error: type[HlpError] = HlpError,
    *,
    missing: str = "no such file",
    limit: int = MAX_DOCUMENT_BYTES,
) -> bytes:
    """The bytes of the file ``path``, read at most ``limit`` of them.

    Raises:
        error: the file is missing, unreadable or larger than ``limit`` (one line).
    """
    try:
        with open(path, "rb") as file:
            data = file.read(limit + 1)
    except FileNotFoundError:
        raise error(f"{path}: {missing}") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not a file") from None
    except OSError as problem:
        raise error(f"{path}: cannot read: {problem.strerror or problem}") from None
    if len(data) > limit:
        raise error(f"{path}: larger than the {limit / 2**20:g} MiB such a file may have") from None
    return data


def read_document(
    path: str | os.PathLike[str],
    error: type[HlpError] = HlpError,
    *,
    missing: str = "no such file",
    limit: int = MAX_DOCUMENT_BYTES,
) -> str:
    """The UTF-8 text of the file ``path`` (``read_bytes``).

    Raises:
        error: as ``read_bytes``, or the file is not UTF-8 (one line).
    """
    data = read_bytes(path, error, missing=missing, limit=limit)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as problem:
        raise error(f"{path}: not UTF-8 text ({problem.reason} at byte {problem.start})") from None


def _line(event: events.Event) -> str:
    mark = event.start_mark
    return f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""


def _scalar(event: events.ScalarEvent) -> Any:
    tag = event.tag
    if tag is None or tag == "!":
        tag = _RESOLVER.resolve(ScalarNode, event.value, event.implicit)
        if event.implicit[0] and tag == _CORE + "str" and _FLOAT_NO_DOT.fullmatch(event.value):
            return float(event.value)
    elif tag not in _SCALAR_TAGS:
        raise _Refused(f"tag {short(tag, 40)!r} is not allowed{_line(event)}")
    node = ScalarNode(tag, event.value, event.start_mark, event.end_mark, event.style)
    constructor = _CONSTRUCTOR.yaml_constructors.get(tag)
    if constructor is None:
        return event.value
    try:
        return constructor(_CONSTRUCTOR, node)
    except ValueError:  # e.g. an integer of more digits than Python converts
        raise _Refused(f"value {brief(event.value)} cannot be read{_line(event)}") from None


class _Builder:
    """Plain data from YAML events, within the limits."""

    def __init__(self) -> None:
        self.stack: list[list[Any]] = []  # [container, key, has_key] per open collection
        self.root: Any = None
        self.nodes = 0
        self.documents = 0

    def feed(self, event: events.Event) -> None:
        if isinstance(event, events.DocumentStartEvent):
            self.documents += 1
            if self.documents > 1:
                raise _Refused(f"more than one document{_line(event)}")
        elif isinstance(event, events.AliasEvent):
            raise _Refused(f"aliases are not allowed (*{short(event.anchor, 40)}{_line(event)})")
        elif isinstance(event, events.ScalarEvent):
            self._count(event)
            self._add(_scalar(event), event)
        elif isinstance(event, events.CollectionStartEvent):
            self._count(event)
            if event.tag not in _COLLECTION_TAGS:
                raise _Refused(f"tag {short(event.tag, 40)!r} is not allowed{_line(event)}")
            if len(self.stack) >= MAX_DEPTH:
                raise _Refused(f"nested deeper than {MAX_DEPTH} levels{_line(event)}")
            container = {} if isinstance(event, events.MappingStartEvent) else []
            self.stack.append([container, None, False])
        elif isinstance(event, events.CollectionEndEvent):
            self._add(self.stack.pop()[0], event)

    def _count(self, event: events.Event) -> None:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise _Refused(f"more than {MAX_NODES} values{_line(event)}")

    def _add(self, value: Any, event: events.Event) -> None:
        if not self.stack:
            self.root = value
            return
        top = self.stack[-1]
        container = top[0]
        if isinstance(container, list):
            container.append(value)
        elif not top[2]:
            if isinstance(value, dict | list):
                raise _Refused(f"a mapping key must be a scalar{_line(event)}")
            if value in container:
                raise _Refused(f"duplicate key {brief(value)}{_line(event)}")
            top[1], top[2] = value, True
        else:
            container[top[1]] = value
            top[2] = False


def parse_yaml(text: str, where: str, error: type[HlpError] = HlpError) -> Any:
    """The YAML document in ``text`` as plain data (None if empty).

    Raises:
        error: a syntax error (naming ``where``, the line and the column), an alias, a tag other
            than the core scalar and collection tags, a duplicate key, a second document, or more
            than ``MAX_NODES`` values or ``MAX_DEPTH`` levels.
    """
    if len(text) > MAX_DOCUMENT_BYTES:
        raise error(f"{where}: longer than the {MAX_DOCUMENT_BYTES / 2**20:g} MiB a document may have")
    builder = _Builder()
    loader = _LOADER(text)
    try:
        while loader.check_event():
            builder.feed(loader.get_event())
    except _Refused as refused:
        raise error(f"{where}: {refused}") from None
    except yaml.YAMLError as problem:
        mark = getattr(problem, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        reason = getattr(problem, "problem", None) or "syntax error"
        raise error(f"{where}: not valid YAML{at}: {reason}") from None
    finally:
        loader.dispose()
    return builder.root


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    mapping: dict[str, Any] = {}
    for key, value in pairs:
        if key in mapping:
            raise _Refused(f"duplicate key {brief(key)}")
        mapping[key] = value
    return mapping


def check_shape(data: Any) -> None:
    """Raise ``_Refused`` if ``data`` nests deeper than ``MAX_DEPTH`` or holds more than
    ``MAX_NODES`` values (iteratively: any depth is safe to check)."""
    pending = [(data, 0)]
    nodes = 0
    while pending:
        value, depth = pending.pop()
        nodes += 1
        if nodes > MAX_NODES:
            raise _Refused(f"more than {MAX_NODES} values")
        if isinstance(value, dict | list):
            if depth >= MAX_DEPTH:
                raise _Refused(f"nested deeper than {MAX_DEPTH} levels")
            items = value.values() if isinstance(value, dict) else value
            pending.extend((item, depth + 1) for item in items)
            nodes += len(value) if isinstance(value, dict) else 0  # the keys


def parse_json(text: str, where: str, error: type[HlpError] = HlpError) -> Any:
    """The JSON document in ``text`` as plain data, within the same limits as ``parse_yaml``."""
    if len(text) > MAX_DOCUMENT_BYTES:
        raise error(f"{where}: longer than the {MAX_DOCUMENT_BYTES / 2**20:g} MiB a document may have")
    try:
        data = json.loads(text, object_pairs_hook=_unique_keys)
        check_shape(data)
    except _Refused as refused:
        raise error(f"{where}: {refused}") from None
    except RecursionError:
        raise error(f"{where}: nested deeper than {MAX_DEPTH} levels") from None
    except ValueError as problem:  # JSONDecodeError, or an integer of too many digits
        raise error(f"{where}: not valid JSON: {short(str(problem), 120)}") from None
    return data
