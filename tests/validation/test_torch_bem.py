"""The torch BEM engine: closed forms (Hertz, a flat punch, a wavy surface in full contact),
Tamaas on the same height maps, the batch solver, and the engine / device options."""

import math
import sys
from importlib.resources import files
from types import SimpleNamespace

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings, Design
from metainterface.physics.registry import get_model
from metainterface.validation import get_engine, solve_path, validate_design
from metainterface.validation import torch_bem as tb
from metainterface.validation.heightmap import height_map

CPU = torch.device("cpu")
EXAMPLE = Design.load(files("metainterface") / "examples" / "example_design.json")
HERTZ = Design(gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1))

#: torch against Tamaas: contact area (sub-pixel) and pressure field, relative to max p.
ALPHA_RTOL = 1e-6
PRESSURE_ATOL = 1e-6


def _solve(heights, side, loads, engine, fields=True, n=1, owner=None):
    owner = np.zeros(heights.shape, dtype=int) if owner is None else owner
    return solve_path(heights, side, loads, owner, n, engine=engine, device="cpu", fields=fields)


def test_hertz_contact_radius_and_pressure_profile():
    # One paraboloid (R = 1, E* = 1) in a cell of side L on 192^2, contact radius ~ L / 9:
    # Hertz gives a^3 = 3 F R / (4 E*) and p(r) = p0 sqrt(1 - r^2 / a^2), p0 = 3 F / (2 pi a^2).
    hm = height_map(HERTZ, 192)
    side = hm.cell_side
    load = get_model().model_curve(HERTZ).p_star_max
    path = _solve(hm.heights, side, [load], "torch")
    force = load * side**2
    a = (3 * force / 4) ** (1 / 3)
    p0 = 3 * force / (2 * math.pi * a**2)
    # a / dx = 19: the sub-pixel area is within 0.3 % of pi a^2 at a radius of 20 steps
    # (test_bem.py's test_subpixel_area_of_discs_and_per_asperity_shares), so a within 0.15 %,
    # doubled for the periodic images the half-space's Hertz has not
    assert math.sqrt(path.alpha[0] * side**2 / math.pi) == pytest.approx(a, rel=0.003)
    # the images' push raises p0 by 0.13 % on 192^2 and 384^2 alike (it is not the grid's):
    # twice that
    assert path.p_max[0] == pytest.approx(p0, rel=0.003)
    x = (np.arange(192) - 96) * hm.spacing
    r = np.hypot(*np.meshgrid(x, x, indexing="ij"))
    inner = r < 0.8 * a  # away from the edge, where the grid cannot follow the square root
    exact = p0 * np.sqrt(1 - (r[inner] / a) ** 2)
    # the same 0.13 % at the peak, and the radius's 0.15 % moves p(r < 0.8 a) by at most
    # 0.15 % / (1 - 0.8^2) = 0.4 %: within 0.6 % of p0
    assert np.abs(path.pressure[inner] - exact).max() < 0.006 * p0
    assert path.residual[0] <= 1e-11
    assert (path.gaps[0] >= 0).all() and path.gaps[0][path.pressure > 0].max() < 1e-6 * a


