"""Experiments: input signals, scenes (shipped in scene_files/), the one fmpy runner,
the one place that finds or builds cam.fmu, and running a scene on an engine."""
