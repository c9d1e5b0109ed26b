"""The adhesive check bounds its own error (issue 52): the two-grid estimate (the check on
M and on M / 2) is at least the check's true error, measured against the JKR closed form on
a Hertz asperity (the adhesive model is JKR there) and against a finer grid's solution; it
is printed beside the check's error and recorded."""

import math

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface._threads import threads_for
from metainterface.physics import CellSettings
from metainterface.verify.adhesive import bounded_check, solve_adhesive

W = 4.2e-5  # w / (E* R): PDMS on glass at R = 0.5 mm


def _jkr(work: float):
    """A Hertz asperity (gamma = 2) and its JKR loading curve as the target, from the JKR
    closed form written here (F = P* L^2, R = 1, E* = 1)."""
    d = mi.Design(gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1))
    from metainterface.validation.heightmap import height_map

    side = height_map(d, 16).cell_side
    top = float(mi.Independent(adhesion=work).model_curve(d).p_star_max)
    p = np.linspace(0, top, 64)
    f = p * side**2
    q = 3 * math.pi * work
    a = ((f + q + np.sqrt(6 * math.pi * work * f + q * q)) / (4 / 3)) ** (1 / 3)
    return d, mi.Target(p_star=p, alpha=math.pi * a * a / side**2, name="hertz")


@pytest.fixture(scope="module")
def hertz():
    return _jkr(W)


def _error(alpha, p, target):
    t = np.interp(p, target.p_star, target.alpha)
    return float(np.linalg.norm(alpha - t) / np.linalg.norm(t))


@pytest.mark.parametrize("work", [W, 1e-4, 5e-4])
def test_the_default_check_of_a_hertz_asperity_is_within_its_bound_of_jkr(work):
    # the disc criterion extrapolated over three grids (the default check): its curve against
    # the JKR closed form written here, whose error the check must bound and keep within a
    # quarter of the 2 % asked (issue 52, item 3)
    design, target = _jkr(work)
    b = bounded_check(
        design, target, mi.Independent(adhesion=work), grid=None, loads=8, max_error=0.02
    )
    s = b.solved
    assert any("family of bonded discs" in n for n in s.notes)
    assert s.p_star.size >= 8
    true = _error(s.alpha_bem, s.p_star, target)
    assert 0 < true <= b.accuracy <= 0.25 * 0.02
    assert any("own error, from the extrapolations" in n for n in s.notes)


def _finer_extrapolation(design, target, model, grid, loads):
    """The disc criterion's curve extrapolated from 2 M and 4 M: a grid finer than any the
    check at M took, along the same approaches."""
    from metainterface.verify.adhesive_discs import disc_check

    return disc_check(design, target, model, grids=(grid, 2 * grid, 4 * grid), loads=loads)[0]


@pytest.mark.long
@pytest.mark.parametrize("seed", [3, 5])
def test_the_disc_check_bound_holds_against_a_finer_grid_on_a_cell(seed):
    # four asperities snapping in one after another (cells not tuned on: the criterion was
    # developed on the package's example cell): the check on 64^2-256^2 (32-128 points an
    # asperity) against the same criterion extrapolated from 256^2 and 512^2, read at the
    # check's loads clear of both curves' snap-ins
    from metainterface.verify.adhesive import read_across_jumps

    design, target, model = _cell(seed)
    b = bounded_check(design, target, model, grid=256, loads=8, max_error=0.02)
    assert b.grids == (64, 128, 256)
    s = b.solved
    assert any("family of bonded discs" in n for n in s.notes)
    ref = _finer_extrapolation(design, target, model, 128, 8)
    other = read_across_jumps(s.p_star, ref.p_star, ref.alpha_bem, ref.snap_ins)
    seen = np.isfinite(other)
    assert seen.sum() >= 4
    t = np.interp(s.p_star[seen], target.p_star, target.alpha)
    true = np.linalg.norm(s.alpha_bem[seen] - other[seen]) / np.linalg.norm(t)
    assert true <= b.accuracy


def test_a_disc_solve_that_does_not_converge_is_an_error_not_a_fallback(hertz, monkeypatch):
    from metainterface.validation import adhesive_discs

    design, target = hertz
    monkeypatch.setattr(adhesive_discs, "MAX_ITER", 1)
    with pytest.raises(mi.MetainterfaceError, match=r"disc criterion.*did not converge"):
        bounded_check(
            design, target, mi.Independent(adhesion=W), grid=None, loads=4, max_error=0.02
        )


