"""`metainterface export`: a design's surface as a height map (PNG/TIFF/NPY) or an STL."""

from __future__ import annotations

import argparse

from metainterface._names import EXPORT_FORMATS


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export",
        help="height map (16-bit PNG/TIFF, NPY in m) or watertight STL (mm) of a tiled patch",
        description="Scale a design by the asperity radius R and write one cell or a tiled "
        "patch: a height map (16-bit PNG/TIFF with the height scale in OUT.json, NPY in "
        "metres) or a binary STL in millimetres on a base plate. Quantities take units "
        "(0.5mm, 500um); a plain number is in metres.",
    )
    p.add_argument("design", help="design file (metainterface/design-v1 JSON)")
    p.add_argument(
        "--radius",
        help="asperity radius R, e.g. 0.5mm (default: the one design.json records, as a "
        "friction law's or a sized design's does)",
    )
    p.add_argument(
        "--tiles",
        default="1x1",
        help="cells along x and y, e.g. 4x4 (default 1x1); auto: the tiling design.json "
        "records for the area designed for (e.g. by design --area auto)",
    )
    p.add_argument(
        "--format",
        choices=EXPORT_FORMATS,
        help="output format (default: from the --out suffix)",
    )
    p.add_argument("--out", required=True, help="output file; a sidecar OUT.json is written too")
    p.add_argument(
        "--resolution",
        metavar="PX_PER_MM",
        help="grid points per millimetre (default: 64 per asperity pitch)",
    )
    p.add_argument(
        "--base", default="1mm", help="STL base plate thickness under the surface (default 1mm)"
    )
    p.add_argument(
        "--z-step",
        metavar="LENGTH",
        help="printer layer height, e.g. 1um: the asperities' heights snapped to its multiples",
    )
    p.add_argument(
        "--flank-step",
        type=int,
        default=4,
        metavar="K",
        help="STL: mesh the flanks between the asperities' contact zones on every K-th grid "
        "line (default 4; 1 = every line)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="write a file over 100 MB (without it the export states the size and how to "
        "make it smaller, and writes nothing)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import sys

    import metainterface as mi
    from metainterface.units import parse_length

    resolution = None
    if args.resolution is not None:
        try:
            resolution = float(args.resolution)
        except ValueError:
            resolution = float("nan")
        if not (resolution > 0 and resolution < float("inf")):
            raise mi.MetainterfaceError(
                f"--resolution expects grid points per mm > 0, got {args.resolution!r}"
            )
    # lengths parsed here so that errors name the options as typed
    rec = mi.export(
        args.design,
        args.out,
        radius=None if args.radius is None else parse_length(args.radius, option="--radius"),
        tiles=args.tiles,
        format=args.format,
        resolution=resolution,
        base=parse_length(args.base, option="--base"),
        z_step=args.z_step,  # checked against the design's Delta_max by export
        flank_step=args.flank_step,
        force=args.force,
    )
    for note in rec.get("notes", ()):
        print(f"warning: {note}", file=sys.stderr)
    nx, ny = rec["tiles"]
    size = f"{rec['size_m'][0] * 1e3:.4g} x {rec['size_m'][1] * 1e3:.4g} mm"
    detail = f"{rec['grid_per_cell']} points per cell side ({rec['points_per_mm']:.4g}/mm)"
    if rec["format"] == "stl":
        ex = rec["extents_mm"]
        size = f"{ex[0]:.4g} x {ex[1]:.4g} x {ex[2]:.4g} mm"
        detail += f", {rec['triangles']} triangles, watertight"
    if "z_step" in rec:
        z = rec["z_step"]
        detail += (
            f", heights on a {z['z_step_m'] * 1e6:.3g} um grid "
            f"(largest shift {z['largest_shift_m'] * 1e6:.3g} um)"
        )
    print(f"{args.out}: {rec['format']} of {nx}x{ny} cells, {size}, {detail}")
    print(f"one cell: {rec['one_cell']}")
    return 0
