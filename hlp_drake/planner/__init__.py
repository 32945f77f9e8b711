"""The human-like planner (Algorithm 1 of the paper) and its output, ``HighLevelPlan``."""

from hlp_drake.planner.config import PlannerConfig
from hlp_drake.planner.hlp import plan
from hlp_drake.planner.plan import ACTIONS, HighLevelPlan, PlanCandidate, PlanKeypoint

__all__ = ["ACTIONS", "HighLevelPlan", "PlanCandidate", "PlanKeypoint", "PlannerConfig", "plan"]
