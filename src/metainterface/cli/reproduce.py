"""`metainterface reproduce`: every figure and table of the paper from one command."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "reproduce",
        help="regenerate the paper's figures and tables (PNG, PDF, captions, results.md)",
        description="Regenerate the paper's results from the package alone (shipped surrogate, "
        "data generated with fixed seeds): fig. 1 and table 1, fig. 3 and the wall case, "
        "fig. 4, fig. 5, fig. 6 and appendix D, as NAME.png, NAME.pdf and a caption NAME.txt "
        "each, plus results.md (every number beside the paper's value) and results.json. "
        "The full run takes about half an hour on 2 cores; --quick a few minutes.",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument(
        "--quick",
        action="store_true",
        help="reduced scale: BEM grid 384 and 8 loads, 250 test curves per category, "
        "20 training epochs, 10 random starts",
    )
    p.add_argument(
        "--only",
        nargs="+",
        metavar="STAGE",
        help="run only these stages (fig1 fig3 fig4 fig5 fig6) and what they need",
    )
    p.add_argument("--model", help="surrogate model file (default: the shipped one)")
    p.add_argument(
        "--work",
        metavar="DIR",
        help="keep intermediate data (datasets, the fig. 4 training run) here and reuse it "
        "on a rerun (default: a temporary folder)",
    )
    p.add_argument("--scale", choices=("full", "quick", "tiny"), help=argparse.SUPPRESS)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from metainterface.reproduce import reproduce

    reproduce(
        args.out,
        quick=args.quick,
        scale=args.scale,
        only=args.only,
        model_path=args.model,
        work_dir=args.work,
    )
    return 0
