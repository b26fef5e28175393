"""The problem: scene files, physical parameters, the drive, exact steady solutions."""
