"""The disc criterion's windows (``adhesive_discs``): a disc alone is solved on a window
about its asperity, the periodic cell's kernel cut to the window and zero-padded, a linear
convolution exact for each pair of the window's points."""

from __future__ import annotations

import numpy as np
import torch

from metainterface.validation.adhesive_bem import (
    PRECONDITIONER_DTYPE,
    _spectral,
    inverse_kernel,
)


def padded(m: int) -> int:
    """The side of a window holding m x m points of a linear convolution: at least 2m - 1,
    with no prime factor above 5 (an FFT of 236 = 4 x 59 points took 3x one of 240)."""
    n = 2 * m
    while True:
        k = n
        for q in (2, 3, 5):
            while k % q == 0:
                k //= q
        if k == 1:
            return n
        n += 2


def window_kernels(kernel: torch.Tensor, grid: int, m: int, spacing: float):
    """The compliance of a window of P x P points (``padded``; the cell's real-space
    kernel ``kernel`` (grid, grid) cut to offsets below m, zero-padded: a linear
    convolution over m x m points) and the window's preconditioner, as ``_bonded`` takes
    them."""
    pad = padded(m)
    cut = torch.zeros(pad, pad, dtype=torch.float64, device=kernel.device)
    near = np.r_[0:m, pad - m + 1 : pad]
    src = np.r_[0:m, grid - m + 1 : grid]
    cut[np.ix_(near, near)] = kernel[np.ix_(src, src)]
    return (
        _spectral(torch.fft.rfft2(cut)[None], torch.complex128),
        _spectral(inverse_kernel(pad, pad * spacing, cut.device), PRECONDITIONER_DTYPE),
    )
