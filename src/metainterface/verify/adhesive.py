"""The BEM check of an adhesive design (issue 38): the JKR-limit BEM under a rising force.

A design made with an adhesive model (``Independent(adhesion=w)``, ``Interacting(adhesion=w)``,
or a friction law with a work of adhesion) has the loading curve under load control: the
normal force rises from zero, each asperity snaps in when it touches and the cell follows
the running maximum of its force (``physics.adhesion``). Its check solves the same cell in
the adhesive torch BEM in the JKR limit (``validation.adhesive_bem``, Pohrt-Popov
criterion) by approach, at K approaches from touch up to a step past where the model
reaches the check's top load (displacement control: an adhesive contact has unstable
branches that load control would jump). The states a rising force reaches, those whose
force is at its running maximum and positive, and, with each asperity in contact, at least
the load the cell carried just before that asperity touched (a peak the samples may miss),
are the BEM's load-controlled curve; they are the check's loads, and the BEM, the model
and the target (interpolated) are compared there with the adhesionless check's measure,

    bem_error = ||alpha_bem - alpha_target||_2 / ||alpha_target||_2,

over the states inside the target's range. Only the torch engine has a JKR-limit solver:
the check runs there whatever ``Verify.engine`` says (a note says so).

The check bounds its own error (issue 52). By default it finds each contact edge by the
disc criterion (``validation.adhesive_discs``: each JKR edge from a family of bonded
discs), whose error against JKR falls as the grid spacing with one sign, on three grids
along the same approaches: the finer two extrapolated to zero spacing are its curve, and
the difference to the coarser two's extrapolation is its own error (``accuracy``;
``verify.adhesive_discs``). On a Hertz asperity against the JKR closed form the curve is
within 0.12-0.21 % and the estimate 0.23-0.34 % (w = 4.2e-5 to 5e-4 E* R); on ten
9-asperity cells against the same criterion a grid finer, 0.02-0.10 % and 0.13-0.31 %, see
``benchmarks/bench_adhesive_disc_check.py`` (benchmarks/results/adhesion.md). Without a
grid given the finest grid starts at ``GRID_START`` points per asperity and doubles, up to
``GRID_MAX``, while the estimate is above ``BOUND_SHARE`` of ``Verify.max_error`` or the
criterion cannot place more than a quarter of the states (contacts a few spacings wide).

Where a grid given is too coarse for it (a quarter of it under ``COARSEST`` points an
asperity), or the criterion does not apply (an edge not found in its asperity's square),
the check is the point-by-point JKR-limit BEM's, and a note says so. That BEM places a
contact edge to a fraction of a grid spacing, so its area error falls with the grid: on a
Hertz asperity against JKR's closed form 7.3 % at 128^2, 3.8 % at 128^2 loading only,
2.6 % at 256^2, 1.3 % at 512^2 (``benchmarks/results/adhesion.md``), and pointwise of
either sign (where an edge falls between grid points). Its own error on a grid M is
estimated from the same check on M / 2 (``accuracy``): the two curves' difference over the
target's norm, divided by 2^p - 1, p = 1 (``ORDER``). With errors of either sign that
halve with the spacing the difference is about twice the fine grid's error, so the
estimate bounds it: on a Hertz asperity against JKR, 14 % estimated against 6.2 % true at
64^2, 6.2 % against 2.9 % at 128^2 (``tests/verify/test_adhesive_bound.py``). That holds
up to ``adhesive_path.FINEST`` (256) points per asperity: past it the criterion's pinning
of each edge (a share of K_c, not of the grid spacing) outweighs the pixel error
(``benchmarks/bench_adhesive_convergence.py``).

A cell of several asperities jumps where each snaps in, and a state at a jump reads either
side of it depending on where the approaches fall, on one grid and the next alike. So the
check leaves out the states within its own snap-ins' bounds (``own_snap_ins``: the loads a
rising force may jump at, as far as the samples tell), and reads the coarse curve piece by
piece between its snap-ins, never across one (``read_across_jumps``). Without that, a
single state at a jump could put the check off a finer grid by several times the estimate
(``benchmarks/bench_adhesive_check_bound.py``, figures in ``benchmarks/results/adhesion.md``).

Point by point and without a grid given, the check starts at ``GRID_START`` points per
asperity and doubles,
the last fine grid now the coarse one, while that estimate is above ``BOUND_SHARE`` of
``Verify.max_error`` and would fall below it by ``GRID_MAX`` per asperity at the assumed
order (a doubling that cannot reach the bound only costs time: the check
then stays where it is and says so); the estimate is the check's ``accuracy``, printed
beside its error, and the correction stops there.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from metainterface._threads import in_background, uses_threads
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.validation.adhesive_discs import DiscCriterionError
from metainterface.validation.adhesive_path import (  # noqa: F401  (re-exported)
    APPROACHES_PER_LOAD,
    FINEST,
    TOUCH_MARGIN,
    approaches,
    at_snap_ins,
    clear_of_snap_ins,
    rising_branch,
)
from metainterface.verify._adhesive_curve import (
    AdhesiveSolved,
    inside_target,
    model_alpha,
    path_notes,
    read_across_jumps,
)
from metainterface.verify.adhesive_discs import COARSEST, disc_check

#: Grid points per lattice cell side of the default adhesive check's first fine grid (the
#: adhesionless check's, 384^2 for N = 9), and the most it doubles to (768^2 for N = 9): the
#: finest the adhesive BEM takes (``adhesive_path.FINEST``).
GRID_START = 128
GRID_MAX = FINEST
#: The check's own error must be at most this share of ``Verify.max_error`` (issue 52).
BOUND_SHARE = 0.25
#: The convergence order assumed of the check's error with the grid spacing (see above).
ORDER = 1.0
#: The largest work of adhesion [E* R] at which the two-grid estimate was shown to hold the
#: check's true error (a Hertz asperity against the JKR closed form, grids up to ``FINEST``:
#: ``benchmarks/bench_adhesive_convergence.py``); above it the check says so.
VALIDATED_WORK = 5e-4


def solve_adhesive(
    design: Design,
    target: Target,
    model: ForwardModel,
    *,
    grid: int,
    loads: int,
    device: str = "auto",
    engine: str = "torch",
) -> AdhesiveSolved:
    """``design`` (made with the adhesive ``model``) in the JKR-limit BEM on ``grid``^2 by
    ``APPROACHES_PER_LOAD * loads`` approaches; ``engine``: the one asked for (noted when it
    is not torch). Raises MetainterfaceError where no state of the path lies in the
    target's range."""
    top = min(target.p_star_max, model.model_curve(design).p_star_max)
    branch = rising_branch(
        design, model, grid=grid, samples=APPROACHES_PER_LOAD * loads, top=top, device=device
    )
    path, deltas, seconds, dev = branch.path, branch.approaches, branch.seconds, branch.device
    keep = inside_target(path.p_star, branch.keep, target, "the adhesive BEM")
    p = path.p_star[keep]
    notes = (
        f"adhesive BEM: the JKR limit (Pohrt-Popov criterion) under a rising force, "
        f"w = {model.adhesion:.3g} E* R, {int(keep.sum())} of {deltas.size} approaches on "
        "the rising branch",
        *path_notes(float(p[-1]), top, engine),
    )
    return AdhesiveSolved(
        p,
        path.alpha[keep],
        model_alpha(design, model, p),
        str(dev),
        seconds,
        notes,
        branch.snap_ins,
    )


