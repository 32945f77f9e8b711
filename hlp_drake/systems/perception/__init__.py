"""Perception: simulated depth cameras to a scene of fitted objects, and its accuracy."""
