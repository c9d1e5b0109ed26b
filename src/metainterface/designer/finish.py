"""``design``'s steps after the designs are made: each checked (and where asked corrected)
in BEM, its adhesion noted, and its files written. :class:`Finish` holds what those steps
need of the call's options, so that the scale search can check its finalists in turn and
write only the one it keeps (``designer.run.designed``)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from metainterface._files import output_set
from metainterface._files.provenance import current_command
from metainterface.designer.adhesion import adhesion_notes
from metainterface.designer.results import DesignResult
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.refine import RefineSettings
from metainterface.physics.cell import Design
from metainterface.physics.limits import PressureCheck, check_pressure
from metainterface.units.dimensions import physical_block
from metainterface.units.quantities import parse_pressure
from metainterface.verify.bemcheck import BemCheck
from metainterface.verify.check import Verify


@dataclass(frozen=True)
class Finish:
    """What ``designed`` leaves to do, with the options it was called with: :meth:`check`
    and :meth:`save`; called, both (what ``design`` returns).

    verify: the check asked (None: none); extra_loss, refine_settings, z_step, perturb: the
    design's, for a correction; limit, modulus: the pressure limit, for a corrected design's
    pressure check; out, single, physical, full_target: where and what to write."""

    verify: Verify | None
    extra_loss: Any
    refine_settings: RefineSettings | None
    z_step: float | None
    perturb: Perturbation | None
    limit: float | None
    modulus: Any
    out: Any
    single: bool
    physical: dict | None
    full_target: bool

    def check(
        self,
        results: list[DesignResult],
        correct: bool | None = None,
        first: list[BemCheck | None] | None = None,
    ) -> list[DesignResult]:
        """The results checked in BEM as asked (``correct``: instead of the ``Verify``'s
        own), with their adhesion notes. ``first``: each result's check already solved with
        these settings (None: solve it), which a correction then starts from."""
        if self.verify is not None:
            asked = self.verify if correct is None else replace(self.verify, correct=correct)
            results = verify_all(results, asked, self, first)
        # after the BEM's correction: the notes are of the design returned and written
        return [replace(r, notes=(*r.notes, *adhesion_notes(r))) for r in results]

    def save(self, results: list[DesignResult]) -> DesignResult | list[DesignResult]:
        """The results' files written where asked; one result for a single target."""
        if self.out is not None:
            out = Path(self.out)
            folders = [out] if self.single else [out / r.target.name for r in results]
            save_all(results, folders, self.physical, self.full_target)
        return results[0] if self.single else results

    def __call__(self, results: list[DesignResult]) -> DesignResult | list[DesignResult]:
        return self.save(self.check(results))


def verify_all(
    results: list[DesignResult],
    checks: Verify,
    finish: Finish,
    first: list[BemCheck | None] | None = None,
) -> list[DesignResult]:
    """Each result checked (and where asked, corrected) in BEM (``first``: checks already
    solved, see :meth:`Finish.check`); a corrected design gets its pressure check again."""
    from metainterface.designer.verified import verified

    out = []
    for r, made in zip(results, first or [None] * len(results), strict=True):
        v = verified(
            r,
            checks,
            extra_loss=finish.extra_loss,
            refine_settings=finish.refine_settings,
            z_step=finish.z_step,
            robust=finish.perturb is not None,
            check=made,
        )
        if v.design is not r.design and r.pressure is not None:
            v = replace(v, pressure=pressure_check(v.design, finish.limit, finish.modulus))
        out.append(v)
    return out


def pressure_check(d: Design, limit: float | None, modulus: Any) -> PressureCheck | None:
    """The design's peak-pressure check against ``limit`` (p/E*, or a stress with a
    modulus), None without a limit."""
    if limit is None:
        return None
    e_star = None if modulus is None else parse_pressure(modulus, option="modulus")
    return check_pressure(d, limit if e_star is None else limit * e_star, e_star=e_star)


def save_all(
    results: list[DesignResult],
    folders: list[Path],
    physical: dict | None,
    full_target: bool = False,
) -> None:
    """Each result's files in its folder: all of them, or none."""
    with output_set():  # every result's files, or none
        for r, folder in zip(results, folders, strict=True):
            command = current_command()
            extra = {"command": command} if command else {}
            if physical is not None:
                extra["physical"] = physical_block(r.design, **physical)
            r.save(folder, full_target=full_target, **extra)
