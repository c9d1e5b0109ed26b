"""Every command, fed hostile input: exit status 2, one line naming the field, nothing written.

Table-driven cases for what a user can get wrong (ranges, overflow, types, encodings, special
paths, foreign files), then Hypothesis over the numeric options: any value outside an option's
range is refused the same way.
"""

from __future__ import annotations

import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from robust_helpers import SLOW_EXAMPLES, assert_refused

import metainterface as mi
from metainterface.units import parse_length

BIG = str(2**70)


def cases(d: str) -> list[tuple[list[str], str]]:
    """(argv, the field the one-line error must name); ``d`` is the inputs folder."""
    o = f"{d}/out/new"
    design = ["design", "--target", "linear", "--out", o]
    curve = ["curve", f"{d}/design.json", "--out", f"{o}.csv"]
    export = ["export", f"{d}/design.json", "--radius", "0.5mm", "--out", f"{o}.stl"]
    gen = ["generate", "--samples", "10", "--seed", "0", "--out", f"{o}.npz", "--quiet"]
    train = ["train", "--dataset", f"{d}/small.npz", "--out", o, "--batch-size", "8"]
    val = ["validate", f"{d}/design.json", "--grid", "16", "--loads", "2", "--out", o]
    friction = ["--shear-strength", "1MPa", "--modulus", "2MPa", "--radius", "0.5mm"]
    return [
        # design: ranges, overflow, types, files
        ([*design, "--starts", "0"], "--starts"),
        ([*design, "--starts", "1000000000"], "--starts"),
        ([*design, "--hedge", "-1"], "--hedge"),
        ([*design, "--fallback", "-1"], "--fallback"),
        ([*design, "--seed", "-1"], "--seed"),
        ([*design, "--seed", BIG], "--seed"),
        ([*design, "--seed", "2**70"], "--seed"),
        ([*design, "--n-asperities", "8"], "--n-asperities"),
        ([*design, "--gamma-min", "nan"], "--gamma-min"),
        ([*design, "--gamma-max", "1e9"], "--gamma-max"),
        ([*design, "--delta-max", "1e-300"], "--delta-max"),
        ([*design, "--delta-max", "inf"], "--delta-max"),
        ([*design, "--max-pressure", "-1"], "--max-pressure"),
        ([*design, "--method", "magic"], "--method"),
        ([*design, "--model", f"{d}/evil.pt"], "evil.pt"),
        ([*design, "--model", f"{d}/junk.pt"], "junk.pt"),
        ([*design, "--model", f"{d}/small.npz"], "small.npz"),
        (["design", "--target", "nope", "--out", o], "target"),
        (["design", "--target-csv", f"{d}/alpha_gt1.csv", "--out", o], "alpha"),
        (["design", "--target-csv", f"{d}/decreasing.csv", "--out", o], "p_star"),
        (["design", "--target-csv", f"{d}/nan.csv", "--out", o], "alpha"),
        (["design", "--target-csv", f"{d}/binary.csv", "--out", o], "binary.csv"),
        (["design", "--target-csv", f"{d}/missing.csv", "--out", o], "missing.csv"),
        (
            ["design", "--friction-csv", f"{d}/both.csv", *friction, "--area", "4cm2", "--out", o],
            "friction_coefficient",
        ),
        (["design", "--friction-csv", f"{d}/plain.csv", *friction, "--out", o], "--area"),
        ([*design, "--radius", "1e300", "--modulus", "2MPa"], "--radius"),
        ([*design, "--radius", "1mm", "--modulus", "1e300"], "--modulus"),
        ([*design, "--radius", "1mm", "--modulus", "2MPa", "--area", "1e-300"], "--area"),
        (
            [*design, "--radius", "1mm", "--modulus", "2MPa", "--total-force", "1e300"],
            "--total-force",
        ),
        (
            [
                *design,
                "--method",
                "hertz",
                "--starts",
                "1",
                "--refine",
                "none",
                "--radius",
                "1mm",
                "--modulus",
                "2MPa",
                "--area",
                "1um2",
            ],
            "--area",
        ),
        (["design", "--target", "linear", "--out", ""], "output"),
        (["design", "--target", "linear", "--out", f"{d}/afile"], "afile"),
        (["design", "--target", "linear", "--out", f"{d}/afile/sub"], "afile"),
        (["design", "--target", "linear", "--out", f"{d}/fifo"], "fifo"),
        # curve: design files, sizes, special outputs
        ([*curve, "--steps", "0"], "--steps"),
        ([*curve, "--steps", "100000000"], "--steps"),
        ([*curve, "--steps", BIG], "--steps"),
        ([*curve, "--smooth", "nan"], "--smooth"),
        ([*curve, "--smooth", "1e-300"], "--smooth"),
        ([*curve, "--physics", "magic"], "--physics"),
        ([*curve, "--plot", f"{o}.bogus"], "bogus"),
        (["curve", f"{d}/strnum.json", "--out", f"{o}.csv"], "gamma[0]"),
        (["curve", f"{d}/bool.json", "--out", f"{o}.csv"], "gamma[0]"),
        (["curve", f"{d}/nested.json", "--out", f"{o}.csv"], "h[0]"),
        (["curve", f"{d}/radius.json", "--out", f"{o}.csv"], "radius"),
        (["curve", f"{d}/absurd_h.json", "--out", f"{o}.csv"], "h[3]"),
        (["curve", f"{d}/notjson.json", "--out", f"{o}.csv"], "malformed JSON"),
        (["curve", f"{d}/missing.json", "--out", f"{o}.csv"], "missing.json"),
        (["curve", f"{d}/fifo", "--out", f"{o}.csv"], "fifo"),
        (["curve", f"{d}/deep.json", "--out", f"{o}.csv"], "deep.json"),
        (["design", "--target-csv", f"{d}/fifo", "--out", o], "fifo"),
        (["train", "--dataset", f"{d}/fifo", "--out", o], "fifo"),
        (["curve", f"{d}/design.json", "--out", ""], "output"),
        ([*curve, "--plot", ""], "figure"),
        (["curve", f"{d}/design.json", "--out", f"{d}/fifo"], "fifo"),
        (["curve", f"{d}/design.json", "--out", f"{d}/link.csv"], "link.csv"),
        (["curve", f"{d}/design.json", "--out", f"{d}/afile/c.csv"], "afile"),
        (["curve", f"{d}/design.json", "--out", f"{d}/out"], "out"),
        (["curve", f"{d}/design.json", "--out", "/dev/null"], "/dev/null"),
        # export: extreme radius, sizes, formats
        ([*export[:3], "--radius", "1e300", "--out", f"{o}.stl"], "--radius"),
        ([*export[:3], "--radius", "1e-300", "--out", f"{o}.stl"], "--radius"),
        ([*export[:3], "--radius", "-1mm", "--out", f"{o}.stl"], "--radius"),
        ([*export[:3], "--radius", "5 parsecs", "--out", f"{o}.stl"], "--radius"),
        ([*export, "--tiles", "0x0"], "--tiles"),
        ([*export, "--tiles", "100000x100000"], "--tiles"),
        ([*export, "--resolution", "1e9"], "--resolution"),
        ([*export, "--resolution", "nan"], "--resolution"),
        ([*export, "--base", "-1mm"], "--base"),
        (["export", f"{d}/absurd_h.json", "--radius", "1mm", "--out", f"{o}.stl"], "h[3]"),
        (["export", f"{d}/design.json", "--radius", "1mm", "--out", f"{o}.xyz"], "xyz"),
        (["export", f"{d}/design.json", "--radius", "1mm", "--out", f"{d}/fifo"], "fifo"),
        # generate: sizes, overflow, cells that underflow
        ([*gen[:1], "--samples", "0", *gen[3:]], "--samples"),
        ([*gen[:1], "--samples", "100000000000", *gen[3:]], "--samples"),
        ([*gen[:1], "--samples", "1e3", *gen[3:]], "--samples"),
        ([*gen[:3], "--seed", "-1", *gen[5:]], "--seed"),
        ([*gen[:3], "--seed", BIG, *gen[5:]], "--seed"),
        ([*gen, "--delta-max", "1e-300"], "--delta-max"),
        ([*gen, "--n-asperities", "3"], "--n-asperities"),
        ([*gen, "--gamma-min", "5"], "gamma"),
        ([*gen, "--chunk", "0"], "--chunk"),
        ([*gen, "--plot", f"{o}.bogus"], "--plot"),
        ([*gen, "--plot", ""], "--plot"),
        ([*gen[:5], "--out", "", "--quiet"], "output"),
        ([*gen[:5], "--out", f"{d}/out", "--quiet"], "out"),
        ([*gen[:5], "--out", f"{d}/afile/x.npz", "--quiet"], "afile"),
        # train: datasets, options, resume
        (["train", "--dataset", f"{d}/bad.npz", "--out", o], "bad.npz"),
        (["train", "--dataset", f"{d}/nan.npz", "--out", o], "alpha_hat"),
        (["train", "--dataset", f"{d}/missing.npz", "--out", o], "missing.npz"),
        ([*train, "--epochs", "0"], "--epochs"),
        ([*train, "--epochs", BIG], "--epochs"),
        ([*train, "--lr", "nan"], "--lr"),
        ([*train, "--lr", "-1"], "--lr"),
        ([*train, "--seed", "-1"], "--seed"),
        ([*train, "--curriculum-epochs", "-1"], "--curriculum-epochs"),
        ([*train, "--batch-size", "1"], "--batch-size"),
        ([*train, "--max-gap", "0"], "--max-gap"),
        ([*train, "--w-shape", "0", "--w-grad", "0", "--w-mag", "0", "--w-curve", "0"], "w_"),
        ([*train, "--w-mag", "-1"], "--w-mag"),
        ([*train, "--resume"], "--resume"),
        ([*train[:3], "--out", f"{d}/afile", "--batch-size", "8"], "afile"),
        ([*train[:3], "--out", "", "--batch-size", "8"], "--out"),
        # evaluate: datasets and models
        (["evaluate", "--dataset", f"{d}/bad.npz"], "bad.npz"),
        (["evaluate", "--dataset", f"{d}/small.npz", "--out", ""], "output"),
        (["evaluate", "--dataset", f"{d}/nan.npz"], "alpha_hat"),
        (["evaluate", "--dataset", f"{d}/tiny.npz"], "test split"),
        (["evaluate", "--dataset", f"{d}/small.npz", "--model", f"{d}/evil.pt"], "evil.pt"),
        (["evaluate", "--dataset", f"{d}/small.npz", "--out", f"{d}/fifo"], "fifo"),
        # validate: sizes, tolerance, targets
        ([*val, "--grid", "7"], "--grid"),
        ([*val[:2], "--grid", "99999", *val[4:]], "--grid"),
        ([*val, "--tolerance", "10"], "--tolerance"),
        ([*val, "--loads", "0"], "--loads"),
        ([*val, "--jobs", "0"], "--jobs"),
        (
            ["validate", f"{d}/nantarget.json", "--grid", "16", "--loads", "2", "--out", o],
            "target.alpha",
        ),
        (["validate", f"{d}/design.json", "--grid", "16", "--out", f"{d}/afile"], "afile"),
        # reproduce: special folders
        (["reproduce", "--out", f"{d}/afile", "--quick"], "afile"),
        (["reproduce", "--out", o, "--work", f"{d}/afile/w", "--quick"], "afile"),
        (["reproduce", "--out", "", "--quick"], "output"),
    ]


