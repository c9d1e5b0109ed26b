"""File formats for making the surface: STL meshes and height maps (PNG, TIFF, NPY).

Design files (design-v1 JSON) are read and written by :class:`~metainterface.Design` itself
(``Design.load`` / ``Design.save``); CSV columns and atomic writes are ``metainterface._files``.
"""

from metainterface.io.export import (
    FORMATS,
    Patch,
    export_design,
    format_for,
    height_patch,
    parse_tiles,
    patch_mesh,
    sidecar_path,
)

__all__ = [
    "FORMATS",
    "Patch",
    "export_design",
    "format_for",
    "height_patch",
    "parse_tiles",
    "patch_mesh",
    "sidecar_path",
]
