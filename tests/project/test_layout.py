"""The layout: one package (no package-dir mapping), small modules and functions, a root that holds only
the public API and the command-line entry points (each written one way), one registry per list of names."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest
from conftest import REPO

SOURCES = ("hlp_drake", "tests", "benchmarks", "tools", "examples")
MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 80
ROOT_MODULES = {"__init__.py", "__main__.py", "errors.py"}
"""The root's modules besides the entry points: the package, ``hlp-drake`` and the errors users catch."""


def python_files() -> list[Path]:
    return sorted(p for folder in SOURCES for p in (REPO / folder).rglob("*.py") if ".venv" not in p.parts)


def test_one_package_found_without_a_package_dir_mapping():
    assert "package-dir" not in (REPO / "pyproject.toml").read_text()
    assert not (REPO / "systems").exists() and not (REPO / "models").exists()
    packages = {p.parent for p in (REPO / "hlp_drake").rglob("__init__.py")}
    for folder in (REPO / "hlp_drake").rglob("*"):
        if folder.is_dir() and any(folder.glob("*.py")) and folder.name != "__pycache__":
            assert folder in packages, f"{folder} holds modules but is not a package"


def test_no_module_over_400_lines_and_no_function_over_80_outside_argument_parsers():
    too_long = []
    for path in python_files():
        text = path.read_text()
        if len(text.splitlines()) > MAX_MODULE_LINES:
            too_long.append(f"{path.relative_to(REPO)}: {len(text.splitlines())} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and "parser" not in node.name:
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    too_long.append(f"{path.relative_to(REPO)}:{node.lineno} {node.name}: {length} lines")
    assert too_long == []


def _entry_points() -> dict[Path, str]:
    """Every ``python -m`` module of a command: the root's and the subpackages' ``__main__``."""
    root = {p for p in (REPO / "hlp_drake").glob("*.py") if p.name not in ROOT_MODULES}
    mains = {p for p in (REPO / "hlp_drake").glob("*/__main__.py")}
    return {p: p.read_text() for p in sorted(root | mains)}


def test_the_root_holds_the_public_api_and_the_entry_points_each_written_one_way():
    from hlp_drake.commands import COMMANDS

    entry_points = _entry_points()
    named = []
    for path, text in entry_points.items():
        tree = ast.parse(text)
        docstring, imported, guard = tree.body
        assert isinstance(docstring.value, ast.Constant)
        assert ast.unparse(imported) == "from hlp_drake.commands import run_command"
        (call,) = guard.body
        assert ast.unparse(guard.test) == "__name__ == '__main__'"
        command = call.exc.args[0].args[0].value  # raise SystemExit(run_command("NAME"))
        assert command in COMMANDS, path
        module = "hlp_drake." + ".".join(path.relative_to(REPO / "hlp_drake").with_suffix("").parts)
        assert module.removesuffix(".__main__") == f"hlp_drake.{COMMANDS[command].replace('-', '_')}"
        named.append(command)
    assert sorted(named) == sorted(COMMANDS)  # one entry point a command
    for name in COMMANDS.values():  # every command's main in hlp_drake.commands
        assert callable(importlib.import_module(f"hlp_drake.commands.{name}").main)


@pytest.mark.parametrize("several", [False, True])
def test_the_command_lines_names_come_from_the_registries(several):
    import argparse

    from hlp_drake.commands.parsing import add_planner_options
    from hlp_drake.systems.low_level.registry import LOW_LEVEL_PLANNERS
    from hlp_drake.systems.planning.initialisers import ALIASES, INITIALISERS

    parser = argparse.ArgumentParser()
    add_planner_options(parser, several=several)
    actions = {a.dest: a for a in parser._actions}
    assert actions["planner"].choices == (*INITIALISERS, *ALIASES)
    assert actions["low_level"].choices == tuple(LOW_LEVEL_PLANNERS)
