"""Typed YAML files: frozen dataclass schemas read with Drake's ``yaml_load_typed``, errors located.

A schema is a frozen dataclass whose fields are floats, ints, bools, strings, ``Literal`` strings,
tuples (``tuple[float, float]`` of a fixed length or ``tuple[X, ...]``), ``X | None``, other schemas
or Drake's bound config structs (e.g. ``MultibodyPlantConfig``). Drake's loader writes into mutable
objects and knows lists, not tuples, so a document is read into a mutable twin of the schema (lists
for tuples, ``str`` for ``Literal``) and frozen again.

Before that, the document is checked against the schema and every problem is reported at its
place, one line each (``obstacles[0].size: expected a list of 3 numbers, got [1, 2]``), which
Drake's loader cannot do: types, finite numbers (at most ``MAX_FLOAT``), 64-bit integers. A
schema with a field without a default (a scene, an object) is read whole: such a mapping must give
every required field and does not merge into a default. A schema whose every field has a default
merges into the defaults: a file gives only what it changes. A whole schema without Drake structs
(a scene) is then built directly from the checked document, the rest by Drake's loader. Documents
come from ``hlp_drake.documents`` (``parse_yaml``: limits on size, depth, aliases, duplicate keys).

Drake's YAML module is imported on the first load or dump only (it costs ~0.3 s), so the Drake-free
half of the package stays quick to import.
"""

from __future__ import annotations

import dataclasses
import functools
import types
import typing
from typing import Any, Literal, TypeVar

import yaml

from hlp_drake.documents import brief
from hlp_drake.errors import HlpError

T = TypeVar("T")
NoneType = type(None)
MAX_FLOAT = 1e300
"""Largest magnitude of a number in a document (inf, nan and integers beyond it are refused)."""


# --- Schema types -------------------------------------------------------------------------------


@functools.cache
def _hints(schema: type) -> dict[str, Any]:
    """A schema's field types, with string annotations resolved."""
    return typing.get_type_hints(schema)


def _is_schema(kind: Any) -> bool:
    return isinstance(kind, type) and dataclasses.is_dataclass(kind)


def _is_drake_struct(kind: Any) -> bool:
    return isinstance(kind, type) and hasattr(kind, "__fields__") and not _is_schema(kind)


@functools.cache
def _optional(kind: Any) -> Any:
    """``X`` for ``X | None``, else None."""
    if typing.get_origin(kind) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(kind) if a is not NoneType]
        if len(args) == 1 and len(typing.get_args(kind)) == 2:
            return args[0]
    return None


@functools.cache
def _required(schema: type) -> list[str]:
    """The fields of ``schema`` that have no default."""
    return [
        f.name
        for f in dataclasses.fields(schema)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]


def _whole(schema: type) -> bool:
    """Whether a mapping of ``schema`` is read whole (it has required fields) rather than merged."""
    return bool(_required(schema))


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


@functools.cache
def _thawed(schema: type) -> type:
    """A mutable dataclass with the fields of ``schema``: lists for tuples, ``str`` for literals,
    None as the default of a required field (filled by the document, else reported missing)."""
    fields = []
    for f in dataclasses.fields(schema):
        kind = _thawed_type(_hints(schema)[f.name])
        if f.default is not dataclasses.MISSING:
            default = _thaw(f.default)
            spec = dataclasses.field(default_factory=functools.partial(_thaw, default))
        elif f.default_factory is not dataclasses.MISSING:
            spec = dataclasses.field(default_factory=lambda factory=f.default_factory: _thaw(factory()))
        else:
            kind, spec = kind | None, dataclasses.field(default=None)
        fields.append((f.name, kind, spec))
    return dataclasses.make_dataclass(schema.__name__, fields)


def _thawed_type(kind: Any) -> Any:
    inner = _optional(kind)
    if inner is not None:
        return _thawed_type(inner) | None
    if typing.get_origin(kind) is Literal:
        return str
    items = _tuple_items(kind)
    if items is not None:
        return list[_thawed_type(items[0])]
    return _thawed(kind) if _is_schema(kind) else kind


def _thaw(value: Any) -> Any:
    """``value`` as its mutable twin (a copy: a default is never shared)."""
    if _is_schema(type(value)):
        twin = _thawed(type(value))
        return twin(**{f.name: _thaw(getattr(value, f.name)) for f in dataclasses.fields(value)})
    if isinstance(value, tuple | list):
        return [_thaw(v) for v in value]
    if _is_drake_struct(type(value)):
        return type(value)(**{f.name: getattr(value, f.name) for f in type(value).__fields__})
    return value


