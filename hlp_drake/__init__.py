"""hlp_drake: human-like planning for reaching in clutter, executed in Drake.

The algorithm half (``hlp_drake.scene``, ``hlp_drake.dataset``, ...) imports no Drake; the Drake blocks
live in ``hlp_drake.systems``.
"""

__version__ = "0.1.0"
