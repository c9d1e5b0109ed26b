"""`python -m metainterface ...` runs the command line."""

from metainterface.cli import run

run()
