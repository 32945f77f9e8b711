"""Execution: the reach, grasp and closed-loop control in the world, and MeshCat drawing."""
