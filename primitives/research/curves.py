"""Learning curves (success and reward vs steps) and the memory curve of training runs, as a PNG.

    python -m primitives.research.curves runs/push runs/roll runs/spin --out curves.png
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from affordplan.errors import InputError
from affordplan.log import cli_logging


def read_log(run: str | Path) -> dict[str, list[float]]:
    """The columns of ``run/log.csv`` as lists (empty for a log with no rows yet)."""
    path = Path(run) / "log.csv"
    if not path.is_file():
        raise InputError(f"{run} is not a training run folder: it has no log.csv")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def thousands(x: float) -> str:
    """A step count as a tick label in thousands: ``120000 -> "120k"``, ``2500 -> "2.5k"``, ``0 -> "0"``."""
    return f"{x / 1000:g}k" if x else "0"


def plot_curves(runs: list[str | Path], out: str | Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    for run in runs:
        log = read_log(run)
        if not log:
            continue
        label = Path(run).name
        axes[0].plot(log["step"], log["success_recent"], label=label)
        axes[1].plot(log["step"], log["reward_recent"], label=label)
        axes[2].plot(log["minutes"], log["rss_mb_total"], label=label)
    for ax in axes[:2]:  # six-digit step counts run into each other as tick labels
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda x, _: thousands(x)))
    axes[0].set(xlabel="primitives executed", ylabel="success (last 500, exploring)", ylim=(0, 1),
                title="training success")
    axes[1].set(xlabel="primitives executed", ylabel="reward = -L (last 500)", title="training reward")
    axes[2].set(xlabel="minutes", ylabel="resident memory, learner + workers (MB)", title="memory")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m primitives.research.curves", description=__doc__.split("\n\n")[0],
                                epilog="example:\n"
                                "  python -m primitives.research.curves runs/push runs/roll --out curves.png",
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+", help="run folders (each with a log.csv)")
    p.add_argument("--out", default="curves.png")
    args = p.parse_args(argv)
    cli_logging()
    try:
        plot_curves(args.runs, args.out)
    except InputError as exc:
        p.error(str(exc))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
