#!/usr/bin/env python
"""Build models/cam.fmu: a thin entry point into ``cam_fmu.fmu.build``.

    python build_fmu.py                  # -> models/cam.fmu
    python build_fmu.py --dest /tmp/x/cam.fmu
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # this checkout's cam_fmu, installed or not

from cam_fmu.experiments.progress import ProgressBar  # noqa: E402
from cam_fmu.fmu.build import main  # noqa: E402

if __name__ == "__main__":
    # a bar on stderr per FMU naming the platform being built (a first build takes minutes: every platform's
    # zig cache is cold), drawn on a terminal or with CAM_FMU_PROGRESS=1 (0: never), as `cam-fmu simulate` draws
    sys.exit(main(progress=ProgressBar))