def accuracy(fine: AdhesiveSolved, coarse: AdhesiveSolved, target: Target) -> float:
    """The fine check's own error estimated from the coarse one (half its grid): the
    relative L2 difference of their alpha_bem over the fine states the coarse curve reads
    (``read_across_jumps``), over the target's norm there, times 1 / (2^ORDER - 1). inf
    where the two share no load."""
    other = read_across_jumps(fine.p_star, coarse.p_star, coarse.alpha_bem, coarse.snap_ins)
    inside = np.isfinite(other)
    if not inside.any() or coarse.p_star.size < 2:
        return math.inf
    p = fine.p_star[inside]
    diff = fine.alpha_bem[inside] - other[inside]
    norm = float(np.linalg.norm(np.interp(p, target.p_star, target.alpha)))
    if not norm > 0:
        return math.inf
    return float(np.linalg.norm(diff)) / norm / (2.0**ORDER - 1.0)


@dataclass(frozen=True)
class BoundedCheck:
    """The adhesive check at its chosen grid: the solve there, the grid, its own error
    estimated from two grids (``accuracy``), the grids tried, the total wall time [s]."""

    solved: AdhesiveSolved
    grid: int
    accuracy: float
    grids: tuple[int, ...]
    seconds: float


# One thread, as the CLI and the design loop run it (``_threads``: light work): its FFTs of
# 192^2-384^2 gain little from a second thread on an idle machine and lose much when
# another process holds a core (the benchmark cell: 40 s on two threads, 30 s on one,
# beside a busy test suite, load ~5)
@uses_threads()
def bounded_check(
    design: Design,
    target: Target,
    model: ForwardModel,
    *,
    grid: int | None,
    loads: int,
    max_error: float,
    device: str = "auto",
    engine: str = "torch",
) -> BoundedCheck:
    """The adhesive check with its own error bounded (see the module's doc): on ``grid``
    and half of it where a grid is given; else from ``GRID_START`` n, doubling while the
    two-grid estimate is above ``BOUND_SHARE * max_error``, up to ``GRID_MAX`` n."""
    from metainterface.validation import check_grid

    s = design.settings
    n = s.n_side
    start = time.perf_counter()
    fine_grid = GRID_START * n if grid is None else check_grid(grid, s)
    bound = BOUND_SHARE * max_error
    fallback = (
        f"the grid {fine_grid}^2 does not suit the disc criterion (its coarsest grid, a "
        f"quarter of it, must be a multiple of {n} with at least {COARSEST} points an "
        "asperity): the check is the point-by-point BEM's"
    )
    checked = None
    if fine_grid // 4 >= COARSEST * n and fine_grid % (4 * n) == 0:
        try:
            checked = _bounded_discs(
                design, target, model, fine_grid, grid is None, loads, bound, device, engine
            )
            fallback = None
        except DiscCriterionError as exc:
            fallback = (
                f"the disc criterion does not apply to this design ({exc}): the check is the "
                "point-by-point BEM's"
            )
    if checked is None:
        checked = _bounded_points(
            design, target, model, fine_grid, grid is None, loads, bound, device, engine
        )
    solved, fine_grid, acc, grids, source, beyond = checked
    note = f"the adhesive check's own error, {source}: {100 * acc:.2g} %" + (
        f" (within a quarter of the {100 * max_error:g} % asked)"
        if acc <= bound
        else f", above a quarter of the {100 * max_error:g} % asked{beyond}: its verdict holds "
        "to that"
    )
    notes = (*solved.notes, note) + ((fallback,) if fallback else ())
    if model.adhesion > VALIDATED_WORK:
        notes += (
            f"w = {model.adhesion:.3g} E* R is above the {VALIDATED_WORK:g} E* R up to which "
            "the check's own error estimate was shown to hold against JKR",
        )
    solved = replace(solved, notes=notes)
    return BoundedCheck(solved, fine_grid, acc, grids, time.perf_counter() - start)


