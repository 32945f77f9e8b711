"""The human-like planner (Algorithm 1 of the paper) and its output, ``HighLevelPlan``."""

from hlp_drake.planner.config import PlannerConfig
from hlp_drake.planner.plan import ACTIONS, HighLevelPlan, PlanCandidate, PlanKeypoint
from hlp_drake.runtime.exports import lazy_exports

__all__ = ["ACTIONS", "HighLevelPlan", "PlanCandidate", "PlanKeypoint", "PlannerConfig", "plan"]

# ``plan`` is the planner function, imported on first use (with the features it computes): the
# scenario's settings need only the two modules above. Importing the submodule ``plan`` made it the
# package's attribute ``plan``; removed, the name's look-up reaches ``__getattr__`` (a submodule
# already imported is not bound again).
del globals()["plan"]
__getattr__, __dir__ = lazy_exports(__name__, {"hlp_drake.planner.hlp": ("plan",)})
