"""hlp_drake: human-like planning for reaching in clutter, executed in Drake.

The algorithm half (``hlp_drake.scene``, ``hlp_drake.dataset``, ...) imports no Drake; the Drake blocks
live in ``hlp_drake.systems``.
"""

import logging as _logging
import os as _os

__version__ = "0.1.0"

DRAKE_LOG = "HLP_DRAKE_LOG"
"""The environment variable by which a command (``hlp_drake.commands.parsing.drake_logging``) tells its own process
and every process it starts (a process pool's or dask's workers, which inherit it) whether Drake's
INFO lines are shown: ``warning`` keeps them out, anything else (or unset) lets them through."""


def _drake_record_shown(record: _logging.LogRecord) -> bool:
    """Whether Drake's logger passes ``record`` on: its warnings and errors always, its INFO lines
    unless ``DRAKE_LOG`` says ``warning`` (read for each record: a command may set it after import)."""
    return record.levelno >= _logging.WARNING or _os.environ.get(DRAKE_LOG) != "warning"


# On the logger, not a level: pydrake sets the "drake" logger's level when it is imported, later.
_logging.getLogger("drake").addFilter(_drake_record_shown)
