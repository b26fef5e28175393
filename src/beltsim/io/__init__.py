"""Reading and writing files: atomic writers, a run's outputs, snapshots and checkpoints."""