def _ids() -> list[str]:
    return [" ".join(a[:1] + [x.rsplit("/", 1)[-1] for x in a[1:]])[:60] for a, _ in cases("D")]


@pytest.mark.parametrize("index", range(len(cases("D"))), ids=_ids())
def test_refused_in_one_line(index, inputs, capsys):
    argv, field = cases(str(inputs))[index]
    assert_refused(argv, field, inputs, capsys)


# --- property-based: any value outside an option's range ---------------------------------

#: (command line before the option, option, smallest and largest valid integer)
INT_OPTIONS = [
    (["curve", "{d}/design.json", "--out", "{d}/out/c.csv"], "--steps", 2, 1_000_000),
    (["design", "--target", "linear", "--out", "{d}/out/x"], "--starts", 1, 10_000),
    (["design", "--target", "linear", "--out", "{d}/out/x"], "--hedge", 0, 10_000),
    (["design", "--target", "linear", "--out", "{d}/out/x"], "--seed", 0, 2**63 - 1),
    (["generate", "--seed", "0", "--out", "{d}/out/g.npz"], "--samples", 1, 10_000_000),
    (["generate", "--samples", "5", "--out", "{d}/out/g.npz"], "--seed", 0, 2**63 - 1),
    (["train", "--dataset", "{d}/small.npz", "--out", "{d}/out/t"], "--epochs", 1, 10**6),
    (["validate", "{d}/design.json", "--out", "{d}/out/v"], "--loads", 1, 10_000),
]


