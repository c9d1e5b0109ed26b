"""Reachability in friction terms: the issue's three everyday laws are out of reach at
E* = 2 MPa, tau = 0.25 MPa, R = 0.5 mm on 4 cm^2; design refuses them unless forced."""

import json
import math

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.cli import main
from metainterface.inverse.verdict import law_reachability as reachability
from metainterface.physics.curves import sweep
from metainterface.units.reach import alpha_bounds

UNITS = dict(shear_strength="0.25MPa", modulus="2MPa", area="4cm2", radius="0.5mm")
FN = np.linspace(0.25, 6.0, 24)
LAWS = {
    "constant": 0.4 * FN,
    "saturating": 1.2 * (1 - np.exp(-FN / 1.5)),
    "power": 0.3 * FN ** (2 / 3),
}


def _csv(folder, name, ff):
    path = folder / f"{name}.csv"
    path.write_text(
        "normal_force,friction_force\n" + "".join(f"{a},{b}\n" for a, b in zip(FN, ff, strict=True))
    )
    return path


@pytest.mark.parametrize("name", LAWS)
def test_the_three_laws_are_out_of_reach_with_the_reachable_mu_stated(name, tmp_path):
    r = mi.reachability(_csv(tmp_path, name, LAWS[name]), **UNITS)
    assert isinstance(r, mi.Reachability) and not r.reachable and not r
    mu = LAWS[name] / FN
    assert r.law_mu == pytest.approx((mu.min(), mu.max()))
    # alpha / P* = mu E* / tau: no cell goes below mu ~ 1.8 at these loads
    assert 1.6 < r.reachable_mu[0] < 2.0 and r.reachable_mu[0] > r.law_mu[1]
    assert r.load_range[1] < 6.0 and r.coverage < 1
    lines = r.message.splitlines()
    assert 1 <= len(lines) <= 2
    assert "not reachable" in lines[0] and "mu" in lines[0] and "N" in lines[0]
    assert "shear strength" in lines[1] and "larger area" in lines[1]


def test_a_reachable_law_and_the_advice_it_gives(tmp_path):
    # the advice for the constant law: a lower tau; following it makes the law reachable
    # once the area is large enough too
    r = mi.reachability(_csv(tmp_path, "c", LAWS["constant"]), **UNITS)
    kpa = [float(v) for v in r.message.split("tau of ")[1].split(" kPa")[0].split(" kPa-")[0:1]]
    ok = mi.reachability(
        _csv(tmp_path, "c", LAWS["constant"]),
        shear_strength=f"{kpa[0] * 1.05}kPa",
        modulus="2MPa",
        area="6cm2",
        radius="0.5mm",
    )
    assert ok.reachable and ok.message.startswith("reachable")
    assert ok.reachable_mu[0] <= 0.4 <= ok.reachable_mu[1]


def test_builtin_targets_are_reachable_and_in_ratio_terms():
    for name in mi.Target.builtins():
        r = mi.reachability(mi.Target.builtin(name))
        assert r.reachable and not r.units and "alpha/P*" in r.message


def test_bounds_hold_every_design_and_are_met_by_uniform_cells():
    s = mi.CellSettings()
    gen = torch.Generator().manual_seed(0)
    gamma = s.gamma_min + (s.gamma_max - s.gamma_min) * torch.rand(64, 9, generator=gen)
    h = s.delta_max * torch.rand(64, 9, generator=gen) * 1.5
    sw = sweep(gamma.double(), h.double(), s, n_delta=64)
    p, a = sw.p_star.numpy(), sw.alpha.numpy()
    lo, hi, reach = alpha_bounds(p.ravel(), s)
    ok = p.ravel() > 0
    assert np.all(a.ravel()[ok] >= lo[ok] * (1 - 1e-6))
    assert np.all(a.ravel()[ok] <= hi[ok] * (1 + 0.05))  # mixed gammas: within the slack
    assert p.max() <= reach
    # a uniform cell at h = 0 (all asperities share the load) lies within the bounds
    g = torch.full((1, 9), 2.5, dtype=torch.float64)
    one = sweep(g, torch.zeros_like(g), s, n_delta=16)
    lo1, hi1, _ = alpha_bounds(one.p_star[0, 1:].numpy(), s)
    a1 = one.alpha[0, 1:].numpy()
    # (the bounds are exact at their force grid's points, within ~0.5 % between them)
    assert np.all(a1 <= hi1 * (1 + 1e-2)) and np.all(a1 >= lo1 * (1 - 1e-2))


def test_dimensionless_reachability_matches_the_friction_one():
    s = mi.CellSettings()
    tau, e, area = 0.25e6, 2e6, 4e-4
    ff = LAWS["power"]
    a = reachability(FN, ff, shear_strength=tau, e_star=e, area=area, settings=s)
    b = reachability(FN / (area * e), ff / (tau * area), settings=s, units=False)
    assert a.reachable == b.reachable
    assert b.reachable_mu[0] * tau / e == pytest.approx(a.reachable_mu[0])
    assert math.isclose(a.coverage, b.coverage)


def test_design_refuses_an_unreachable_law_in_one_line(tmp_path):
    t = mi.Target.from_friction(_csv(tmp_path, "c", LAWS["constant"]), **UNITS)
    out = tmp_path / "out"
    with pytest.raises(mi.UnreachableError) as info:
        mi.design(t, out=out)
    assert isinstance(info.value, ValueError) and "\n" not in str(info.value)
    assert "mu" in str(info.value) and "force=True" in str(info.value)
    assert not out.exists()


def test_forced_design_is_marked_everywhere(tmp_path):
    t = mi.Target.from_friction(_csv(tmp_path, "c", LAWS["constant"]), **UNITS)
    with pytest.warns(mi.ReachWarning, match=r"friction law c: not reachable.*closest cell$"):
        r = mi.design(
            t, force=True, out=tmp_path / "f", verify=False, effort=mi.Effort(hedge=0, fallback=0)
        )
    assert r.forced and "FORCED" in repr(r) and r.notes[0].startswith("FORCED")
    assert r.coverage < 0.5 and r.error >= 1 - r.coverage
    record = json.loads((tmp_path / "f" / "design.json").read_text())
    assert record["forced"] is True and record["coverage"] == pytest.approx(r.coverage)
    assert record["carrying_asperities"] == r.carrying
    assert record["idle_asperities"] == list(r.idle)


def test_cli_exits_2_with_two_lines_and_writes_nothing(tmp_path, capsys):
    law = _csv(tmp_path, "power", LAWS["power"])
    args = [
        "design",
        "--friction-csv",
        str(law),
        "--shear-strength",
        "0.25MPa",
        "--modulus",
        "2MPa",
        "--radius",
        "0.5mm",
        "--area",
        "4cm2",
        "--hedge",
        "0",
        "--fallback",
        "0",
        "--no-verify",
    ]
    out = tmp_path / "out"
    assert main([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "not reachable" in err[0] and "mu" in err[0]
    assert "--force" in err[1] and "Traceback" not in "".join(err)
    assert not out.exists()
    assert main([*args, "--out", str(out), "--force"]) == 0
    printed = capsys.readouterr().out
    assert "FORCED" in printed and "coverage" in printed
    assert json.loads((out / "design.json").read_text())["forced"] is True
