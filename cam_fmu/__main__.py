"""`python -m cam_fmu` is `cam-fmu`."""
import sys

from .cli import main

sys.exit(main())
