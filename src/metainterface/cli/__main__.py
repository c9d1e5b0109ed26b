"""`python -m metainterface.cli ...` runs the command line."""

from metainterface.cli import run

run()
