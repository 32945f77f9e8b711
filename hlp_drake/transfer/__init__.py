"""The push transfer: a person's plan of lifted obstacles becomes a robot's plan of pushes (pure geometry, no Drake)."""
