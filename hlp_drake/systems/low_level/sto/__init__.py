"""The stochastic trajectory optimiser (``kind: sto``): its settings, rollout worlds and pool, cost,
search and budget, and the planner the registry makes of them (``StoPlanner``)."""
