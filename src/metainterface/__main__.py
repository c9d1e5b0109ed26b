"""`python -m metainterface ...` runs the command line."""

import sys

from metainterface.cli import main

sys.exit(main())
