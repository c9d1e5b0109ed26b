"""Per-iteration overhead of the batched L-BFGS (design/lbfgs.py), apart from the loss.

The refinement's problems are tiny (B = 3..150 rows, D = 9..17 parameters), so what the
optimiser costs is its number of tensor operations, not their flops. This times ``minimize``
on a cheap batched quadratic (condition number 1e4: 100 iterations do not converge it, so
every iteration takes an ordinary step) with the tolerances off, subtracts the time of as
many loss-and-gradient evaluations (forward + autograd, full batch) and divides by the
iterations. Plain and ``indexed`` calls, float64, one thread; best of --repeat, the runs of
each module and of the bare evaluations interleaved, so that a slow spell of the machine
hits all of them alike.

--old FILE also times another copy of the module, e.g. the committed one:
  git show HEAD:src/metainterface/design/lbfgs.py > /tmp/lbfgs_old.py
  python benchmarks/bench_lbfgs.py --old /tmp/lbfgs_old.py
"""

import argparse
import importlib.util
import sys
import time
from collections.abc import Callable
from types import ModuleType

import torch
from torch import Tensor

from metainterface.inverse import lbfgs
from metainterface.runtime import tune_allocator

OFF = {"tol_grad": -1.0, "tol_change": -1.0, "tol_loss": -float("inf")}


def quadratic(b: int, d: int, cond: float = 1e4, seed: int = 0) -> Callable[..., Tensor]:
    """Row-wise 0.5 (x - c)^T A (x - c), A (b, d, d) random with eigenvalues 1..cond."""
    gen = torch.Generator().manual_seed(seed)
    q, _ = torch.linalg.qr(torch.randn(b, d, d, generator=gen, dtype=torch.float64))
    eig = torch.logspace(0, torch.log10(torch.tensor(cond)).item(), d, dtype=torch.float64)
    a = q @ torch.diag_embed(eig.expand(b, d)) @ q.mT
    c = torch.randn(b, d, generator=gen, dtype=torch.float64)

    def fun(x: Tensor, idx: Tensor | None = None) -> Tensor:
        a_, c_ = (a, c) if idx is None else (a[idx], c[idx])
        z = (x - c_)[:, :, None]
        return 0.5 * (z.mT @ a_ @ z)[:, 0, 0]

    return fun


def timed(run: Callable[[], object]) -> float:
    t0 = time.perf_counter()
    run()
    return time.perf_counter() - t0


def overheads(
    mods: dict[str, ModuleType], b: int, d: int, indexed: bool, args: argparse.Namespace
) -> dict[str, str]:
    """Per module: its overhead per iteration (ms) and the counts, as a line."""
    fun = quadratic(b, d)
    x0 = torch.zeros(b, d, dtype=torch.float64)
    idx = torch.arange(b)
    kw = {"indexed": indexed, "max_iter": args.iterations, "history": args.history, **OFF}
    # warm-up; also the counts (the same every run)
    results = {name: mod.minimize(fun, x0, **kw) for name, mod in mods.items()}
    evaluations = max(res.evaluations for res in results.values())

    def bare() -> None:
        for _ in range(evaluations):
            x = x0.detach().requires_grad_(True)
            f = fun(x, idx) if indexed else fun(x)
            torch.autograd.grad(f.sum(), x)

    best = dict.fromkeys([*mods, "bare"], float("inf"))
    for _ in range(args.repeat):
        for name, mod in mods.items():
            best[name] = min(best[name], timed(lambda mod=mod: mod.minimize(fun, x0, **kw)))
        best["bare"] = min(best["bare"], timed(bare))
    per_eval = best["bare"] / evaluations
    lines = {}
    for name, res in results.items():
        loss_time = per_eval * res.evaluations
        per_it = (best[name] - loss_time) / res.iterations * 1e3
        lines[name] = (
            f"{per_it:6.3f} ms/iteration  (total {best[name] * 1e3:6.1f} ms, "
            f"{res.evaluations} evaluations {loss_time * 1e3:5.1f} ms, "
            f"{res.iterations} iterations)"
        )
    return lines


def load(path: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location("lbfgs_other", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--iterations 10 --repeat 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--old", help="another lbfgs.py to time against this one")
    ap.add_argument("--iterations", type=int, default=100)
    ap.add_argument("--history", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    tune_allocator()  # as the CLI does
    torch.set_num_threads(1)
    mods = {"new": lbfgs} if args.old is None else {"old": load(args.old), "new": lbfgs}
    print(
        f"batched L-BFGS overhead per iteration (minimize minus the evaluations), history "
        f"{args.history}, {args.iterations} iterations, best of {args.repeat}, float64, "
        f"torch {torch.__version__}, 1 thread"
    )
    for b, d in ((3, 17), (150, 17)):
        for indexed in (False, True):
            lines = overheads(mods, b, d, indexed, args)
            for name, line in lines.items():
                print(f"  B={b:<3d} D={d} {'indexed' if indexed else 'plain  '} {name}: {line}")


if __name__ == "__main__":
    main()
