"""The simulated world: the robot, the scene's bodies and scene source, model error and the world diagram."""