def test_a_grid_too_coarse_for_the_disc_criterion_says_it_checks_point_by_point(hertz):
    design, target = hertz
    b = bounded_check(design, target, mi.Independent(adhesion=W), grid=64, loads=4, max_error=0.02)
    assert any("does not suit the disc criterion" in n for n in b.solved.notes)
    assert b.grids == (32, 64)


@pytest.mark.parametrize("grid", [64])
def test_the_point_by_point_bound_holds_against_jkr_and_a_finer_grid(hertz, grid):
    # a grid given too coarse for the disc criterion: the point-by-point BEM on it and half
    design, target = hertz
    model = mi.Independent(adhesion=W)
    b = bounded_check(design, target, model, grid=grid, loads=6, max_error=0.02)
    assert b.grid == grid and b.grids == (grid // 2, grid)
    s = b.solved
    # the model is JKR on a Hertz asperity: its curve error here is the interpolation's
    # (the 63-point target read linearly between its points: ~1e-4)
    assert _error(s.alpha_model, s.p_star, target) < 1e-3
    true = _error(s.alpha_bem, s.p_star, target)
    assert 0 < true <= b.accuracy
    finer = solve_adhesive(design, target, model, grid=2 * grid, loads=6)
    inside = (s.p_star >= finer.p_star[0]) & (s.p_star <= finer.p_star[-1])
    near = np.interp(s.p_star[inside], finer.p_star, finer.alpha_bem)
    t = np.interp(s.p_star[inside], target.p_star, target.alpha)
    assert np.linalg.norm(s.alpha_bem[inside] - near) / np.linalg.norm(t) <= b.accuracy
    assert any("own error" in n for n in s.notes)


def test_the_check_records_and_prints_its_accuracy(hertz):
    design, target = hertz
    model = mi.Independent(adhesion=W)
    from metainterface.verify import bem_check

    check = bem_check(design, target, mi.Verify(grid=64, loads=4), model)
    assert check.accuracy > 0
    assert check.to_dict()["accuracy"] == check.accuracy
    assert "+-" in repr(check)


def test_a_bonded_solve_that_does_not_converge_is_an_error(hertz):
    from metainterface.validation import adhesive_bem as ab
    from metainterface.validation.heightmap import height_map

    design, _ = hertz
    hm = height_map(design, 32)
    z = torch.as_tensor(hm.heights)[None]
    with pytest.raises(mi.MetainterfaceError, match="did not converge"):
        ab.solve_jkr(z, hm.cell_side, torch.tensor([-float(z.mean()) - 0.01]), W, max_iter=2)


def _cell(seed: int, n: int = 4, spread: float = 0.6):
    """A random adhesive cell of n asperities (heights over ``spread`` Delta_max, so that
    they snap in one after another) and its own loading curve under Independent(w)."""
    s = CellSettings(n_asperities=n)
    rng = np.random.default_rng(seed)
    g = rng.uniform(1.8, 4.0, n)
    h = rng.uniform(0, spread, n) * s.delta_max
    h -= h.min()
    model = mi.Independent(adhesion=W)
    gt, ht = torch.as_tensor(g)[None], torch.as_tensor(h)[None]
    with torch.no_grad():
        p = np.linspace(0, 0.9 * float(model.sweep(gt, ht, s).p_star[0, -1]), 24)[1:]
        a = model.alpha_at_loads(gt, ht, s, torch.as_tensor(p)[None])[0].numpy()
    return mi.Design(gamma=g, h=h, settings=s), mi.Target(p_star=p, alpha=a, name="cell"), model


@pytest.mark.long
@pytest.mark.parametrize("seed", [2, 4])
def test_the_bound_holds_across_snap_ins_against_a_finer_path(seed):
    # Several asperities snapping in: the estimate must hold the check's difference to a
    # grid twice as fine sampled at four times the approaches (other loads, other jumps).
    # That path is read here on its own terms: linearly, except near its jumps, found from
    # its curve (a rise above four times its median step), not from the check's code.
    design, target, model = _cell(seed)
    b = bounded_check(design, target, model, grid=96, loads=8, max_error=0.02)
    s = b.solved
    with threads_for("light"):  # one thread, as the check runs (never spinning beside xdist)
        ref = solve_adhesive(design, target, model, grid=192, loads=32)
    rise = np.diff(ref.alpha_bem)
    big = np.flatnonzero(rise > 4 * np.median(rise))
    assert big.size >= 1  # the finer path does snap in within the range
    lo, hi = ref.p_star[big][None] / 1.1, ref.p_star[big + 1][None] * 1.1
    clear = ~((s.p_star[:, None] > lo) & (s.p_star[:, None] < hi)).any(1)
    clear &= (s.p_star >= ref.p_star[0]) & (s.p_star <= ref.p_star[-1])
    assert clear.sum() >= 3
    p = s.p_star[clear]
    diff = s.alpha_bem[clear] - np.interp(p, ref.p_star, ref.alpha_bem)
    true = np.linalg.norm(diff) / np.linalg.norm(np.interp(p, target.p_star, target.alpha))
    assert 0 < true <= b.accuracy


def test_two_grids_with_one_snap_in_sampled_apart_agree():
    # Both grids read the same curve, alpha = 0.02 + 10 P* below the snap-in at P* = 1e-3
    # and 0.03 + 10 P* above it, at other loads: the coarse curve's last state before the
    # jump and its first after are 40 % of the load apart. Read across that gap with a
    # straight line it would differ from the fine one by up to the whole jump; read as the
    # load-controlled curve it is (a step), the two agree.
    from metainterface.verify.adhesive import AdhesiveSolved, accuracy

    def curve(p, snap):
        a = 0.02 + 10 * p + 0.01 * (p >= 1e-3)
        return AdhesiveSolved(p, a, a, "cpu", 0.0, (), np.array([snap]))

    fine = curve(
        np.array([2e-4, 4e-4, 6e-4, 8e-4, 9.5e-4, 1.05e-3, 1.2e-3, 1.4e-3]), [9.5e-4, 1.02e-3]
    )
    coarse = curve(np.array([1e-4, 4e-4, 8e-4, 1.2e-3, 1.5e-3]), [8e-4, 1.1e-3])
    target = mi.Target(p_star=np.linspace(0, 1.5e-3, 16), alpha=np.full(16, 0.04))
    assert accuracy(fine, coarse, target) == pytest.approx(0.0, abs=1e-12)
    # a coarse curve that jumps later than the fine one does differ, by the jump
    late = AdhesiveSolved(
        coarse.p_star,
        0.02 + 10 * coarse.p_star + 0.01 * (coarse.p_star >= 1.3e-3),
        coarse.alpha_bem,
        "cpu",
        0.0,
        (),
        np.array([[1.2e-3, 1.3e-3]]),
    )
    assert accuracy(fine, late, target) > 0.05


def test_a_check_whose_coarse_grid_fails_stops_its_fine_grid(hertz, monkeypatch):
    # the two grids run at once; where the coarse one fails, the error is the check's and
    # each chain of the fine grid starts at most one more state; by the time the error
    # reaches the caller both have ended. A state started after the failure holds its
    # chain for a second, so that the stop has surely arrived by its end whatever the
    # scheduler does (a count of states in the window alone was at its mercy).
    import threading

    from metainterface.validation import adhesive_path
    from metainterface.verify import bem_check

    design, target = hertz
    real = adhesive_path.solve_jkr
    busy, failed, returned = threading.Event(), threading.Event(), threading.Event()
    started, after, late = [], [], []

    def solve(z, side, gap, work, **kwargs):
        if z.shape[-1] == 32:  # the coarse grid fails once the fine grid is under way
            busy.wait(timeout=5.0)
            failed.set()
            raise mi.MetainterfaceError("adhesive BEM (JKR) did not converge (test)")
        if returned.is_set():
            late.append(float(gap[0]))
        elif failed.is_set():
            after.append(float(gap[0]))
            returned.wait(timeout=1.0)
        else:
            started.append(float(gap[0]))
            if len(started) == 2:
                busy.set()
                failed.wait(timeout=5.0)  # mid-state when the coarse grid fails
        return real(z, side, gap, work, **kwargs)

    monkeypatch.setattr(adhesive_path, "solve_jkr", solve)
    model = mi.Independent(adhesion=W)
    with pytest.raises(mi.MetainterfaceError, match="did not converge"):
        bem_check(design, target, mi.Verify(grid=64, loads=8), model)
    returned.set()
    threading.Event().wait(1.0)  # time for a grid left running to solve its other states
    assert len(started) >= 2 and len(after) <= 2 and not late, (started, after, late)


def test_a_failed_check_exits_with_its_own_status_not_an_abort(tmp_path):
    # the coarse grid (32^2) of a strongly adhesive Hertz asperity reaches no state in the
    # target's range and raises while the fine grid still solves on its own thread: the
    # process that then exits must not abort inside torch ("terminate called ...", 134)
    script = tmp_path / "fails.py"
    script.write_text(
        "import sys\n"
        "import numpy as np\n"
        "import metainterface as mi\n"
        "from metainterface.physics import CellSettings\n"
        "from metainterface.verify import bem_check\n"
        "d = mi.Design(gamma=np.array([2.0]), h=np.array([0.0]),\n"
        "              settings=CellSettings(n_asperities=1))\n"
        "model = mi.Independent(adhesion=1e-3)\n"
        "top = float(model.model_curve(d).p_star_max)\n"
        "t = mi.Target(p_star=np.linspace(0, top, 20), alpha=np.linspace(0.01, 0.2, 20))\n"
        "try:\n"
        "    bem_check(d, t, mi.Verify(grid=64, loads=10), model)\n"
        "except mi.MetainterfaceError as exc:\n"
        "    print(exc, file=sys.stderr)\n"
        "    sys.exit(2)\n"
    )
    import subprocess
    import sys

    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True)
    assert run.returncode == 2, run.stderr
    assert "reached no load" in run.stderr and "terminate" not in run.stderr


