"""The run loop: a controller with trackers, the result of a run, the discrete state read as a solution."""
