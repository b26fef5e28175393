"""The run loop: a controller with trackers, a run's result, the state read as a solution."""
