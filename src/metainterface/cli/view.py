"""`metainterface view`: an interactive HTML page of a design, one file that opens offline."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "view",
        help="interactive HTML page of a design: curves with hover, the cell in 3D, its files",
        description="Write one self-contained HTML file (plotly.js and the design's files "
        "embedded) that opens in a browser from disk, without a server: alpha(P*) and "
        "S*(P*) against the target, the friction law in newtons when the target came from "
        "one, the unit cell as a 3D surface, and the folder's files to download. Needs the "
        "[view] extra (plotly).",
    )
    p.add_argument("design", metavar="DIR", help="design folder (design --out) or design file")
    p.add_argument("--out", help="the page to write (default DIR/view.html)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import metainterface as mi

    path = mi.view(args.design, args.out)
    print(f"{path}: open it in a browser ({path.stat().st_size / 1e6:.2g} MB, self-contained)")
    return 0
