"""The sampling and the min-plus / max-plus convolution the cell's exact bounds are built
with (``reach`` without adhesion, ``adhesive_reach`` with it)."""

from __future__ import annotations

import numpy as np

#: Shape exponents sampled across [gamma_min, gamma_max] for the bounds.
GAMMA_SAMPLES = 129
#: Forces sampled per asperity, 0 to the largest one asperity carries.
FORCE_SAMPLES = 256


def _convolve(a: np.ndarray, b: np.ndarray, pick) -> np.ndarray:
    """(a * b)[j] = pick over i of a[j - i] + b[i]: the min-plus (or max-plus) convolution."""
    n = a.size + b.size - 1
    fill = np.inf if pick is np.minimum else -np.inf
    out = np.full(n, fill)
    for i, v in enumerate(b):  # len(b) passes over a: ~FORCE_SAMPLES vector operations
        out[i : i + a.size] = pick(out[i : i + a.size], a + v)
    return out
