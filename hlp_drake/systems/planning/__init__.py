"""Planning blocks: the planners, the push transfer, keypoint IK and the planning diagram."""
