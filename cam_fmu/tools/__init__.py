"""Developer tools: the bench and native-host helpers (no FMU carries them)."""
