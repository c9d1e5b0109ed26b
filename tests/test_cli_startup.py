"""The command line answers at once: no torch, scipy.stats or plotting before the work starts."""

import os
import subprocess
import sys

import pytest

import metainterface as mi

HEAVY = ("torch", "scipy.stats", "matplotlib", "pint")


def _imported_after(code: str) -> set[str]:
    """Heavy modules imported by ``code`` in a fresh interpreter."""
    probe = (
        f"import sys\n{code}\nprint('HEAVY:' + ','.join(m for m in {HEAVY!r} if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True
    ).stdout
    line = out.rpartition("HEAVY:")[2].strip()
    return set(filter(None, line.split(",")))


def test_import_metainterface_is_light():
    assert _imported_after("import metainterface") == set()


@pytest.mark.parametrize(
    "argv",
    [
        ["--help"],
        ["design", "--help"],
        ["validate", "--help"],
        ["export", "--help"],
        ["design", "--target", "bilinear", "--bogus", "1"],
        ["design", "--physics", "nonsense", "--out", "x"],
    ],
)
def test_help_and_argument_errors_need_no_heavy_import(argv):
    code = (
        "from metainterface.cli import main\n"
        "try:\n"
        f"    main({argv!r})\n"
        "except SystemExit:\n"
        "    pass"
    )
    assert _imported_after(code) == set()


def test_cli_choices_agree_with_the_registries():
    from metainterface._names import DEFAULT_MODEL, EXPORT_FORMATS, METHOD_NAMES, MODEL_NAMES
    from metainterface.inverse.pipeline import METHODS
    from metainterface.io.export import FORMATS

    assert tuple(mi.MODELS)[: len(MODEL_NAMES)] == MODEL_NAMES
    assert DEFAULT_MODEL in MODEL_NAMES
    assert tuple(METHODS) == METHOD_NAMES
    assert tuple(FORMATS) == EXPORT_FORMATS


def test_every_public_name_is_listed_and_resolves():
    assert set(mi.__all__) <= set(dir(mi))
    for name in mi.__all__:
        assert getattr(mi, name) is not None
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        mi.nonsense  # noqa: B018


def test_a_subpackage_never_hides_a_public_function():
    code = (
        "import metainterface as mi, metainterface.units.quantities\n"
        "mi.design\n"
        "print(callable(mi.physical) and not isinstance(mi.physical, type(mi)))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"


def test_the_console_script_exits_with_its_status_and_all_its_output(tmp_path):
    """``python -m metainterface`` ends without Python's slow teardown (``cli.run``): its exit
    status, its printed line and its file are those of ``main``, and a pipe closed by the
    reader (``| head -c 5``) is no error."""
    from importlib.resources import files

    example = str(files("metainterface") / "examples" / "example_design.json")
    out = tmp_path / "curve.csv"
    run = [sys.executable, "-m", "metainterface", "curve", example, "--out", str(out)]
    done = subprocess.run([*run, "--steps", "50"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    rows = [r for r in out.read_text().splitlines() if r[:1].isdigit()]
    assert len(rows) == 50 and done.stdout.startswith(f"{out}: 50 points")
    bad = subprocess.run([*run, "--steps", "0"], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1
    piped = subprocess.run(
        f"{' '.join(run)} --steps 50 | head -c 5", shell=True, capture_output=True, text=True
    )
    assert piped.returncode == 0 and piped.stdout == str(out)[:5] and piped.stderr == ""
    # a reader gone before anything is printed: no traceback, the file written, status 0
    out.unlink()
    gone = subprocess.run(
        ["bash", "-c", f"{' '.join(run)} --steps 50 | true; exit ${{PIPESTATUS[0]}}"],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert gone.returncode == 0 and gone.stderr == "" and out.exists()
