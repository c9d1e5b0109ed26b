"""BEM fields on disk: pressure, gap and contact mask at every load, as one NetCDF4/HDF5 file.

The file is an xarray Dataset (written with the h5netcdf engine, the ``fields`` extra):

    dims     load (K), y (M), x (M)
    coords   x, y: grid point positions; load: 0..K-1; p_star (load): P* = P / E*;
             alpha_bem (load): the BEM's contact area fraction
    data     pressure (load, y, x)  p / E*
             gap      (load, y, x)  gap between the surfaces (0 in contact)
             contact  (load, y, x)  1 where p > 0 (uint8)
             height   (y, x)        the cell's surface, tips up, highest tip at 0

Lengths are in units of R, or in metres when the design carries a ``physical`` block with
its radius (``mi.physical``); every variable has a ``units`` attribute. Array row i is the
line y = i * spacing, as in the height map. Open it with ``xarray.open_dataset(path)``.
"""

from __future__ import annotations

import os
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from metainterface._files import strict_json
from metainterface._files.atomic import atomic_path
from metainterface._files.provenance import provenance
from metainterface.errors import MetainterfaceError

if TYPE_CHECKING:
    from metainterface.validation.result import ValidationResult

FIELDS_HINT = "pip install 'metainterface[fields]'"
FIELDS_FILE = "fields.nc"


def require_xarray() -> ModuleType:
    """Import xarray (and check h5netcdf), or raise a one-line error with the install command."""
    try:
        import h5netcdf  # noqa: F401  (the engine xarray writes with)
        import xarray
    except ImportError:
        raise MetainterfaceError(
            f"BEM fields need xarray and h5netcdf, which are not installed: run `{FIELDS_HINT}`"
        ) from None
    return xarray


def length_scale(result: ValidationResult) -> tuple[float, str]:
    """(factor, units): lengths in the result times factor are in ``units`` (m or R)."""
    physical = result.design.extras.get("physical")
    radius = result.design.settings.radius
    if isinstance(physical, dict) and isinstance(physical.get("radius_m"), int | float):
        return float(physical["radius_m"]) / radius, "m"
    return 1.0 / radius, "R"


def fields_dataset(result: ValidationResult, **settings: Any) -> Any:
    """The result's fields as an ``xarray.Dataset`` (see the module docstring).

    Raises MetainterfaceError if the result was solved without ``fields=True``.
    """
    xr = require_xarray()
    if result.pressures is None or result.gaps is None:
        raise MetainterfaceError("fields: this result was solved without fields=True")
    scale, units = length_scale(result)
    hm = result.heights
    coord = np.arange(hm.grid) * hm.spacing * scale
    dims = ("load", "y", "x")
    ds = xr.Dataset(
        {
            "pressure": (
                dims,
                result.pressures,
                {"units": "1", "long_name": "contact pressure p / E*"},
            ),
            "gap": (
                dims,
                result.gaps * scale,
                {"units": units, "long_name": "gap between the surfaces (0 in contact)"},
            ),
            "contact": (
                dims,
                (result.pressures > 0).astype(np.uint8),
                {"units": "1", "long_name": "contact mask (1 where p > 0)"},
            ),
            "height": (
                ("y", "x"),
                hm.heights * scale,
                {"units": units, "long_name": "surface height, tips up, highest tip at 0"},
            ),
        },
        coords={
            "x": ("x", coord, {"units": units, "long_name": "x"}),
            "y": ("y", coord, {"units": units, "long_name": "y"}),
            "load": ("load", np.arange(len(result.p_star)), {"long_name": "load index"}),
            "p_star": ("load", result.p_star, {"units": "1", "long_name": "P* = P / E*"}),
            "alpha_bem": (
                "load",
                result.alpha_bem,
                {"units": "1", "long_name": "contact area fraction (BEM)"},
            ),
        },
        attrs={
            "title": f"BEM fields of {result.name}",
            "design": result.name,
            "grid": result.grid,
            "length_units": units,
            "provenance": strict_json.dumps(provenance(**settings), default=str),
        },
    )
    return ds


def write_fields(result: ValidationResult, path: str | os.PathLike[str], **settings: Any) -> Path:
    """Write the result's fields to ``path`` (NetCDF4/HDF5), atomically; compressed."""
    ds = fields_dataset(result, **settings)
    encoding = {name: {"zlib": True, "complevel": 4} for name in ds.data_vars}
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf", encoding=encoding)
    return Path(path)


def open_fields(path: str | os.PathLike[str]) -> Any:
    """The fields file at ``path`` as an ``xarray.Dataset`` (loaded into memory)."""
    xr = require_xarray()
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()