def _freeze(schema: Any, value: Any) -> Any:
    """The mutable twin ``value`` as an instance of ``schema``."""
    inner = _optional(schema)
    if inner is not None:
        return None if value is None else _freeze(inner, value)
    if _is_schema(schema):
        hints = _hints(schema)
        return schema(
            **{f.name: _freeze(hints[f.name], getattr(value, f.name)) for f in dataclasses.fields(schema)}
        )
    items = _tuple_items(schema)
    if items is not None:
        return tuple(_freeze(items[0], v) for v in value)
    return value


# --- Located problems -------------------------------------------------------------------------------


MAX_INT = 2**63 - 1
"""Largest integer a document may give (Drake reads 64-bit integers)."""


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


def _join(where: str, name: str) -> str:
    return f"{where}.{name}" if where else name


def document_problems(schema: Any, value: Any, where: str = "", *, top: str = "document") -> list[str]:
    """Every place where the parsed YAML ``value`` does not fit ``schema``, one message each.

    Args:
        where: the path of ``value`` in the document ("" at the top, where ``top`` names it).
    """
    label = where or top
    inner = _optional(schema)
    if inner is not None:
        return [] if value is None else document_problems(inner, value, where, top=top)
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
        if _is_schema(schema):
            hints, required = _hints(schema), _required(schema)
        else:
            hints, required = {f.name: f.type for f in schema.__fields__}, []
        problems = [f"{label}: unknown field {key!r}" for key in value if key not in hints]
        problems += [f"{label}: missing field {name!r}" for name in required if name not in value]
        for name, sub in value.items():
            if name in hints:
                problems += document_problems(hints[name], sub, _join(where, name), top=top)
        return problems
    problem = _scalar_problem(schema, value)
    return [] if problem is None else [f"{label}: {problem}"]


# --- Loading and dumping -------------------------------------------------------------------------------


@functools.cache
def _plain(kind: Any) -> bool:
    """Whether values of ``kind`` hold no Drake struct (so they are built without Drake's loader)."""
    inner = _optional(kind)
    if inner is not None:
        return _plain(inner)
    items = _tuple_items(kind)
    if items is not None:
        return _plain(items[0])
    if _is_schema(kind):
        return all(_plain(hint) for hint in _hints(kind).values())
    return not _is_drake_struct(kind)


def _build(kind: Any, value: Any) -> Any:
    """The checked document ``value`` as an instance of the plain type ``kind`` (fields it does not
    give take their defaults, as Drake's loader fills them)."""
    inner = _optional(kind)
    if inner is not None:
        return None if value is None else _build(inner, value)
    items = _tuple_items(kind)
    if items is not None:
        return tuple(_build(items[0], v) for v in value)
    if _is_schema(kind):
        hints = _hints(kind)
        return kind(**{name: _build(hints[name], v) for name, v in value.items()})
    return float(value) if kind is float else value


def _clear_whole(schema: type, base: Any, document: Any) -> None:
    """Replace every default in ``base`` that ``document`` gives a whole value for by a blank one."""
    if not isinstance(document, dict):
        return
    for name, kind in _hints(schema).items():
        kind = _optional(kind) or kind
        if name in document and _is_schema(kind):
            if _whole(kind):
                setattr(base, name, _thawed(kind)())
            elif getattr(base, name) is not None:
                _clear_whole(kind, getattr(base, name), document[name])


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
    problems = document_problems(schema, document, top=top)
    if problems:
        raise error(*(prefix + p for p in problems))
    if defaults is None and _plain(schema):
        return _build(schema, document)
    # Whole plain fields (a scenario's scene) are built directly: Drake's loader would take ~1 s
    # per thousand objects to read what is already checked.
    from pydrake.common.yaml import yaml_load_typed

    hints = _hints(schema)
    direct = {
        name: _build(hints[name], sub)
        for name, sub in (document or {}).items()
        if _is_schema(hints[name]) and _whole(hints[name]) and _plain(hints[name])
    }
    document = {name: sub for name, sub in (document or {}).items() if name not in direct}
    base = _thaw(defaults) if defaults is not None else _thawed(schema)()
    _clear_whole(schema, base, document)
    try:
        loaded = yaml_load_typed(schema=_thawed(schema), data=yaml.safe_dump(document), defaults=base)
    except (RuntimeError, ValueError, TypeError, KeyError, AssertionError) as problem:
        raise error(prefix + " ".join(str(problem).split())) from None
    return dataclasses.replace(_freeze(schema, loaded), **direct)


def dump_typed(value: Any) -> str:
    """``value`` (a schema instance) as YAML text that ``load_typed`` reads back to an equal value."""
    from pydrake.common.yaml import yaml_dump_typed

    return yaml_dump_typed(_thaw(value))
