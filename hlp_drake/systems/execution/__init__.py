"""Execution: the execution diagram and its run (reach, grasp), closed-loop control, MeshCat drawing and
the experiments' job."""
