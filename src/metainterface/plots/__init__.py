"""Every figure: one function per figure, data in -> matplotlib Figure out."""

from metainterface.plots.common import new_figure, save_figure
from metainterface.plots.curve import plot_curve

__all__ = ["new_figure", "plot_curve", "save_figure"]
