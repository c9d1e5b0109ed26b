"""`metainterface train`: train the inverse surrogate, or plot a run's training panels."""

from __future__ import annotations

import argparse

from metainterface.cli.common import add_device, positive_int

# TrainConfig's defaults, repeated here so that `--help` needs no torch import; a test
# checks that they agree.
DEFAULTS = {
    "epochs": 500,
    "batch_size": 1024,
    "lr": 2e-3,
    "patience": 50,
    "curriculum_epochs": 20,
    "max_gap": 1.1,
    "w_shape": 10.0,
    "w_grad": 1.0,
    "w_mag": 1000.0,
    "w_curve": 300.0,
}


# TrainConfig.laws()'s, for the options --laws changes (a test checks them too).
LAWS = {
    "epochs": 60,
    "batch_size": 512,
    "lr": 5e-4,
    "curriculum_epochs": 0,
    "w_shape": 0.0,
    "w_grad": 0.0,
    "w_mag": 0.0,
    "w_curve": 100.0,
}

PAPER = {"shape": 10, "grad": 1, "mag": 10, "curve": 0}


def _default(name: str, fmt: str = "{}") -> str:
    """'default X' for an option, with the --laws value where that differs."""
    text = "default " + fmt.format(DEFAULTS[name])
    if name in LAWS:
        text += ", with --laws " + fmt.format(LAWS[name])
    return text


def gap_scale(text: str) -> float | None:
    """--max-gap: a number in (0, 10] (units of Delta_max) or 'paper'."""
    if text == "paper":
        return None
    # the model's own check, imported here (not at start-up) to keep `--help` free of torch
    from metainterface.errors import MetainterfaceError
    from metainterface.surrogate.model import check_max_gap

    try:
        return check_max_gap(float(text))
    except (ValueError, MetainterfaceError):
        raise argparse.ArgumentTypeError(
            f"expected a number in (0, 10] (units of Delta_max) or 'paper', got {text!r}"
        ) from None


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "train",
        help="train the inverse surrogate through the physics layer (or --plot a run)",
        description="Train the MLP of the paper on a dataset from `metainterface generate`. "
        "The run folder gets checkpoint.pt (resumable), model.pt (best), metrics.csv.",
    )
    p.add_argument("--dataset", help="dataset .npz from `metainterface generate`")
    p.add_argument("--out", help="run folder")
    p.add_argument("--epochs", type=positive_int, help=_default("epochs"))
    p.add_argument(
        "--batch-size",
        type=positive_int,
        help="goes with --lr: 1024 with 2e-3 by default (the shipped model: 512 with "
        "2e-3; with --laws 512 with 5e-4); a GPU wants larger batches, and then a larger --lr",
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--lr",
        type=float,
        help=f"peak learning rate (AdamW, {_default('lr')}), see --batch-size",
    )
    p.add_argument(
        "--patience",
        type=positive_int,
        default=DEFAULTS["patience"],
        help="early-stopping patience",
    )
    p.add_argument(
        "--curriculum-epochs",
        type=int,
        help="epochs over which the parameter anchor lambda falls linearly to 0 "
        f"({_default('curriculum_epochs')})",
    )
    p.add_argument(
        "--max-gap",
        type=gap_scale,
        default=DEFAULTS["max_gap"],
        help="largest height gap between consecutive asperities the network can output, in "
        "units of Delta_max (default %(default)s); 'paper' for the paper's 2/(N-1)",
    )
    for name, what in (
        ("shape", "L1 of alpha_hat and S_hat"),
        ("grad", "L1 of the S_hat differences"),
        ("mag", "squared log10 errors of P*_max and alpha_max"),
        ("curve", "relative curve error (what `evaluate` reports)"),
    ):
        p.add_argument(
            f"--w-{name}",
            type=float,
            help=f"loss weight of the {what} ({_default('w_' + name)}; the paper's: {PAPER[name]})",
        )
    p.add_argument(
        "--laws",
        action="store_true",
        help="train the friction-law network: on targets made from the dataset's cells the "
        "way friction laws arrive (ended anywhere, a few points, no stiffness, near but not "
        "on a cell's curve), loss the curve error at their own pressures, starting from "
        "--init (default: the shipped surrogate); `design` reads targets without stiffness "
        "with it too when it is the shipped weights/surrogate_laws.pt",
    )
    p.add_argument(
        "--adhesive",
        action="store_true",
        help="train the adhesive network: on the adhesive loading curves of the dataset's "
        "cells at works of adhesion drawn over 1e-6..3e-4 E* R, read as friction laws "
        "arrive, starting from --init (default: the shipped friction-law network), with "
        "the shipped adhesive network's settings otherwise (133 epochs, a 256-approach "
        "physics layer, snap-ins read over +-2 %% of the largest load); `design` reads "
        "targets of a model with adhesion with it too when it is the shipped "
        "weights/surrogate_adhesive.pt",
    )
    p.add_argument(
        "--adhesion-input",
        action=argparse.BooleanOptionalAction,
        help="with --adhesive: give the network log10 of w / (E* R) as an input too (the "
        "default, as the shipped one), or not (--no-adhesion-input: it reads the curve alone)",
    )
    p.add_argument(
        "--init",
        metavar="MODEL",
        help="start from this model file's weights (with --laws: the shipped surrogate, "
        "with --adhesive the shipped friction-law network, unless given)",
    )
    p.add_argument("--resume", action="store_true", help="continue the run in --out")
    add_device(p)
    p.add_argument("--plot", metavar="RUN_DIR", help="draw the training panels of a run")
    p.add_argument("--figure", help="with --plot: figure path (default RUN_DIR/training.png)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from metainterface.errors import MetainterfaceError

    if args.plot is not None:
        from metainterface.plots import plot_training, save_figure
        from metainterface.surrogate.run_state import read_metrics

        fig_path = args.figure if args.figure is not None else str(Path(args.plot) / "training.png")
        save_figure(plot_training(read_metrics(args.plot)), fig_path, command="train --plot")
        print(f"{fig_path}: training panels of {args.plot}")
        return 0
    if not (args.dataset and args.out):
        raise MetainterfaceError("train needs --dataset FILE and --out RUN_DIR (or --plot RUN_DIR)")
    import metainterface as mi

    given = {
        k: getattr(args, k)
        for k in ("epochs", "batch_size", "lr", "curriculum_epochs", *(f"w_{w}" for w in PAPER))
        if getattr(args, k) is not None
    }
    given.update(seed=args.seed, patience=args.patience, max_gap=args.max_gap)
    if args.init is not None:
        given["init"] = args.init
    if args.laws and args.adhesive:
        raise MetainterfaceError("give --laws or --adhesive, not both", argument="--adhesive")
    if args.adhesion_input is not None and not args.adhesive:
        raise MetainterfaceError("--adhesion-input needs --adhesive", argument="--adhesion-input")
    if args.adhesive:
        if args.adhesion_input is not None:
            given["adhesion_input"] = args.adhesion_input
        config = mi.TrainConfig.adhesive(**given)
    else:
        make = mi.TrainConfig.laws if args.laws else mi.TrainConfig
        config = make(**{**({} if args.laws else DEFAULTS), **given})
    result = mi.train_surrogate(
        args.dataset, args.out, config, resume=args.resume, device=args.device
    )
    print(
        f"{result.run_dir}: {result.epochs_run} epochs in {result.seconds:.0f} s, best "
        f"validation loss {result.best_val_loss:.4f} at epoch {result.best_epoch}"
        + (" (early stop)" if result.stopped_early else "")
    )
    return 0
