"""A package's public names imported on first use (PEP 562).

A package whose ``__init__`` imported every module its names come from would make importing any one
of its modules (a rollout worker importing the pool, a command parsing its arguments) import all of
them, and the libraries they use. ``lazy_exports`` gives such a package the module ``__getattr__``
and ``__dir__`` instead: ``from package import name`` imports only the module that defines ``name``.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping


def lazy_exports(
    package: str, exports: Mapping[str, tuple[str, ...]]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package``, whose public names ``exports`` lists by the
    module that defines them: a name's first look-up imports its module and makes the name a global
    of the package (later look-ups find it there)."""
    module_of = {name: module for module, names in exports.items() for name in names}

    def __getattr__(name: str) -> object:
        if name not in module_of:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module_of[name]), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted({*vars(sys.modules[package]), *module_of})

    return __getattr__, __dir__
