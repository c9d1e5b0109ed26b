"""`metainterface validate`: designs against the boundary element method.

One design file: its results in DIR (``mi.validate``). Several files or a folder: a sweep,
DIR/<name>/ per design and DIR/summary.csv (``mi.validate_many``), on local processes or a
Dask cluster (``--scheduler``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from metainterface._names import DEFAULT_ENGINE, DEFAULT_MODEL, ENGINE_NAMES, MODEL_NAMES
from metainterface.cli.common import add_device, positive_float, positive_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "validate",
        help="compare a design's alpha(P*) with a BEM solution",
        description="Solve the normal contact of the design's periodic cell by the boundary "
        "element method (Polonsky-Keer-Rey, tolerance 1e-11, E* = 1; --engine torch, the "
        "default, or tamaas, the [bem] extra) at K ascending mean pressures up to "
        "the load reached at Delta_max, and compare the contact-area fraction with the "
        "forward model. The BEM's contact edges are placed to sub-pixel accuracy from the "
        "pressure field (p^2 is linear near a smooth edge); the plain count of grid points "
        "in contact is kept as alpha_bem_pixels. Writes DIR/bem.csv "
        "(p_star,alpha_bem,alpha_model,rel_err,p_max,alpha_bem_pixels), "
        "DIR/asperities.csv, DIR/validation.png, DIR/result.json and DIR/models.csv (alpha "
        "and rel_err of both forward models at the same loads). With several design files "
        "or a folder of them: a sweep that writes DIR/<name>/ per design as each finishes "
        "and DIR/summary.csv (name, status, largest relative error over the upper half of "
        "the loads, target errors), and resumes where it stopped when run again with the "
        "same settings; exit status 1 if a design failed.",
    )
    p.add_argument(
        "designs",
        nargs="+",
        metavar="DESIGN",
        help="design file(s) (metainterface/design-v1 JSON), or a folder of them",
    )
    p.add_argument(
        "--grid",
        type=positive_int,
        metavar="M",
        help="grid points per side, a multiple of n (default 256 n: 768 for N = 9; sizes "
        "with small prime factors, e.g. 192, 384, 768, keep the FFTs fast)",
    )
    p.add_argument(
        "--loads",
        type=positive_int,
        default=20,
        metavar="K",
        help="number of loads, uniform on (0, P_max] (default 20)",
    )
    p.add_argument(
        "--p-max",
        type=positive_float,
        metavar="P",
        help="largest load P* (default: P* at Delta_max; must not exceed it)",
    )
    p.add_argument(
        "--workers",
        "--jobs",
        dest="workers",
        type=positive_int,
        metavar="N",
        help="worker processes, local or of --scheduler local (default: the available "
        "cores); one design's load path is split into N warm-started chunks",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDR",
        help="run on Dask (the [distributed] extra): tcp://HOST:PORT joins a running "
        "cluster (`dask scheduler`, dask-jobqueue), 'local' starts a LocalCluster of N "
        "workers",
    )
    p.add_argument(
        "--chunks",
        type=positive_int,
        metavar="C",
        help="sweeps: split each design's load path into C warm-started tasks (default 1)",
    )
    p.add_argument(
        "--fields",
        action="store_true",
        help="also write DIR/fields.nc: pressure, gap and contact mask at every load "
        "(NetCDF4, open with xarray.open_dataset; the [fields] extra)",
    )
    p.add_argument(
        "--no-figures",
        action="store_true",
        help="sweeps: skip validation.png for each design",
    )
    p.add_argument(
        "--tolerance",
        type=positive_float,
        default=1e-11,
        help="Polonsky-Keer-Rey tolerance (default 1e-11, the paper's; 1e-9 gives the same "
        "contact areas about 20 %% faster)",
    )
    p.add_argument(
        "--physics",
        choices=MODEL_NAMES,
        default=None,
        help="forward model that sets the loads and alpha_model: the paper's independent "
        f"asperities (default: {DEFAULT_MODEL}) or with their elastic interaction; both are "
        "reported. A design made with adhesion (its design.json's model) is, without "
        "--physics, solved in the adhesive (JKR-limit) BEM by approach and compared with "
        "its adhesive model on the rising-force branch",
    )
    p.add_argument(
        "--engine",
        choices=ENGINE_NAMES,
        default=DEFAULT_ENGINE,
        help="contact solver: torch (default; CPU threads or a GPU, no extra needed) or "
        "tamaas (the [bem] extra; the reference, one CPU thread)",
    )
    add_device(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import metainterface as mi

    if len(args.designs) > 1 or Path(args.designs[0]).is_dir():
        return run_many(args)
    result = mi.validate(
        args.designs[0],
        grid=args.grid,
        loads=args.loads,
        p_max=args.p_max,
        model=args.physics,
        tolerance=args.tolerance,
        jobs=args.workers,
        progress=True,
        out=args.out,
        fields=args.fields,
        scheduler=args.scheduler,
        engine=args.engine,
        device=args.device,
    )
    rel = {name: result.alpha_bem / a - 1.0 for name, a in result.alpha_by_model.items()}
    if result.model.adhesion:  # the adhesive BEM: against the adhesive model only
        rel = {result.model.label: result.rel_err}
        print(
            f"adhesive BEM (JKR limit) by approach: {len(result.p_star)} states on the "
            f"rising-force branch, against {result.model.label}"
        )
    k = len(result.p_star)
    print(
        f"{args.out}: {k} loads on {result.grid}x{result.grid} ({result.engine} engine), "
        f"solves {result.seconds.sum():.1f} s; max p/E* = {result.p_max.max():.4g}"
    )
    print(
        f"largest relative error over the upper half of the loads "
        f"(P* >= {result.p_star[result.upper_half][0]:.4g}): "
        f"{100 * result.max_rel_err_upper:.3g} % "
        f"(counting grid points in contact: {100 * result.max_rel_err_upper_pixels:.3g} %)"
    )
    upper = result.upper_half
    print(
        f"  by model (loads from the {result.model.label} model): "
        + ", ".join(f"{name} {100 * abs(r[upper]).max():.3g} %" for name, r in rel.items())
    )
    errors = result.target_errors()
    if errors is not None:
        print(
            f"curve error against the design's target: BEM {100 * errors[0]:.3g} %, "
            f"{result.model.label} model {100 * errors[1]:.3g} % (coverage "
            f"{100 * result.coverage:.3g} %, {result.carrying} of "
            f"{result.design.n_asperities} asperities carry load)"
        )
    return 0


def run_many(args: argparse.Namespace) -> int:
    import metainterface as mi

    if args.p_max is not None:
        raise mi.MetainterfaceError("--p-max applies to one design; sweeps use --loads")
    designs = args.designs[0] if len(args.designs) == 1 else args.designs
    summaries = mi.validate_many(
        designs,
        args.out,
        grid=args.grid,
        loads=args.loads,
        jobs=args.workers,
        model=args.physics,
        tolerance=args.tolerance,
        figures=not args.no_figures,
        fields=args.fields,
        chunks=args.chunks or 1,
        scheduler=args.scheduler,
        engine=args.engine,
        device=args.device,
    )
    failed = [name for name, s in summaries.items() if "error" in s]
    worst = max(
        (s["max_rel_err_upper_half"] for s in summaries.values() if "error" not in s),
        default=float("nan"),
    )
    print(
        f"{args.out}/summary.csv: {len(summaries) - len(failed)} designs validated, "
        f"{len(failed)} failed; largest relative error over the upper half of the loads "
        f"{100 * worst:.3g} %"
    )
    for name in failed:
        print(f"  {name}: {summaries[name]['error']}")
    return 1 if failed else 0
