"""The held-back PDMS friction law the adhesive benchmarks design: a held-back adhesive
cell's loading curve (``metainterface._testing.adhesive_cell_curve``, 24 rows from zero
load) as a friction law over 4 cm^2 (tau 0.3 MPa, E* 2.4 MPa, R 0.5 mm, w 50 mJ/m^2),
written as the CSV a user would hand in (newtons)."""

from __future__ import annotations

from pathlib import Path

from metainterface._testing import adhesive_cell_curve

#: E* [Pa], R [m], w [J/m^2], tau [Pa], the law's area [m^2].
E, R, W_J, TAU, AREA = 2.4e6, 0.5e-3, 0.05, 0.3e6, 4e-4


def write_law(path: Path, seed: int = 11, rows: int = 24) -> Path:
    """The law of the held-back cell of ``seed`` (``rows`` rows) written to ``path``."""
    p, a = adhesive_cell_curve(W_J / (E * R), seed=seed, rows=rows)
    lines = (f"{x:.12g},{y:.12g}\n" for x, y in zip(p * AREA * E, a * TAU * AREA, strict=True))
    path.write_text("normal_force,friction_force\n" + "".join(lines))
    return path
