"""The paper's Generalization I and II experiments (Tables II and III): ``python -m hlp_drake.experiments``.

- ``runner``: one (scene, planner) job -> a ``results.csv`` row (the real job, with Drake, is
  ``hlp_drake.systems.run_job``; ``hlp_drake.systems.scenario_yamls`` reads the scenario);
- ``executors``: run jobs in this process, a local process pool or on dask;
- ``results``: ``results.csv`` (columns, reading back, atomic rewrites);
- ``experiment``: ``run_experiment``: resumable runs into a directory;
- ``summary``, ``plots``: the paper-format tables beside the paper's numbers, and PNG plots;
- ``cli``: the command line.
"""

from hlp_drake.experiments.experiment import ExperimentSettings, run_experiment
from hlp_drake.experiments.runner import Job, ScenarioYamls, make_row

__all__ = ["ExperimentSettings", "Job", "ScenarioYamls", "make_row", "run_experiment"]
