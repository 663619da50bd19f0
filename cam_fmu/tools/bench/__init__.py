"""`cam-fmu bench`: the speed-accuracy trade of cam.fmu, measured through fmpy (see run.py)."""