def test_an_adhesive_validation_finer_than_the_bem_allows_is_refused(hertz):
    # above 256 points per asperity the JKR-limit BEM's error against JKR stops falling (and
    # grows with strong adhesion): bench_adhesive_convergence.py
    design, _ = hertz
    with pytest.raises(mi.MetainterfaceError, match="grid must be at most 256") as info:
        mi.validate(design, model=mi.Independent(adhesion=W), grid=512)
    assert info.value.argument == "grid"


@pytest.mark.long
@pytest.mark.parametrize("work", [2e-5, 1e-4, 2e-4, 5e-4])
def test_the_bound_holds_against_jkr_at_the_finest_grid_the_check_takes(work):
    # 256 points per asperity (adhesive_path.FINEST): past it the estimate no longer holds
    # (bench_adhesive_convergence.py); the JKR closed form written here, not the model's
    from metainterface.validation.adhesive_path import FINEST

    d, target = _jkr(work)
    b = bounded_check(
        d, target, mi.Independent(adhesion=work), grid=FINEST, loads=10, max_error=0.02
    )
    assert 0 < _error(b.solved.alpha_bem, b.solved.p_star, target) <= b.accuracy


def test_a_check_above_the_validated_adhesion_says_so(hertz):
    # bench_adhesive_convergence.py showed the estimate to hold up to VALIDATED_WORK only
    from metainterface.verify.adhesive import VALIDATED_WORK

    design, target = hertz
    inside = bounded_check(
        design, target, mi.Independent(adhesion=W), grid=64, loads=4, max_error=0.02
    )
    assert not any("shown to hold" in n for n in inside.solved.notes)
    strong = 1.2 * VALIDATED_WORK
    d, t = _jkr(strong)
    above = bounded_check(d, t, mi.Independent(adhesion=strong), grid=64, loads=6, max_error=0.02)
    assert any("shown to hold against JKR" in n for n in above.solved.notes)


def test_the_check_reads_the_target_only_inside_its_rows(hertz):
    # a law whose first row is above zero force: below it np.interp would hold the target at
    # that row's alpha, an error the law does not state, so those states are left out
    design, full = hertz
    first = 3  # the first row at 3 / 63 of the top load (a target may start up to 5 % in)
    target = mi.Target(p_star=full.p_star[first:], alpha=full.alpha[first:], name="late")
    s = bounded_check(
        design, target, mi.Independent(adhesion=W), grid=64, loads=10, max_error=0.02
    ).solved
    assert s.p_star.size >= 2 and s.p_star.min() >= target.p_star[0]


def test_the_disc_check_says_it_ran_in_torch_when_another_engine_was_asked(hertz):
    # only the torch engine has a JKR-limit solver: a check asked of tamaas runs there and
    # says so, by the disc criterion as point by point
    design, target = hertz
    b = bounded_check(
        design,
        target,
        mi.Independent(adhesion=W),
        grid=None,
        loads=4,
        max_error=0.02,
        engine="tamaas",
    )
    assert any("family of bonded discs" in n for n in b.solved.notes)
    assert any("runs in the torch engine, not tamaas" in n for n in b.solved.notes)
