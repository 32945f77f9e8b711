"""Typed YAML documents: frozen dataclass schemas, every problem located on its own line.

A schema is a frozen dataclass whose fields are floats, ints, bools, strings, ``Literal`` strings,
tuples (``tuple[float, float]`` of a fixed length or ``tuple[X, ...]``), ``X | None``, other schemas,
tagged unions (a schema with a class method ``variants()``: its subclasses by the name its ``TAG``
field holds, e.g. ``planner.low_level: {kind: sto, ...}``) or Drake's bound config structs (e.g.
``MultibodyPlantConfig``).

A document (``hlp_drake.files.documents.parse_yaml``: limits on size, depth, aliases, duplicate keys) is
checked against the schema first, every problem reported at its place, one line each
(``obstacles[0].size: expected a list of 3 numbers, got [1, 2]``): types, finite numbers (at most
``MAX_FLOAT``), 64-bit integers, unknown and missing fields. The checked document is then read over
the defaults: a schema whose every field has a default merges into its default (a file gives only
what it changes); a schema with a required field (a scene, an object) is read whole from its
mapping, as is an item of a list (fields it omits take their class defaults); a list replaces the
default one. A Drake struct is merged by Drake's ``yaml_load_typed`` (imported then: it costs
~0.3 s). ``dump_typed`` writes the layout of Drake's ``yaml_dump_typed``.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import hashlib
import types
import typing
from typing import Any, Literal, TypeVar

import yaml

from hlp_drake.config.ranges import join_path
from hlp_drake.errors import HlpError
from hlp_drake.files.documents import brief

T = TypeVar("T")
NoneType = type(None)
MAX_FLOAT = 1e300
"""Largest magnitude of a number in a document (inf, nan and integers beyond it are refused)."""
MAX_INT = 2**63 - 1
"""Largest integer a document may give (Drake reads 64-bit integers)."""


# --- Schema types -------------------------------------------------------------------------------


def _is_schema(kind: Any) -> bool:
    return isinstance(kind, type) and dataclasses.is_dataclass(kind)


def _is_drake_struct(kind: Any) -> bool:
    return isinstance(kind, type) and hasattr(kind, "__fields__") and not _is_schema(kind)


@functools.cache
def _fields(kind: type) -> dict[str, Any]:
    """The field types of a schema (string annotations resolved) or of a Drake struct."""
    if _is_schema(kind):
        hints = typing.get_type_hints(kind)
        return {f.name: hints[f.name] for f in dataclasses.fields(kind)}  # no ClassVar
    return {f.name: f.type for f in kind.__fields__}


@functools.cache
def _required(kind: type) -> list[str]:
    """The fields of a schema that have no default (a schema with any is read whole)."""
    if not _is_schema(kind):
        return []
    return [
        f.name
        for f in dataclasses.fields(kind)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]


def _variants(kind: Any) -> dict[str, type] | None:
    """The variants of a tagged union (a schema that defines a ``variants()`` class method: its
    subclasses, which inherit it, by the name its ``TAG`` field holds), else None."""
    variants = getattr(kind, "variants", None) if _is_schema(kind) and "variants" in vars(kind) else None
    return dict(variants()) if callable(variants) else None


@functools.cache
def _optional(kind: Any) -> Any:
    """``X`` for ``X | None``, else None."""
    if typing.get_origin(kind) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(kind) if a is not NoneType]
        if len(args) == 1 and len(typing.get_args(kind)) == 2:
            return args[0]
    return None


@functools.cache
def _tuple_items(kind: Any) -> tuple[Any, int | None] | None:
    """(item type, fixed length or None) of a tuple type, else None."""
    if typing.get_origin(kind) is not tuple:
        return None
    args = typing.get_args(kind)
    if len(args) == 2 and args[1] is Ellipsis:
        return args[0], None
    if len(set(args)) != 1:
        raise TypeError(f"tuple fields must hold one type, got {kind}")
    return args[0], len(args)


# --- Located problems -------------------------------------------------------------------------------


def _scalar_problem(kind: Any, value: Any) -> str | None:
    """Why ``value`` cannot be read as the scalar type ``kind`` (None if it can)."""
    if typing.get_origin(kind) is Literal:
        choices = typing.get_args(kind)
        ok = isinstance(value, str) and value in choices
        return None if ok else f"expected one of {', '.join(map(str, choices))}, got {brief(value)}"
    expected = {float: "a number", int: "an integer", bool: "true or false", str: "text"}.get(kind)
    if expected is None:
        return None
    ok = {
        float: isinstance(value, int | float) and not isinstance(value, bool),
        int: isinstance(value, int) and not isinstance(value, bool),
        bool: isinstance(value, bool),
        str: isinstance(value, str),
    }[kind]
    if not ok:
        return f"expected {expected}, got {brief(value)}"
    if kind is int and abs(value) > MAX_INT:
        return f"expected an integer of at most 64 bits, got {brief(value)}"
    if kind is float and not (abs(value) <= MAX_FLOAT):  # also refuses nan
        return f"expected a finite number, got {brief(value)}"
    return None


def _variant_problems(
    base: type, variants: dict[str, type], value: Any, default: Any, label: str
) -> tuple[type | None, list[str]]:
    """(the variant of the tagged union ``base`` that ``value`` names, or its ``default``'s; the
    problems of the tag and of fields that belong to other variants)."""
    if not isinstance(value, dict):
        return None, [f"{label}: expected a mapping, got {type(value).__name__}"]
    tag = base.TAG
    name = value.get(tag, getattr(default, tag, None))
    known = ", ".join(variants)
    if name not in variants:
        given = f"unknown {base.NOUN} {name!r}" if name is not None else f"missing field {tag!r}"
        return None, [f"{label}.{tag}: {given} (known: {known})"]
    kind, problems = variants[name], []
    own = _fields(kind)
    for key in value:
        owners = [other for other, cls in variants.items() if key in _fields(cls)]
        if key not in own and owners:
            problems.append(
                f"{label}: {key!r} is a setting of {' and '.join(owners)}, not of {name} "
                f"(the {base.NOUN}s: {known}; give its {tag} to use another)"
            )
    return kind, problems


def _did_you_mean(key: Any, known: Any) -> str:
    """``; did you mean 'planner'?`` when ``key`` is close to one of the ``known`` names, else ""."""
    close = difflib.get_close_matches(str(key), list(known), n=1, cutoff=0.75)
    return f"; did you mean {close[0]!r}?" if close else ""


def document_problems(
    schema: Any, value: Any, where: str = "", *, top: str = "document", default: Any = None
) -> list[str]:
    """Every place where the parsed YAML ``value`` does not fit ``schema``, one message each.

    Args:
        where: the path of ``value`` in the document ("" at the top, where ``top`` names it).
        default: what ``value`` is read over (None: the class defaults); a tagged union's variant is
            the one ``value`` names, else its default's.
    """
    label = where or top
    inner = _optional(schema)
    if inner is not None:
        return [] if value is None else document_problems(inner, value, where, top=top)
    variants = _variants(schema)
    if variants is not None:
        kind, problems = _variant_problems(schema, variants, value, default, label)
        if kind is None or problems:
            return problems
        same = default if type(default) is kind else None
        return document_problems(kind, value, where, top=top, default=same)
    items = _tuple_items(schema)
    if items is not None:
        item, length = items
        noun = {float: "numbers", int: "integers", str: "texts"}.get(item, "entries")
        if not isinstance(value, list) or (length is not None and len(value) != length):
            count = "a list" if length is None else f"a list of {length} {noun}"
            if isinstance(value, list | dict) and length is None:
                return [f"{label}: expected a list, got {type(value).__name__}"]
            return [f"{label}: expected {count}, got {brief(value)}"]
        return [p for i, v in enumerate(value) for p in document_problems(item, v, f"{label}[{i}]", top=top)]
    if _is_schema(schema) or _is_drake_struct(schema):
        if not isinstance(value, dict):
            return [f"{label}: expected a mapping, got {type(value).__name__}"]
        hints = _fields(schema)
        problems = [
            f"{label}: unknown field {key!r}{_did_you_mean(key, hints)}" for key in value if key not in hints
        ]
        problems += [f"{label}: missing field {name!r}" for name in _required(schema) if name not in value]
        merged = default is not None and not _required(schema)
        for name, sub in value.items():
            if name in hints:
                below = getattr(default, name, None) if merged else None
                problems += document_problems(
                    hints[name], sub, join_path(where, name), top=top, default=below
                )
        return problems
    problem = _scalar_problem(schema, value)
    return [] if problem is None else [f"{label}: {problem}"]


# --- Loading and dumping -------------------------------------------------------------------------------


def _read(kind: Any, default: Any, value: Any) -> Any:
    """The checked document ``value`` as a ``kind`` over ``default`` (None: the class defaults)."""
    inner = _optional(kind)
    if inner is not None:
        return None if value is None else _read(inner, default, value)
    items = _tuple_items(kind)
    if items is not None:
        return tuple(_read(items[0], None, v) for v in value)
    if _is_drake_struct(kind):
        from pydrake.common.yaml import yaml_load_typed

        return yaml_load_typed(schema=kind, data=yaml.safe_dump(value), defaults=default)
    if not _is_schema(kind):
        return float(value) if kind is float else value
    variants = _variants(kind)
    if variants is not None:
        chosen = variants[value.get(kind.TAG, getattr(default, kind.TAG, None))]
        return _read(chosen, default if type(default) is chosen else None, value)
    hints = _fields(kind)
    if default is None or _required(kind):
        return kind(**{name: _read(hints[name], None, v) for name, v in value.items()})
    # A Drake struct is mutable: each read gets its own copy, as Drake's loader gives.
    changes = {
        name: _read(hint, getattr(default, name), value.get(name, {}))
        for name, hint in hints.items()
        if name in value or _is_drake_struct(hint)
    }
    return dataclasses.replace(default, **changes)


def load_typed(
    schema: type[T],
    document: Any,
    *,
    defaults: T | None = None,
    where: str = "",
    top: str = "document",
    error: type[HlpError] = HlpError,
) -> T:
    """``document`` (parsed YAML, e.g. from ``parse_yaml``) read as ``schema`` over ``defaults``.

    An empty document (None) gives the defaults. Every problem is one line, ``{where}: {path}:
    {problem}`` (the path is ``top`` at the top of the document).

    Raises:
        error: the document does not fit the schema.
    """
    if document is None and defaults is not None:
        return defaults
    prefix = f"{where}: " if where else ""
    problems = document_problems(schema, document, top=top, default=defaults)
    if problems:
        raise error(*(prefix + p for p in problems))
    return _read(schema, defaults, document)


def _plain(kind: Any, value: Any) -> Any:
    """``value`` of type ``kind`` as plain data, as Drake's ``yaml_dump_typed`` gives it (a None
    is left out where the field may be None or is required)."""
    inner = _optional(kind)
    if inner is not None:
        return None if value is None else _plain(inner, value)
    items = _tuple_items(kind)
    if items is not None:
        return [_plain(items[0], v) for v in value]
    if _variants(kind) is not None:
        kind = type(value)  # a tagged union's variant
    if _is_schema(kind) or _is_drake_struct(kind):
        data = {}
        for name, hint in _fields(kind).items():
            item = getattr(value, name)
            if item is not None or (_optional(hint) is None and name not in _required(kind)):
                data[name] = _plain(hint, item)
        return data
    return str(value) if typing.get_origin(kind) is Literal else kind(value)


class _Dumper(yaml.SafeDumper):
    """The layout of Drake's ``yaml_dump_typed``: a mapping on one line only when it is empty."""

    def serialize_node(self, node: yaml.Node, parent: Any, index: Any) -> None:
        if isinstance(node, yaml.MappingNode):
            node.flow_style = not node.value
        return super().serialize_node(node, parent, index)


def dump_typed(value: Any) -> str:
    """``value`` (a schema instance) as YAML text that ``load_typed`` reads back to an equal value."""
    return yaml.dump(_plain(type(value), value), Dumper=_Dumper, default_flow_style=None, sort_keys=False)


class Documented:
    """A frozen schema dataclass's YAML text (``yaml``, ``dump_typed``) and its digest (``key``: equal
    for equal values), each computed once."""

    @functools.cached_property
    def yaml(self) -> str:
        """The value as YAML text that ``load_typed`` reads back (computed once)."""
        return dump_typed(self)

    @functools.cached_property
    def key(self) -> str:
        """A digest of ``yaml``: equal for equal values (computed once)."""
        return hashlib.sha256(self.yaml.encode()).hexdigest()
