"""A closed-form gradient without autograd: a ``torch.autograd.Function``'s own forward and
backward run directly, with a plain object in place of autograd's context.

The refinement evaluates a loss and its gradient a few hundred times per design on batches of
a few rows, where the cost is the number of torch calls, not their flops. Through autograd
each evaluation records a graph (a node per operation), runs the engine over it and calls
the Functions' backward through it: about 40 % of the evaluation. Where every step of the
loss has a hand-written backward (the sweep, the interpolated loss, the parameter map), the
chain is applied by hand instead (``pullback``), with the same formulas and so the same
gradient.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import torch
from torch import Tensor

#: A vector-Jacobian product: upstream gradients of a step's outputs -> its inputs' gradients.
Pullback = Callable[..., Any]


class Tape:
    """What a ``torch.autograd.Function``'s forward and backward use of their context:
    ``needs_input_grad``, ``save_for_backward`` / ``saved_tensors`` and attributes."""

    def __init__(self, needs_input_grad: Sequence[bool]) -> None:
        self.needs_input_grad = tuple(needs_input_grad)
        self.saved_tensors: tuple[Tensor, ...] = ()

    def save_for_backward(self, *tensors: Tensor) -> None:
        self.saved_tensors = tensors

    def set_materialize_grads(self, value: bool) -> None:
        """(autograd's option; the backward here gets exactly the gradients passed to it)"""

    def mark_non_differentiable(self, *tensors: Tensor) -> None:
        """(nothing is recorded here)"""


def pullback(
    function: type[torch.autograd.Function], needs: Sequence[bool], *args: Any
) -> tuple[Any, Pullback]:
    """``function``'s outputs at ``args`` and its pullback: ``back(*grads)`` gives the
    gradients of the inputs (None where ``needs`` is False or the input is not a tensor)
    for the upstream gradients of the outputs, as ``function.backward`` computes them."""
    tape = Tape(needs)
    with torch.no_grad():
        out = function.forward(tape, *args)

    def back(*grads: Tensor | None) -> Any:
        with torch.no_grad():
            return function.backward(tape, *grads)

    return out, back
