"""What starting up imports, each in a fresh interpreter: a rollout worker imports what rollouts need,
a command's help or usage error imports no numerical library, and the lazy packages' names all resolve."""

from __future__ import annotations

import subprocess
import sys

import pytest

WORKER_UNNEEDED = ("sklearn", "pandas", "matplotlib", "scipy.stats")
"""Libraries a rollout never uses (the planner's learners, the dataset's tables, plots)."""
NUMERICAL = ("pydrake", "sklearn", "scipy", "numpy", "pandas", "matplotlib", "shapely", "yaml")
LAZY_PACKAGES = (
    "hlp_drake.systems",
    "hlp_drake.scene",
    "hlp_drake.segmentation",
    "hlp_drake.planner",
    "hlp_drake.experiments",
)


def _modules_after(code: str) -> tuple[int | None, set[str]]:
    """Run ``code`` in a fresh interpreter (which must not fail): its exit code (None: it did not
    exit) and the modules it imported."""
    probe = (
        "import sys\ncode = None\n"
        f"try:\n    exec({code!r})\nexcept SystemExit as exit:\n    code = exit.code\n"
        "print('\\nexit', code, 'modules', *sys.modules)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=False, timeout=600
    )
    assert result.returncode == 0, result.stderr
    _, exit_code, _, *modules = result.stdout.splitlines()[-1].split()
    return (None if exit_code == "None" else int(exit_code)), set(modules)


def _loaded(modules: set[str], names: tuple[str, ...]) -> list[str]:
    """The modules of ``names`` (each a module or a package) among ``modules``."""
    return sorted(m for m in modules if any(m == n or m.startswith(f"{n}.") for n in names))


def test_a_rollout_worker_imports_no_learner_dataset_or_plotting_library():
    # A worker unpickles its task (importing the pool) and reads its scenario (load_scenario).
    _, modules = _modules_after(
        "import hlp_drake.systems.low_level.sto.pool\nfrom hlp_drake.systems.scenario import load_scenario"
    )
    assert "hlp_drake.systems.low_level.sto.rollout_world" in modules
    assert not _loaded(modules, WORKER_UNNEEDED)
    unused = ("perception.perception", "perception.system", "execution.diagram", "execution.run")
    assert not _loaded(modules, tuple(f"hlp_drake.systems.{name}" for name in unused))
    assert not _loaded(modules, ("hlp_drake.learners", "hlp_drake.dataset", "hlp_drake.planner.hlp"))


@pytest.mark.parametrize(
    ("argv", "exit_code"),
    [
        (["--help"], 0),
        (["--version"], 0),
        (["--kind", "nowhere"], 2),
        (["--seed", "3"], 2),
        (["--workers", "0"], 2),
    ],
)
def test_run_scene_help_version_and_usage_errors_import_no_numerical_library(argv, exit_code):
    for module, prefix in (("hlp_drake.run_scene", []), ("hlp_drake", ["run-scene"])):
        code, modules = _modules_after(
            f"import runpy\nsys.argv = {['prog', *prefix, *argv]!r}\n"
            f"runpy.run_module({module!r}, run_name='__main__', alter_sys=True)"
        )
        assert code == exit_code
        assert not _loaded(modules, NUMERICAL), module


@pytest.mark.parametrize(
    ("argv", "exit_code"), [(["--help"], 0), (["--version"], 0), (["gen1", "--scenes", "0", "--out", "x"], 2)]
)
def test_experiments_help_version_and_usage_errors_import_no_numerical_library(argv, exit_code):
    """``experiments --help`` took 0.5 s importing matplotlib, numpy and shapely; now what
    ``run_scene --help`` takes."""
    for module, prefix in (("hlp_drake.experiments", []), ("hlp_drake", ["experiments"])):
        code, modules = _modules_after(
            f"import runpy\nsys.argv = {['prog', *prefix, *argv]!r}\n"
            f"runpy.run_module({module!r}, run_name='__main__', alter_sys=True)"
        )
        assert code == exit_code
        assert not _loaded(modules, NUMERICAL), (module, _loaded(modules, NUMERICAL))


def test_importing_hlp_drake_systems_imports_no_drake():
    _, modules = _modules_after("import hlp_drake.systems")
    assert not _loaded(modules, NUMERICAL)


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_every_public_name_of_a_lazy_package_resolves(package):
    # No name may resolve to a submodule of the same name (``hlp_drake.planner.plan`` is the planner).
    _modules_after(
        f"import types\nimport {package} as package\n"
        "for name in package.__all__:\n"
        "    assert not isinstance(getattr(package, name), types.ModuleType), name\n"
        "    assert name in dir(package), name\n"
        "namespace = {}\n"
        f"exec('from {package} import *', namespace)\n"
        "assert set(package.__all__) <= set(namespace)\n"
        "assert not hasattr(package, 'no_such_name')\n"
    )


def test_the_planner_package_plan_is_the_planner_after_its_submodule_plan_is_imported():
    _modules_after(
        "import hlp_drake.planner.plan\nfrom hlp_drake.planner import plan\n"
        "from hlp_drake.planner.hlp import plan as planner\nassert plan is planner\n"
    )