#: What a way of checking hands ``bounded_check``: the solve at the grid it settled on, that
#: grid, its own error, the grids solved, where the error came from (for the note), and what
#: the note adds where that error stays above the bound.
_Checked = tuple[AdhesiveSolved, int, float, tuple[int, ...], str, str]


def _bounded_points(
    design: Design,
    target: Target,
    model: ForwardModel,
    fine_grid: int,
    auto: bool,
    loads: int,
    bound: float,
    device: str,
    engine: str,
) -> _Checked:
    """``bounded_check`` point by point: on fine_grid and half of it; where ``auto``,
    doubling while the two-grid estimate is above ``bound`` and would fall below it by
    ``GRID_MAX`` n at the assumed order."""
    n = design.settings.n_side

    def solve(m: int) -> AdhesiveSolved:
        return solve_adhesive(
            design, target, model, grid=m, loads=loads, device=device, engine=engine
        )

    coarse_grid = max(8 * n, (fine_grid // 2) // n * n)  # a multiple of n, >= 8 an asperity
    # The two grids at once, on two Python threads (each one torch thread; a solve's FFTs
    # and CG steps release the GIL), each path in two chains (``rising_branch``): on two
    # cores, or beside busy processes, the check takes about half the fine path's time
    # instead of both grids' (``benchmarks/bench_adhesive_bound.py``)
    with in_background(lambda: solve(fine_grid), name="adhesive-check") as later:
        coarse = solve(coarse_grid)  # where it fails, the fine grid stops at its next state
        fine = later()
    grids = [coarse_grid, fine_grid]
    acc = accuracy(fine, coarse, target)

    def worth(m: int) -> bool:  # the bound within reach by GRID_MAX at the assumed order
        return acc * (m / (GRID_MAX * n)) ** ORDER <= bound and 2 * m <= GRID_MAX * n

    while auto and acc > bound and worth(fine_grid):
        coarse, coarse_grid = fine, fine_grid
        fine_grid = 2 * fine_grid
        fine = solve(fine_grid)
        grids.append(fine_grid)
        acc = accuracy(fine, coarse, target)
    beyond = f" (a finer grid, to {GRID_MAX} n, would not reach it)" if auto else ""
    source = f"from {coarse_grid}^2 and {fine_grid}^2"
    return fine, fine_grid, acc, tuple(grids), source, beyond


def _bounded_discs(
    design: Design,
    target: Target,
    model: ForwardModel,
    fine_grid: int,
    auto: bool,
    loads: int,
    bound: float,
    device: str,
    engine: str,
) -> _Checked:
    """``bounded_check`` by the disc criterion (``verify.adhesive_discs``): on fine_grid /
    4, / 2 and fine_grid; where ``auto``, doubled while its own error is above ``bound`` or
    the criterion cannot place the states (a contact a few spacings wide), up to
    ``GRID_MAX`` n. The paths of grids already solved are reused."""
    n = design.settings.n_side

    def grids(m: int) -> tuple[int, int, int]:
        return (m // 4, m // 2, m)

    paths: dict = {}
    while True:
        finer = auto and 2 * fine_grid <= GRID_MAX * n
        try:
            solved, acc = disc_check(
                design,
                target,
                model,
                grids=grids(fine_grid),
                loads=loads,
                device=device,
                engine=engine,
                known=paths,
            )
        except DiscCriterionError:
            if not finer:
                raise
            fine_grid *= 2
            continue
        if acc <= bound or not finer:
            break
        fine_grid *= 2
    g = grids(fine_grid)
    source = f"from the extrapolations of ({g[0]}^2, {g[1]}^2) and ({g[1]}^2, {g[2]}^2)"
    return solved, fine_grid, acc, tuple(sorted(paths)), source, ""
