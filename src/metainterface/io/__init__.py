"""File formats: the surface for manufacture (STL meshes and height maps: PNG, TIFF, NPY) and
the BEM fields (NetCDF4/HDF5 via xarray, the ``fields`` extra).

Design files (design-v1 JSON) are read and written by :class:`~metainterface.Design` itself
(``Design.load`` / ``Design.save``); CSV columns and atomic writes are ``metainterface._files``.
"""

from metainterface.io.export import FORMATS, export_design, format_for, sidecar_path
from metainterface.io.fields import (
    FIELDS_FILE,
    fields_dataset,
    open_fields,
    require_xarray,
    write_fields,
)
from metainterface.io.patch import Patch, height_patch, parse_tiles
from metainterface.io.stl import patch_mesh

__all__ = [
    "FIELDS_FILE",
    "FORMATS",
    "Patch",
    "export_design",
    "fields_dataset",
    "format_for",
    "height_patch",
    "open_fields",
    "parse_tiles",
    "patch_mesh",
    "require_xarray",
    "sidecar_path",
    "write_fields",
]
