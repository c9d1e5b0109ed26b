"""`metainterface evaluate`: zero-shot quality of a surrogate on a dataset's test split."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "evaluate",
        help="per-category zero-shot errors of a surrogate on the test split",
        description="Median and 90th-percentile relative curve error per category, log10 "
        "errors of P*_max and alpha_max, and the train/test loss gap. A friction-law network "
        "(`train --laws`) is evaluated on friction-law-like targets made from the test "
        "cells, per kind (cut, warped, shaped).",
    )
    p.add_argument("--model", help="model file (default: the shipped surrogate)")
    p.add_argument("--dataset", required=True, help="dataset .npz from `metainterface generate`")
    p.add_argument("--plot", help="figure of true vs predicted curves per category (fig. 3)")
    p.add_argument("--out", help="also write the table as JSON here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:

    import metainterface as mi
    from metainterface._files import provenance, strict_json, write_text
    from metainterface.surrogate.checkpoint import default_model_path
    from metainterface.surrogate.evaluate import format_table

    model_path = args.model or default_model_path()
    result = mi.evaluate_surrogate(args.dataset, model_path)
    print(format_table(result))
    if args.out is not None:
        record = {
            **result,
            "model": str(model_path),
            "dataset": args.dataset,
            "provenance": provenance(command="evaluate"),
        }
        write_text(args.out, strict_json.dumps(record, indent=2) + "\n")
    if args.plot is not None and result["reads"] == "laws":
        from metainterface.errors import MetainterfaceError

        raise MetainterfaceError(
            "--plot draws the test split's exact curves; a friction-law network reads other "
            "targets (`design --friction-csv LAW --out DIR` draws its fit in DIR/design.png)"
        )
    if args.plot is not None:
        from metainterface.data import load_dataset
        from metainterface.plots import plot_reconstructions, save_figure
        from metainterface.surrogate.checkpoint import load_model
        from metainterface.surrogate.data import split_of
        from metainterface.surrogate.evaluate import predict_split

        model, settings, _ = load_model(model_path)
        ds = load_dataset(args.dataset, settings)
        pred = predict_split(model, split_of(ds, "test"), settings)
        save_figure(
            plot_reconstructions(ds.subset("test"), pred, settings),
            args.plot,
            command="evaluate",
            model=str(model_path),
        )
    return 0