def bad_integers(low: int, high: int) -> st.SearchStrategy[str]:
    """Text that is not a whole number in [low, high]: out of range, huge, fractional,
    non-finite, garbage."""
    numbers = st.one_of(
        st.integers(max_value=low - 1),
        st.integers(min_value=high + 1),
        st.integers(min_value=2**63, max_value=2**200),
    ).map(str)
    floats = st.floats(allow_nan=True, allow_infinity=True).filter(
        lambda x: not (x == x and x == int(x) if abs(x) < 1e300 else False)
    )
    words = st.text(min_size=1, max_size=12).filter(lambda s: not _is_int_in(s, low, high))
    return st.one_of(numbers, floats.map(repr), words, st.sampled_from(["1e3", "2**70", "0x10"]))


def _is_int_in(text: str, low: int, high: int) -> bool:
    try:
        return low <= int(text) <= high
    except ValueError:
        return False


def _int_property(inputs, capsys, case: int, value: str) -> None:
    before, option, _, _ = INT_OPTIONS[case]
    argv = [a.format(d=inputs) for a in before] + [f"{option}={value}"]
    if "\0" in value:  # the OS cannot pass a NUL in an argument; argparse in process can
        return
    assert_refused(argv, option, inputs, capsys)


@given(data=st.data())
def test_out_of_range_integers_are_refused(inputs, capsys, data):
    case = data.draw(st.integers(0, len(INT_OPTIONS) - 1), label="option")
    _, _, low, high = INT_OPTIONS[case]
    _int_property(inputs, capsys, case, data.draw(bad_integers(low, high), label="value"))


