"""Studies: a grid of conditions run on seeded scenes, ``python -m hlp_drake.experiments``.

- ``study``: ``Study``, an experiment as data (the bundled ``gen1`` and ``gen2``: Tables II and III);
- ``runner``: one (scene, cell) job -> a ``results.csv`` row (the real job, with Drake, is
  ``hlp_drake.systems.run_job``; ``hlp_drake.systems.resolve_study`` reads the scenario and checks
  the cells);
- ``executors``: run jobs in this process, a local process pool or on dask;
- ``results``: ``results.csv`` (columns, reading back, atomic rewrites);
- ``experiment``: ``run_experiment``: resumable runs into a directory;
- ``summary``, ``paper``, ``plots``: the study's table beside the paper's numbers, and PNG plots.

The command line is ``hlp_drake.commands.experiments``.
"""

from hlp_drake.runtime.exports import lazy_exports

__all__ = ["ExperimentSettings", "Job", "ResolvedStudy", "Study", "load_study", "make_row", "run_experiment"]

# Imported on first use: the command's parser needs ``study`` alone (not matplotlib, numpy or shapely).
__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "hlp_drake.experiments.experiment": ("ExperimentSettings", "run_experiment"),
        "hlp_drake.experiments.runner": ("Job", "ResolvedStudy", "make_row"),
        "hlp_drake.experiments.study": ("Study", "load_study"),
    },
)
