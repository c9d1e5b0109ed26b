"""`python -m metainterface.cli ...` runs the command line."""

import sys

from metainterface.cli import main

sys.exit(main())
