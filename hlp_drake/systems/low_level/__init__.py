"""Low-level planners: they turn the initialiser's keyframes into the robot's commanded motion.

``control_sequence``: the robot's positions over time, what every planner commands; ``sto``: the
physics-based stochastic trajectory optimiser.
"""
