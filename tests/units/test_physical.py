"""The physical block: the design in SI (paper sec. 2.3)."""

from pathlib import Path

import numpy as np
import pytest

import metainterface
from metainterface.errors import MetainterfaceError
from metainterface.physics import Design
from metainterface.physics.curves import design_sweep
from metainterface.units.dimensions import physical_block

EXAMPLE = Path(metainterface.__file__).parent / "examples" / "example_design.json"
R, E = 0.5e-3, 2e6


def test_dimensions_follow_section_2_3():
    design = Design.load(EXAMPLE)
    s = design.settings
    p_star_max = float(design_sweep(design).p_star[0, -1])
    blk = physical_block(design, radius=R, e_star=E, total_force=50.0)
    assert blk["pressure_max_pa"] == pytest.approx(p_star_max * E)
    assert blk["cell_side_m"] == pytest.approx(s.cell_side * R)
    assert blk["a_max_m"] == pytest.approx(s.a_max * R)
    assert blk["delta_max_m"] == pytest.approx(s.delta_max * R)
    np.testing.assert_allclose(blk["height_offsets_m"], (design.h - design.h.min()) * R)
    # F_total = P N_cells L^2
    assert blk["n_cells"] * blk["pressure_max_pa"] * blk["cell_side_m"] ** 2 == pytest.approx(50.0)
    assert blk["tiles_per_side"] ** 2 >= blk["n_cells"]
    by_area = physical_block(design, radius=R, e_star=E, area=4e-4)
    assert by_area["n_cells"] == pytest.approx(4e-4 / blk["cell_side_m"] ** 2)
    assert by_area["force_at_pressure_max_n"] == pytest.approx(blk["pressure_max_pa"] * 4e-4)


def test_bad_physical_input():
    design = Design.load(EXAMPLE)
    with pytest.raises(MetainterfaceError, match="radius must be"):
        physical_block(design, radius=0.0, e_star=E)
    with pytest.raises(MetainterfaceError, match="not both"):
        physical_block(design, radius=R, e_star=E, total_force=1.0, area=1.0)
