"""One answer on reach (issue 39): ``reachability``, ``feasible_scale`` and ``design`` ask
the same test, so they agree on every law, and ``design`` says a target is partly out of
reach before it starts the work."""

import warnings

import numpy as np
import pytest

import metainterface as mi
from metainterface._testing import borderline_laws

UNITS = dict(shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="4cm2")
TAU, E_STAR, AREA = 0.25e6, 2e6, 4e-4


def test_reachability_and_feasible_scale_agree(tmp_path):
    verdicts = []
    for i, (p, alpha) in enumerate(borderline_laws(24, seed=3)):
        csv = tmp_path / f"law{i}.csv"
        fn, ff = p * AREA * E_STAR, alpha * TAU * AREA
        csv.write_text(
            "normal_force,friction_force\n"
            + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(fn, ff, strict=True))
        )
        r = mi.reachability(csv, **UNITS)
        fs = mi.feasible_scale(csv, fit="never", **UNITS)
        assert r.reachable == fs.reachable, (i, r.message, fs.summary())
        verdicts.append(r.reachable)
    assert 0 < sum(verdicts) < len(verdicts)  # both answers occur


def test_design_says_partly_out_of_reach_before_the_work(tmp_path):
    p = np.linspace(0.0, 1e-3, 12)
    target = mi.Target(p_star=p, alpha=2 * p, name="flat")  # alpha/P* below any cell's
    with warnings.catch_warnings():
        warnings.simplefilter("error", mi.ReachWarning)  # raised at the first warning
        with pytest.raises(mi.ReachWarning, match=r"flat.*outside the reachable envelope"):
            mi.design(target, out=tmp_path / "out", verify=False)
    assert not (tmp_path / "out").exists()  # said before any work or file
    with pytest.warns(mi.ReachWarning) as said:
        r = mi.design(target, verify=False, effort=mi.Effort(refine=False))
    assert len(said) == 1 and said[0].message.args[0].endswith("designing the closest cell")
    assert any("outside the reachable envelope" in n for n in r.notes)  # kept in the record


def test_a_reachable_target_says_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("error", mi.ReachWarning)
        mi.design("bilinear", verify=False, effort=mi.Effort(refine=False))
