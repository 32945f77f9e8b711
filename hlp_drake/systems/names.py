"""The names a command line and a study take for the run's settings, importing nothing else: where the
planners' scene comes from (``perception.source``) and how the motion is executed. The initialisers'
and the low-level planners' names are their registries' (``planning.initialisers``,
``low_level.registry``)."""

from typing import Literal, get_args

PerceptionSource = Literal["truth", "camera"]
"""A ``perception.source``."""
PERCEPTION_SOURCES: tuple[str, ...] = get_args(PerceptionSource)
"""``truth``: the plant's body poses; ``camera``: what the world's cameras see."""
EXECUTIONS = ("open", "closed")
"""``open``: play the planned motion; ``closed``: the receding-horizon controller re-plans it."""
WorldName = Literal["model", "reference"]
"""A ``world.kind``: what the robot acts in and the run is judged in."""
WORLDS: tuple[str, ...] = get_args(WorldName)
"""``reference``: physics finer than the planner's model (``WorldConfig``); ``model``: the planner's
own model (the execution replays the low-level planner's accepted rollout)."""
