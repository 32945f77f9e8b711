"""The simulated world: the robot, the scene's bodies, cameras, model error and the world diagram."""
