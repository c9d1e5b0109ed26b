"""The public functions, fed anything: a correct result or one MetainterfaceError line.

Properties (Hypothesis): whatever goes into ``Target``, ``curve``, ``Design.from_dict``,
``CellSettings`` or a CSV reader comes out as a finite result or a one-line
MetainterfaceError, never another exception or a NaN. Then a table of bad arguments for every
public function, each naming the argument.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from robust_helpers import SLOW_EXAMPLES

import metainterface as mi

ANY_NUMBER = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**80), max_value=2**80),
    st.booleans(),
    st.text(max_size=6),
    st.none(),
)
NUMBERISH = st.one_of(st.floats(0, 0.05), ANY_NUMBER)


def one_line(exc: BaseException) -> str:
    text = str(exc)
    assert text and "\n" not in text and "Traceback" not in text, text
    return text


def _target(p_star, alpha) -> None:
    try:
        t = mi.Target(p_star=p_star, alpha=alpha)
    except mi.MetainterfaceError as exc:
        one_line(exc)
        return
    assert np.isfinite(t.p_star).all() and np.isfinite(t.alpha).all()
    assert (np.diff(t.p_star) > 0).all()
    assert ((t.alpha >= 0) & (t.alpha < 1)).all()


@given(
    p_star=st.one_of(st.lists(NUMBERISH, max_size=6), ANY_NUMBER),
    alpha=st.one_of(st.lists(NUMBERISH, max_size=6), ANY_NUMBER),
)
def test_target_takes_anything(p_star, alpha):
    _target(p_star, alpha)


@given(n=st.integers(3, 8), data=st.data())
def test_target_curves_near_valid(n, data):
    """Nearly valid curves (increasing from 0), with one value spoiled."""
    p = np.linspace(0.0, 1e-3, n)
    a = np.linspace(0.0, 0.05, n)
    which = data.draw(st.sampled_from(["p", "a"]))
    i = data.draw(st.integers(0, n - 1))
    value = data.draw(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.just(1.5)))
    (p if which == "p" else a)[i] = value
    _target(p, a)


def _curve(gamma, h, n_asperities) -> None:
    settings_ = mi.CellSettings(n_asperities=n_asperities) if n_asperities else None
    try:
        c = mi.curve(gamma=gamma, h=h, settings=settings_, steps=16)
    except mi.MetainterfaceError as exc:
        one_line(exc)
        return
    for arr in (c.delta, c.p_star, c.alpha):
        assert np.isfinite(arr).all()
    assert (c.alpha >= 0).all() and (c.alpha < 1).all()


@given(
    gamma=st.one_of(st.lists(st.one_of(st.floats(1.5, 4.5), ANY_NUMBER), max_size=9), ANY_NUMBER),
    h=st.one_of(st.lists(st.one_of(st.floats(0, 0.05), ANY_NUMBER), max_size=9), ANY_NUMBER),
    n_asperities=st.sampled_from([None, 4, 9]),
)
def test_curve_takes_anything(gamma, h, n_asperities):
    _curve(gamma, h, n_asperities)


@pytest.mark.slow
@settings(max_examples=SLOW_EXAMPLES)
@given(
    gamma=st.lists(st.one_of(st.floats(1.5, 4.5), ANY_NUMBER), min_size=1, max_size=16),
    h=st.lists(st.one_of(st.floats(0, 0.1), ANY_NUMBER), min_size=1, max_size=16),
    n_asperities=st.sampled_from([None, 1, 4, 9, 16]),
)
def test_curve_takes_anything_many(gamma, h, n_asperities):
    _curve(gamma, h, n_asperities)


DESIGN_FIELDS = {
    "gamma": st.one_of(st.lists(st.one_of(st.floats(1.8, 4.0), ANY_NUMBER), max_size=4)),
    "h": st.one_of(st.lists(st.one_of(st.floats(0, 0.02), ANY_NUMBER), max_size=4)),
    "radius": ANY_NUMBER,
    "delta_max": ANY_NUMBER,
    "e_star": ANY_NUMBER,
    "gamma_bounds": st.one_of(st.lists(ANY_NUMBER, max_size=3), ANY_NUMBER),
    "format": st.one_of(st.just("metainterface/design-v1"), st.text(max_size=5)),
}


@given(data=st.fixed_dictionaries({}, optional=DESIGN_FIELDS))
def test_design_files_take_anything(data):
    try:
        d = mi.Design.from_dict(data, source="fuzz.json")
    except mi.MetainterfaceError as exc:
        assert one_line(exc).startswith("fuzz.json")
        return
    assert np.isfinite(d.gamma).all() and np.isfinite(d.h).all()
    c = mi.curve(d, steps=8)
    assert np.isfinite(c.alpha).all() and np.isfinite(c.p_star).all()


@given(
    kwargs=st.fixed_dictionaries(
        {},
        optional={
            "n_asperities": st.one_of(st.integers(-2, 20_000), ANY_NUMBER),
            "radius": ANY_NUMBER,
            "e_star": ANY_NUMBER,
            "delta_max": ANY_NUMBER,
            "gamma_min": ANY_NUMBER,
            "gamma_max": ANY_NUMBER,
            "n_steps": st.one_of(st.integers(-2, 2 * 10**6), ANY_NUMBER),
        },
    )
)
def test_cell_settings_take_anything(kwargs):
    try:
        s = mi.CellSettings(**kwargs)
    except mi.MetainterfaceError as exc:
        one_line(exc)
        return
    assert math.isfinite(s.nominal_area) and s.nominal_area > 0


@given(content=st.binary(max_size=200))
def test_csv_reader_takes_any_bytes(tmp_path_factory, content):
    path = tmp_path_factory.mktemp("csv") / "t.csv"
    path.write_bytes(content)
    try:
        t = mi.Target.from_csv(path)
    except mi.MetainterfaceError as exc:
        assert str(path) in one_line(exc)
        return
    assert np.isfinite(t.alpha).all()


@given(
    bom=st.booleans(),
    ending=st.sampled_from(["\n", "\r\n", "\r"]),
    encoding=st.sampled_from(["utf-8", "latin-1", "cp1252"]),
    quoted=st.booleans(),
    comment=st.sampled_from(["", "# mesuré à 20 °C", "# plain"]),
)
def test_csv_encodings_read_the_same(tmp_path_factory, bom, ending, encoding, quoted, comment):
    """A UTF-8 BOM, Latin-1 text, any line ending or quoted cells give the same target."""
    header = '"p_star","alpha"' if quoted else "p_star,alpha"
    lines = ([comment] if comment else []) + [header, "0,0", "0.0005,0.01", "0.001,0.02"]
    data = ending.join(lines).encode(encoding)
    path = tmp_path_factory.mktemp("enc") / "law.csv"
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + data)
    t = mi.Target.from_csv(path)
    np.testing.assert_array_equal(t.p_star, [0.0, 0.0005, 0.001])
    np.testing.assert_array_equal(t.alpha, [0.0, 0.01, 0.02])


# --- a table of bad arguments for every public function ----------------------------------

DESIGN = mi.Design(gamma=[2.0, 2.5, 3.0, 3.5], h=[0.0, 0.002, 0.004, 0.008])
NINE = {"gamma": [2.0] * 9, "h": [0.0] * 9}


def api_cases(tmp):
    """(callable, the argument its error must name)."""
    t = "linear"
    return [
        (lambda: mi.design(t, effort=mi.Effort(starts=0)), "starts"),
        (lambda: mi.design(t, effort=mi.Effort(starts=2**70)), "starts"),
        (lambda: mi.design(t, effort=mi.Effort(starts=2.5)), "starts"),
        (lambda: mi.design(t, effort=mi.Effort(starts=True)), "starts"),
        (lambda: mi.design(t, effort=mi.Effort(hedge=-1)), "hedge"),
        (lambda: mi.design(t, effort=mi.Effort(fallback=-1)), "fallback"),
        (lambda: mi.design(t, effort=mi.Effort(seed=-1)), "seed"),
        (lambda: mi.design(t, effort=mi.Effort(seed=2**70)), "seed"),
        (lambda: mi.design(t, method="magic"), "method"),
        (lambda: mi.design(t, model="magic"), "magic"),
        (lambda: mi.design(t, max_pressure=-1), "max_pressure"),
        (lambda: mi.design(t, out=""), "output"),
        (lambda: mi.design(t, out=tmp / "afile"), "afile"),
        (lambda: mi.design([], method="hertz"), "target"),
        (lambda: mi.design([t, t]), "2 times"),
        (lambda: mi.compare(t, method="hertz"), "method"),
        (lambda: mi.compare(t, out=tmp / "afile"), "afile"),
        (lambda: mi.curve(DESIGN, steps=1), "steps"),
        (lambda: mi.curve(DESIGN, steps=10**9), "steps"),
        (lambda: mi.curve(DESIGN, smooth=float("nan")), "smooth"),
        (lambda: mi.curve(DESIGN, model="magic"), "magic"),
        (lambda: mi.curve(gamma=[2.0] * 4, h=[0.0] * 4, settings=mi.CellSettings()), "gamma"),
        (lambda: mi.curve(gamma=["2"] * 9, h=[0.0] * 9), "gamma[0]"),
        (lambda: mi.curve(gamma=[2.0] * 9, h=[0.0] * 8), "same length"),
        (lambda: mi.curve(gamma=[2.0] * 8, h=[0.0] * 8), "perfect square"),
        (lambda: mi.curve(gamma=[2.0] * 9, h=[0.0] * 8 + [1e300]), "h[8]"),
        (lambda: mi.curve(gamma=[[2.0]] * 9, h=[0.0] * 9), "gamma[0]"),
        (lambda: mi.curve(tmp / "missing.json"), "missing.json"),
        (lambda: mi.curve(42), "design"),
        (lambda: mi.export(DESIGN, tmp / "p.stl", radius=1e300), "radius"),
        (lambda: mi.export(DESIGN, tmp / "p.stl", radius="-1mm"), "radius"),
        (lambda: mi.export(DESIGN, tmp / "p.stl", radius="1mm", tiles=(0, 1)), "tiles"),
        (lambda: mi.export(DESIGN, tmp / "p.stl", radius="1mm", resolution=0), "resolution"),
        (lambda: mi.export(DESIGN, tmp / "p.stl", radius="1mm", base="1km"), "base"),
        (lambda: mi.export(DESIGN, tmp / "p.xyz", radius="1mm"), "xyz"),
        (lambda: mi.export(DESIGN, "", radius="1mm"), "output"),
        (lambda: mi.export(DESIGN, tmp / "fifo", radius="1mm"), "fifo"),
        (lambda: mi.physical(DESIGN, radius="1mm", modulus="-2MPa"), "modulus"),
        (lambda: mi.physical(DESIGN, radius="1 kg", modulus="2MPa"), "radius"),
        (lambda: mi.pressure_check(DESIGN, 2.0), "max_pressure"),
        (lambda: mi.pressure_check(DESIGN, "50MPa"), "modulus"),
        (lambda: mi.validate(DESIGN, grid=7), "grid"),
        (lambda: mi.validate(DESIGN, grid=10**6), "grid"),
        (lambda: mi.validate(DESIGN, loads=10**9), "loads"),
        (lambda: mi.validate(DESIGN, tolerance=10.0), "tolerance"),
        (lambda: mi.validate(DESIGN, jobs=0), "jobs"),
        (lambda: mi.validate(DESIGN, grid=16, out=tmp / "afile"), "afile"),
        (lambda: mi.generate_dataset(0, tmp / "d.npz"), "samples"),
        (lambda: mi.generate_dataset(10**12, tmp / "d.npz"), "samples"),
        (lambda: mi.generate_dataset(10, tmp / "d.npz", seed=-1), "seed"),
        (lambda: mi.generate_dataset(10, tmp / "d.npz", chunk=0), "chunk"),
        (lambda: mi.generate_dataset(10, ""), "output"),
        (lambda: mi.generate_dataset(10, tmp / "afile" / "d.npz"), "afile"),
        (lambda: mi.train_surrogate(tmp / "afile", tmp / "run"), "afile"),
        (lambda: mi.train_surrogate(tmp / "missing.npz", tmp / "afile"), "afile"),
        (lambda: mi.evaluate_surrogate(tmp / "afile"), "afile"),
        (lambda: mi.TrainConfig(epochs=0), "epochs"),
        (lambda: mi.TrainConfig(lr=float("inf")), "lr"),
        (lambda: mi.TrainConfig(curriculum_epochs=-1), "curriculum_epochs"),
        (lambda: mi.TrainConfig(w_shape=0, w_grad=0, w_mag=0, w_curve=0), "w_shape"),
        (lambda: mi.TrainConfig(seed=2**64), "seed"),
        (lambda: mi.Target(p_star=[0, 1, 2], alpha=[0, 0.5, 1.5]), "alpha"),
        (lambda: mi.Target(p_star=[0, 2, 1], alpha=[0, 0.1, 0.2]), "p_star"),
        (lambda: mi.Target(p_star=[0, 1, float("nan")], alpha=[0, 0.1, 0.2]), "p_star"),
        (lambda: mi.Target(p_star=[0, 1], alpha=[0, 0.1, 0.2]), "same length"),
        (lambda: mi.Target(p_star=[[0, 1, 2]], alpha=[[0, 0.1, 0.2]]), "1-D"),
        (lambda: mi.Target.builtin("magic"), "magic"),
        (lambda: mi.Target(p_star=[0, 1e-3, 2e-3], alpha=[0, 0.01, 0.02], name="../x"), "name"),
        (lambda: mi.validate(DESIGN, grid=16, jobs=10**6), "jobs"),
        (lambda: mi.CellSettings(delta_max=1e-300), "delta_max"),
        (lambda: mi.CellSettings(gamma_max=1e6), "gamma_max"),
        (lambda: mi.CellSettings(n_asperities=10**8), "n_asperities"),
        (lambda: mi.CellSettings(radius="1"), "radius"),
        (lambda: mi.get_model("magic"), "magic"),
    ]


N_API = len(api_cases(None))


@pytest.mark.parametrize("index", range(N_API))
def test_public_functions_refuse_in_one_line(index, tmp_path):
    (tmp_path / "afile").write_text("x")
    import os

    os.mkfifo(tmp_path / "fifo")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    call, field = api_cases(tmp_path)[index]
    with pytest.raises(mi.MetainterfaceError) as info:
        call()
    assert field.lower() in one_line(info.value).lower()
    assert sorted(p.name for p in tmp_path.rglob("*")) == before