@pytest.mark.slow
@settings(max_examples=SLOW_EXAMPLES)
@given(data=st.data())
def test_out_of_range_integers_are_refused_many(inputs, capsys, data):
    case = data.draw(st.integers(0, len(INT_OPTIONS) - 1), label="option")
    _, _, low, high = INT_OPTIONS[case]
    _int_property(inputs, capsys, case, data.draw(bad_integers(low, high), label="value"))


#: Options that take a positive quantity with a unit (or a number in SI).
QUANTITIES = [
    (["export", "{d}/design.json", "--out", "{d}/out/p.stl"], "--radius"),
    (["export", "{d}/design.json", "--radius", "1mm", "--out", "{d}/out/p.stl"], "--base"),
    (["validate", "{d}/design.json", "--grid", "16", "--out", "{d}/out/v"], "--tolerance"),
]


@given(
    case=st.integers(0, len(QUANTITIES) - 1),
    value=st.one_of(
        st.floats(max_value=0.0).map(repr),
        st.sampled_from(["nan", "inf", "-inf", "1e400", "", "mm", "3 kg", "1e300", "1e-300m"]),
        st.text(alphabet="0123456789.e-+ abcxyz", max_size=8),
    ),
)
@example(case=0, value="0a90")  # years^90: pint's conversion overflowed, a traceback
def test_bad_quantities_are_refused(inputs, capsys, case, value):
    assume(not _valid_quantity(case, value))
    before, option = QUANTITIES[case]
    argv = [a.format(d=inputs) for a in before] + [f"{option}={value}"]
    assert_refused(argv, option, inputs, capsys)


def _valid_quantity(case: int, text: str) -> bool:
    """Whether ``text`` is a valid value of QUANTITIES[case] (pint evaluates '0+1' too)."""
    try:
        if case == 2:
            return 0 < float(text) <= 1e-6
        low, high = ((1e-9, 10.0), (1e-6, 1.0))[case]
        return low <= parse_length(text, option="x") <= high
    except (ValueError, mi.MetainterfaceError):
        return False
