"""Controllers for the cam drive, as plain Python (no FMU): the sampled PI speed law."""
