"""`python -m cam_fmu.cli` is `cam-fmu`."""
import sys

from . import main

sys.exit(main())
