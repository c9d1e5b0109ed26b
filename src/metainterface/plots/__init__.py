"""Every figure: one function per figure, data in -> matplotlib Figure out."""

from metainterface.plots.common import new_figure, save_figure
from metainterface.plots.curve import draw_curve, plot_curve
from metainterface.plots.dataset import plot_dataset_examples
from metainterface.plots.design import plot_comparison, plot_design
from metainterface.plots.reconstruction import plot_reconstructions
from metainterface.plots.training import plot_training
from metainterface.plots.validation import plot_validation

__all__ = [
    "draw_curve",
    "new_figure",
    "plot_comparison",
    "plot_curve",
    "plot_dataset_examples",
    "plot_design",
    "plot_reconstructions",
    "plot_training",
    "plot_validation",
    "save_figure",
]
