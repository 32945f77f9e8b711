"""The stochastic trajectory optimiser: control sequences, rollout worlds, their cost and pool."""
