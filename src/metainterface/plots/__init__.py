"""Every figure: one function per figure, data in -> matplotlib Figure out."""

from metainterface.plots.common import new_figure, save_figure
from metainterface.plots.curve import plot_curve
from metainterface.plots.dataset import plot_dataset_examples
from metainterface.plots.validation import plot_validation

__all__ = [
    "new_figure",
    "plot_curve",
    "plot_dataset_examples",
    "plot_validation",
    "save_figure",
]
