"""Shared inputs of the robustness suite: good and hostile files, and how a case is judged.

Hypothesis runs a few examples per property by default (profile ``ci``, no deadline: the
machine is shared); ``HYPOTHESIS_PROFILE=thorough`` runs many more, and the tests marked
``slow`` run the same properties with more examples.
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest
import torch
from hypothesis import HealthCheck, settings

import metainterface as mi

settings.register_profile(
    "ci",
    max_examples=12,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.register_profile(
    "thorough",
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

GOOD = {"gamma": [2.0, 2.5, 3.0, 3.5], "h": [0.0, 0.002, 0.004, 0.008]}


@pytest.fixture(scope="session")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder of inputs, good and hostile. Tests write only below ``out/`` in it, and a
    refused case must leave the whole folder as it was."""
    d = tmp_path_factory.mktemp("inputs")
    good = mi.Design(gamma=GOOD["gamma"], h=GOOD["h"])
    good.save(d / "design.json")
    data = json.loads((d / "design.json").read_text())

    def variant(name: str, **changes: object) -> None:
        (d / name).write_text(json.dumps({**data, **changes}), encoding="utf-8")

    variant("strnum.json", gamma=[str(g) for g in GOOD["gamma"]])
    variant("nantarget.json", target={"p_star": [0.0, 1e-4, 2e-4], "alpha": [0, float("nan"), 1]})
    variant("absurd_h.json", h=[0.0, 0.0, 0.0, 1e300])
    variant("bool.json", gamma=[True, 2.0, 2.0, 2.0])
    variant("nested.json", h=[[0.0], [0.0], [0.0], [0.0]])
    variant("radius.json", radius="1")
    (d / "bom.json").write_bytes(b"\xef\xbb\xbf" + (d / "design.json").read_bytes())
    (d / "deep.json").write_text("[" * 100_000, encoding="utf-8")
    (d / "notjson.json").write_text("{gamma: [2, 2", encoding="utf-8")
    rows = "0,0\n0.0005,0.01\n0.001,0.02\n"
    (d / "plain.csv").write_text("p_star,alpha\n" + rows)
    (d / "bom.csv").write_bytes(b"\xef\xbb\xbf" + b"p_star,alpha\n" + rows.encode())
    (d / "crlf.csv").write_bytes(("p_star,alpha\n" + rows).replace("\n", "\r\n").encode())
    (d / "latin.csv").write_bytes(
        "# mesuré à 20 °C\np_star,alpha\n".encode("latin-1") + rows.encode()
    )
    (d / "alpha_gt1.csv").write_text("p_star,alpha\n0,0\n0.001,0.5\n0.002,1.5\n")
    (d / "decreasing.csv").write_text("p_star,alpha\n0,0\n0.002,0.01\n0.001,0.02\n")
    (d / "nan.csv").write_text("p_star,alpha\n0,0\n0.001,nan\n0.002,0.02\n")
    (d / "binary.csv").write_bytes(b"p_star,alpha\n\x00\x01\x02")
    (d / "both.csv").write_text(
        "normal_force,friction_force,friction_coefficient\n0,0,0\n1,0.1,0.1\n2,0.2,0.1\n"
    )
    (d / "bad.npz").write_text("not a dataset")
    mi.generate_dataset(60, d / "small.npz", seed=0, progress=False)
    mi.generate_dataset(6, d / "tiny.npz", seed=0, progress=False)  # empty test split
    with np.load(d / "small.npz") as npz:
        arrays = dict(npz)
    arrays["alpha_hat"][3, 5] = np.nan
    np.savez(d / "nan.npz", **arrays)

    class Evil:
        def __reduce__(self):
            return (print, ("this must never run",))

    torch.save({"format": "x", "payload": Evil()}, d / "evil.pt")
    (d / "junk.pt").write_bytes(b"\x80\x02junk")
    (d / "afile").write_text("a regular file\n")
    (d / "link.csv").symlink_to(d / "afile")
    os.mkfifo(d / "fifo")
    assert stat.S_ISFIFO(os.lstat(d / "fifo").st_mode)
    (d / "out").mkdir()
    return d
