"""Developer tools: the bench and native-host helpers (not bundled into the FMU)."""
