"""Experiments: scenes (shipped in scene_files/), the one fmpy runner, running a scene on an engine,
co-simulation of SSPs, frequency responses and sweeps."""
