"""design's option groups as a user calls them: built once, reused, the same designs as the
keywords they stand for, and a one-line error when a group meets one of its own keywords."""

import dataclasses
import json

import numpy as np
import pytest

import metainterface as mi

#: A quick design: a few unrefined random starts, no BEM check.
QUICK = {"method": "multistart", "verify": False}


def test_groups_are_frozen_values_with_design_defaults() -> None:
    effort = mi.Effort(starts=8, seed=1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        effort.starts = 9  # type: ignore[misc]
    assert effort == mi.Effort(starts=8, seed=1)  # a value: equal when its fields are
    assert (mi.Effort().starts, mi.Effort().hedge, mi.Effort().fallback) == (50, 8, 50)
    assert mi.Robust().samples == 16
    assert mi.Scale() == mi.Scale(radius=None, modulus=None, total_force=None, area=None)
    for name in ("Effort", "Scale", "Robust"):
        assert name in mi.__all__ and name in dir(mi)


def test_effort_designs_as_its_keywords() -> None:
    effort = mi.Effort(starts=4, refine=False, seed=3)
    grouped = mi.design("bilinear", effort=effort, **QUICK)
    with pytest.deprecated_call(match=r"pass effort=mi.Effort\(starts=\.\.\., refine="):
        flat = mi.design("bilinear", starts=4, refine=False, seed=3, **QUICK)
    np.testing.assert_array_equal(grouped.design.gamma, flat.design.gamma)
    np.testing.assert_array_equal(grouped.design.h, flat.design.h)
    again = mi.design("saturating", effort=effort, **QUICK)  # reused for another target
    assert again.target.name == "saturating"


def test_robust_is_robust_true_with_its_errors() -> None:
    quick = mi.Effort(starts=2, refine=False)
    grouped = mi.design(
        "bilinear", effort=quick, robust=mi.Robust(sigma_h=0.002, samples=2), **QUICK
    )
    with pytest.deprecated_call(match=r"robust=mi.Robust\(sigma_h=\.\.\., samples="):
        flat = mi.design(
            "bilinear", effort=quick, robust=True, sigma_h=0.002, robust_samples=2, **QUICK
        )
    assert grouped.robust == flat.robust
    assert grouped.robust["robust_samples"] == 2


def test_scale_reads_a_stress_limit_and_writes_the_si_block(tmp_path) -> None:
    quick = mi.Effort(starts=2, refine=False)
    pad = mi.Scale(radius="0.5mm", modulus="2MPa", area="4cm2")
    r = mi.design("bilinear", effort=quick, scale=pad, max_pressure="1MPa", out=tmp_path, **QUICK)
    with pytest.deprecated_call(match="scale=mi.Scale"):
        flat = mi.design("bilinear", effort=quick, modulus="2MPa", max_pressure="1MPa", **QUICK)
    assert r.pressure is not None and r.pressure.e_star == flat.pressure.e_star == 2e6
    np.testing.assert_array_equal(r.pressure.peak, flat.pressure.peak)
    block = json.loads((tmp_path / "design.json").read_text())["physical"]
    assert block["radius_m"] == pytest.approx(5e-4)


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"effort": mi.Effort(), "starts": 4}, "effort=Effort(...) or starts, not both"),
        ({"scale": mi.Scale(modulus="2MPa"), "radius": "1mm"}, "scale=Scale(...) or radius"),
        ({"robust": mi.Robust(sigma_h=0.1), "robust_samples": 4}, "robust_samples, not both"),
        ({"effort": {"starts": 4}}, "effort must be Effort(...), got dict"),
        ({"scale": "1mm"}, "scale must be Scale(...), got str"),
    ],
)
def test_a_group_and_its_keyword_is_one_line_error(options, words) -> None:
    with pytest.raises(mi.MetainterfaceError) as err:
        mi.design("bilinear", **QUICK, **options)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_help_of_design_fits_one_screen() -> None:
    assert len(mi.design.__doc__.splitlines()) <= 60
    for group in (mi.Effort, mi.Scale, mi.Robust):
        assert "Examples" in group.__doc__


def test_design_takes_at_most_15_parameters_and_fits_a_screen() -> None:
    import contextlib
    import inspect
    import io

    assert len(inspect.signature(mi.design).parameters) <= 15
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        help(mi.design)
    assert len(text.getvalue().splitlines()) <= 40


def test_an_unknown_keyword_is_one_line() -> None:
    with pytest.raises(mi.MetainterfaceError, match="unexpected keyword 'stars'"):
        mi.design("bilinear", stars=3)


def test_an_old_error_without_robust_is_still_one_line() -> None:
    with pytest.deprecated_call(), pytest.raises(mi.MetainterfaceError, match="need robust=True"):
        mi.design("bilinear", sigma_h=0.001)
