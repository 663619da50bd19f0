"""Run cam.fmu with fmpy's FMU2Slave and print theta, omega, s (JSON): fig. 6 for 2 s, backlash (c = 0.5 mm)
for 1 s, and a state saved at 0.5 s, stepped on, restored and stepped on again. Any Python with fmpy runs it;
it imports nothing of cam_fmu. Usage: python fmpy_driver.py UNZIPPED_FMU_DIR"""
import json
import sys

from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave

NAMES = ("theta", "omega", "s")


def run(unzipped, md, start, steps, state_at=None):
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="cam", instanceName="probe")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for name, value in start.items():
        fmu.setReal([vr[name]], [value])
    fmu.exitInitializationMode()
    t, again = 0.0, None
    for k in range(steps):
        if state_at is not None and k == state_at:
            state = fmu.getFMUstate()
            for j in range(state_at, steps):
                fmu.doStep(j * 1e-3, 1e-3)
            again = fmu.getReal([vr[n] for n in NAMES])
            fmu.setFMUstate(state)
            fmu.freeFMUstate(state)
        fmu.doStep(k * 1e-3, 1e-3)
        t = (k + 1) * 1e-3
    out = fmu.getReal([vr[n] for n in NAMES])
    fmu.terminate()
    fmu.freeInstance()
    return {"t": t, "values": out, "restored_run": again}


def main():
    unzipped = sys.argv[1]
    md = read_model_description(unzipped)
    print(json.dumps({
        "python": "%d.%d" % sys.version_info[:2],
        "fig6": run(unzipped, md, {}, 2000),
        "backlash": run(unzipped, md, {"c": 5e-4}, 1000),
        "state": run(unzipped, md, {}, 1000, state_at=500),
    }))


if __name__ == "__main__":
    main()