def _punch(m):
    """A rigid flat punch of radius a = L / 8 on m^2: (pressure, r, a, load, centre value)."""
    side = 1.0
    x = (np.arange(m) - m // 2) * side / m
    r = np.hypot(*np.meshgrid(x, x, indexing="ij"))
    a = side / 8
    heights = np.where(r <= a, 0.0, -1.0)
    load = 1e-3
    path = _solve(heights, side, [load], "torch")
    assert path.alpha_pixels[0] == pytest.approx((r <= a).mean())  # the whole face touches
    return path.pressure, r, a, load * side**2 / (2 * math.pi * a**2)


def test_flat_punch_pressure_rises_to_the_edge_singularity():
    # A rigid flat punch of radius a = L / 8 (everything outside it far below): the whole face
    # is in contact and p(r) = F / (2 pi a sqrt(a^2 - r^2)) (Boussinesq), 1 / sqrt(1 - r^2/a^2)
    # times its centre value. Checked inside r < a / 2, where the grid resolves it. (From a
    # uniform start the first gap is flat on the face: an error measured after one step
    # reads 0 there, and Tamaas stops with a uniform pressure. Ours takes a second step.)
    # The reference is the closed form reached on a grid twice as fine: the pixelated edge
    # (a / dx = 16 and 32) makes a first-order error, so the 256^2 error is half the 128^2
    # one (within 1.6-2.4x, the first order's 2x +- 20 %) and Richardson's 2 e_256 - e_128
    # meets Boussinesq within 0.5 % (a tenth of the 128^2 grid's dx / a = 6 %).
    errors = []
    for m in (128, 256):
        p, r, a, centre = _punch(m)
        inner = r < a / 2
        ratio = p[inner] / p[m // 2, m // 2] * np.sqrt(1 - (r[inner] / a) ** 2)
        errors.append((p[m // 2, m // 2] / centre - 1, np.abs(ratio - 1).max()))
        assert p[r <= a].max() > 3 * centre  # the rise to the edge
    (c128, s128), (c256, s256) = errors
    assert 0 < c256 < c128 and 1.6 < c128 / c256 < 2.4  # centre pressure, reads high
    assert 1.6 < s128 / s256 < 2.4  # the shape 1 / sqrt(1 - r^2 / a^2)
    assert abs(2 * c256 - c128) < 0.005
    assert abs(2 * s256 - s128) < 0.005


def test_wavy_surface_in_full_contact_matches_the_closed_form():
    # z = d cos(q x) cos(q y) pressed flat (P* well above full contact): u = z + c everywhere,
    # so p = P* + E* |q| d / 2 cos(q x) cos(q y), |q| = sqrt(2) 2 pi / L (u_hat = 2 p_hat / E*|q|)
    m, side, d = 64, 1.0, 1e-3
    x = np.arange(m) * side / m
    wave = np.cos(2 * math.pi * x)[:, None] * np.cos(2 * math.pi * x)[None, :]
    q = math.sqrt(2) * 2 * math.pi / side
    load = 2 * q * d / 2
    path = _solve(d * wave, side, [load], "torch")
    assert path.alpha_pixels[0] == 1.0 and path.alpha[0] == pytest.approx(1.0)
    np.testing.assert_allclose(path.pressure, load + q * d / 2 * wave, rtol=0, atol=1e-9 * load)


def _random_design(seed):
    rng = np.random.default_rng(seed)
    return Design(gamma=rng.uniform(1.8, 4.0, 9), h=rng.uniform(0.0, 0.01, 9))


def _designs():
    targets = mi.design(
        ["saturating", "bilinear", "linear"], method="hertz", effort=mi.Effort(starts=2, seed=0)
    )
    return {
        **{f"target-{r.target.name}": r.design for r in targets},
        "example": EXAMPLE,
        "random-0": _random_design(0),
        "random-1": _random_design(1),
    }


@pytest.fixture(scope="module")
def designs():
    return _designs()


def _compare(hm, n, loads):
    torch_path = _solve(hm.heights, hm.cell_side, loads, "torch", n=n, owner=hm.owner)
    ref = _solve(hm.heights, hm.cell_side, loads, "tamaas", n=n, owner=hm.owner)
    np.testing.assert_allclose(torch_path.alpha, ref.alpha, rtol=ALPHA_RTOL, atol=0)
    np.testing.assert_allclose(torch_path.asperity_alpha, ref.asperity_alpha, rtol=0, atol=1e-9)
    scale = ref.pressures.max(axis=(1, 2), keepdims=True)
    assert (np.abs(torch_path.pressures - ref.pressures) / scale).max() < PRESSURE_ATOL
    np.testing.assert_allclose(torch_path.gaps, ref.gaps, rtol=0, atol=1e-8 * np.ptp(hm.heights))
    assert (torch_path.residual <= 1e-11).all()
    return torch_path


@pytest.mark.parametrize(
    "name",
    ["target-saturating", "target-bilinear", "target-linear", "example", "random-0", "random-1"],
)
def test_torch_matches_tamaas_along_a_load_path(designs, name):
    pytest.importorskip("tamaas")
    design = designs[name]
    hm = height_map(design, 96)
    top = get_model().model_curve(design).p_star_max
    _compare(hm, 9, top * np.arange(1, 9) / 8)


def test_torch_matches_tamaas_at_the_first_contacts(designs):
    # the first two asperities to touch (asperity 2 is the highest, 4 the next one, 3e-4 R
    # lower; the first stays one grid point until the second touches), contacts of a few grid
    # points; and a lone asperity's first contacts, from 5 grid points on
    pytest.importorskip("tamaas")
    design = designs["random-0"]
    hm = height_map(design, 192)
    top = get_model().model_curve(design).p_star_max
    path = _compare(hm, 9, np.array([1.4e-4, 1.6e-4, 2.1e-4, 5e-4, 1e-3]) * top)
    touching = (path.asperity_alpha > 0).sum(axis=1)
    assert (touching == 2).all()
    assert path.alpha_pixels[0] * 192**2 < 10  # a contact of a few grid points
    lone = height_map(HERTZ, 128)
    top = get_model().model_curve(HERTZ).p_star_max
    path = _compare(lone, 1, np.array([3e-3, 1e-2, 3e-2]) * top)
    assert 1 < path.alpha_pixels[0] * 128**2 < 20


def test_a_path_through_one_point_contacts_goes_on():
    # 1-point contacts at the smallest loads: a warm start from one has no conjugate
    # direction (0 / 0), so that load starts afresh; the path then grows as it should
    design = _random_design(0)
    hm = height_map(design, 192)
    top = get_model().model_curve(design).p_star_max
    path = solve_path(
        hm.heights, hm.cell_side, np.geomspace(3e-5, 3e-2, 8) * top, hm.owner, 9, device="cpu"
    )
    pixels = np.rint(path.alpha_pixels * 192**2)
    assert pixels[0] == pixels[1] == 1 and (np.diff(pixels[1:]) > 0).all()
    assert (path.residual <= 1e-11).all()


def test_torch_matches_tamaas_in_full_contact():
    pytest.importorskip("tamaas")
    m = 64
    rng = np.random.default_rng(3)
    x = np.arange(m) * 2 * math.pi / m
    heights = sum(
        rng.normal() * 1e-3 * np.cos(i * x[:, None] + j * x[None, :] + rng.uniform(0, 6))
        for i, j in [(1, 0), (0, 1), (1, 1), (2, 1), (1, 3)]
    )
    cell = SimpleNamespace(heights=heights, cell_side=1.0, owner=np.zeros((m, m), int))
    path = _compare(cell, 1, [0.1, 0.2])
    assert (path.alpha_pixels == 1.0).all()


def test_batch_solves_as_one_item_at_a_time():
    # two cells of one grid size (different sides and loads) as one batch, with convergence
    # checked every 4 iterations (as on a GPU): each item as solved alone, within tolerance
    a, b = height_map(EXAMPLE, 96), height_map(_random_design(2), 96)
    sides = np.array([a.cell_side, b.cell_side])
    tops = [get_model().model_curve(d).p_star_max for d in (EXAMPLE, _random_design(2))]
    loads = np.array([[0.3 * tops[0], tops[0]], [0.5 * tops[1], 0.9 * tops[1]]])
    got = {}

    def keep(k, pressures, gaps, errors, seconds):
        got[k] = (pressures, gaps, errors)

    heights = np.stack([a.heights, b.heights])
    tb.solve_paths(
        heights,
        sides,
        loads,
        device=CPU,
        tolerance=1e-11,
        max_iter=1000,
        on_load=keep,
        check_every=4,
    )
    assert sorted(got) == [0, 1]
    for i, hm in enumerate((a, b)):
        alone = _solve(hm.heights, hm.cell_side, loads[i], "torch", n=9, owner=hm.owner)
        for k in range(2):
            pressures, gaps, errors = got[k]
            assert errors[i] <= 1e-11 and gaps[i].min() == 0.0
            scale = alone.pressures[k].max()
            assert np.abs(pressures[i] - alone.pressures[k]).max() < 1e-7 * scale


def test_validate_runs_on_torch_without_tamaas(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "tamaas", None)  # import tamaas -> ImportError
    res = mi.validate(EXAMPLE, grid=48, loads=2, device="cpu", out=tmp_path / "run")
    assert res.engine == "torch" and res.summary()["engine"] == "torch"
    assert (res.residual <= 1e-11).all() and np.abs(res.rel_err).max() < 0.2
    auto = validate_design(EXAMPLE, 48, 2, device="auto")  # the CPU here
    np.testing.assert_allclose(auto.alpha_bem, res.alpha_bem, rtol=1e-9)
    text = (tmp_path / "run" / "result.json").read_text()
    assert '"engine": "torch"' in text
    with pytest.raises(MetainterfaceError, match=r"pip install 'metainterface\[bem\]'"):
        mi.validate(EXAMPLE, grid=48, loads=2, engine="tamaas")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"engine": "fenics"}, "engine must be one of torch, tamaas, got 'fenics'"),
        ({"device": "tpu"}, "device must be one of auto, cpu, cuda or cuda:N"),
        ({"device": "cuda:x"}, "device must be one of"),
    ],
)
def test_bad_engine_or_device_is_one_line(kwargs, match):
    with pytest.raises(MetainterfaceError, match=match) as exc:
        mi.validate(EXAMPLE, grid=48, loads=2, **kwargs)
    assert "\n" not in str(exc.value)
    with pytest.raises(MetainterfaceError, match=match):
        validate_design(EXAMPLE, 48, 2, **kwargs)


@pytest.mark.skipif(torch.cuda.is_available(), reason="checks the refusal where there is no GPU")
def test_cuda_without_a_gpu_is_refused_before_solving():
    with pytest.raises(MetainterfaceError, match="torch sees no CUDA device"):
        mi.validate(EXAMPLE, grid=48, loads=2, device="cuda")


def test_engines_registry_matches_the_cli_names():
    from metainterface._names import DEFAULT_ENGINE, ENGINE_NAMES
    from metainterface.validation import ENGINES

    assert tuple(ENGINES) == ENGINE_NAMES and get_engine().name == DEFAULT_ENGINE == "torch"
    assert get_engine(" Tamaas ").name == "tamaas"


def test_workers_solve_on_one_thread_each():
    # a path split over two forked processes (torch on one thread there) gives the same areas
    one = validate_design(EXAMPLE, 48, 4, jobs=1)
    two = validate_design(EXAMPLE, 48, 4, jobs=2)
    np.testing.assert_allclose(two.alpha_bem, one.alpha_bem, rtol=1e-6)


def test_a_sweep_resumed_with_another_engine_solves_again(tmp_path):
    pytest.importorskip("tamaas")
    out = tmp_path / "sweep"
    first = mi.validate_many([EXAMPLE], out, grid=48, loads=2, progress=False)
    again = mi.validate_many([EXAMPLE], out, grid=48, loads=2, progress=False)
    assert again == first  # the same engine: reused
    other = mi.validate_many([EXAMPLE], out, grid=48, loads=2, progress=False, engine="tamaas")
    assert other["design_0000"]["engine"] == "tamaas"
    assert other["design_0000"]["max_rel_err"] == pytest.approx(
        first["design_0000"]["max_rel_err"], rel=1e-5
    )
    assert '"engine": "tamaas"' in (out / "design_0000" / "result.json").read_text()


def test_a_sweep_solves_designs_as_one_batch(tmp_path, monkeypatch):
    # three designs of one grid as batches of two (as on a GPU): the same results as one by
    # one; a batch whose solve fails is solved again design by design
    designs = [EXAMPLE, _random_design(4), _random_design(5)]
    kw = dict(grid=48, loads=3, progress=False)
    single = mi.validate_many(designs, tmp_path / "one", batch=1, **kw)
    both = mi.validate_many(designs, tmp_path / "batch", batch=2, **kw)
    for name, s in single.items():
        assert both[name]["max_rel_err"] == pytest.approx(s["max_rel_err"], rel=1e-6, abs=1e-9)

    def fail(*args, **kwargs):
        raise ArithmeticError(0, "NaN")

    monkeypatch.setattr(tb, "solve_paths", fail)
    again = mi.validate_many(designs, tmp_path / "fallback", batch=3, **kw)
    for name, s in single.items():
        assert again[name]["max_rel_err"] == pytest.approx(s["max_rel_err"], rel=1e-6, abs=1e-9)
    with pytest.raises(MetainterfaceError, match="batch > 1 needs engine='torch'"):
        mi.validate_many(designs, tmp_path / "x", batch=2, chunks=2, **kw)


def test_a_failed_solve_is_one_line_naming_the_load(monkeypatch):
    def nan(*args, **kwargs):
        raise ArithmeticError("the solve of item 0 produced NaN")

    monkeypatch.setattr(tb, "solve_batch", nan)
    with pytest.raises(MetainterfaceError, match=r"BEM failed at load 1 of 2 \(P\* = .*finer grid"):
        validate_design(HERTZ, 32, 2)
