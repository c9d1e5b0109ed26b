"""Designs checked, and corrected, in the boundary element method before they are handed over.

``check``: the BEM check of a design against its target (:class:`Verify` settings,
:class:`BemCheck` result, :func:`bem_check`). ``correct``: output space mapping, the design
re-refined against the target shifted by the model's defect until the BEM error falls.
Above ``inverse`` and ``validation`` (it uses both), below ``api``.
"""

from metainterface.verify.check import BemCheck, Verify, as_verify, bem_check, solve_bem
from metainterface.verify.correct import Corrected, Correction, correct

__all__ = [
    "BemCheck",
    "Corrected",
    "Correction",
    "Verify",
    "as_verify",
    "bem_check",
    "correct",
    "solve_bem",
]
