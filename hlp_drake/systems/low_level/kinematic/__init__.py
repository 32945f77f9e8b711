"""Kinematic low-level planners: they plan a collision-free joint path in the robot's configuration
space (no physics) and leave the pushes to the world. ``world``: the robot, the table and the
objects the path must avoid; ``waypoints``: the initialiser's sub-goals and what it may touch;
``timing``: a path timed into a commanded motion; ``planner``: what every kinematic planner does;
``trajopt``: Drake's ``KinematicTrajectoryOptimization``; ``rrt``: OMPL's RRT-Connect."""
