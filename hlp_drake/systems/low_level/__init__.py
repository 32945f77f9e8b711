"""Low-level planners: they turn the initialiser's keyframes into the robot's commanded motion.

``protocol``: what every planner is (settings, problem, planner); ``registry``: the planners by
name; ``system``: their Drake block; ``result``, ``outcome``, ``control_sequence``: what they
return and command; ``sto``: the physics-based stochastic trajectory optimiser.
"""
