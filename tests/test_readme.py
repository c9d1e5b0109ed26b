"""The README's two commands are the ones CI and users run."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    blocks = text.split("```bash\n")[1:3]
    return [b.split("\n```")[0].strip() for b in blocks]


def test_ci_runs_the_readme_test_command():
    _, test_cmd = _readme_commands()
    assert "pytest" in test_cmd
    ci = (ROOT / ".ci" / "run").read_text()
    assert test_cmd in ci
    # the long runs and the docs build (marked long and docs, out of the default run) are
    # CI's steps after it
    after = ci.split(test_cmd, 1)[1]
    assert "python -m pytest -q -m long\n" in after
    assert "python -m pytest -q -m docs" in after


def test_readme_install_takes_the_cpu_constraints():
    for cmd in _readme_commands():
        assert "-c constraints-cpu.txt" in cmd


@pytest.mark.long
def test_the_readme_python_example_runs_as_written(tmp_path, monkeypatch):
    text = (ROOT / "README.md").read_text()
    code = text.split("```python\n")[1].split("\n```")[0]
    monkeypatch.chdir(tmp_path)  # it writes bilinear.json and patch.stl where it runs
    namespace: dict = {}
    exec(compile(code, "README.md", "exec"), namespace)
    assert namespace["r"].error < 0.01
    assert namespace["v"].alpha_bem.shape == (4,)
    assert (tmp_path / "patch.stl").stat().st_size > 0
    assert (tmp_path / "patch.stl.json").is_file()
