"""Do the local and the Ray rollout backends train equally well? Same budget, same seeds, same test.

    python -m primitives.research.compare_backends push --steps 1500 --seeds 3 --trials 200 \
        --init primitives/weights/push.pt --out runs/compare_backends

For each seed, trains one policy with ``--backend local`` and one with ``--backend ray`` (same step
budget, same ``--workers``, same seed, hence the same worker seeds), then evaluates every policy
greedily on the same held-out starts (:func:`primitives.training.evaluate.evaluate`: the held-out procedural
objects, one evaluation seed). Reports, per backend, the greedy success pooled over seeds and the
exploring success of the transitions collected during training, each with a two-sided
two-proportion z-test and Fisher's exact test of "both backends succeed equally often".

The tests treat trials as independent, which ignores that trials of one policy share its training
seed: with few seeds, read a large p-value as "no difference this run can detect", not as proof of
equality. A short run from scratch barely learns (both rates stay near zero and agree trivially);
starting both from the shipped weights (``--init``) makes the comparison informative. Runs with
workers are not bit-reproducible (when new weights reach a worker, and in which order workers'
transitions arrive, is timing), so the backends never produce identical policies; only their
distributions can agree.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from scipy import stats

from affordplan.log import cli_logging
from primitives.training import checkpoint as ckpt
from primitives.training.env import PRIMITIVES
from primitives.training.evaluate import evaluate, load_policy
from primitives.training.rollouts import BACKENDS, connect_ray, import_ray
from primitives.training.train import TrainConfig, train

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Proportions:
    """Successes out of trials for the two backends, and tests of their equality."""

    successes: tuple[int, int]  # (local, ray)
    trials: tuple[int, int]

    @property
    def rates(self) -> tuple[float, float]:
        return tuple(s / max(1, n) for s, n in zip(self.successes, self.trials))

    def z_test(self) -> tuple[float, float]:
        """Two-sided two-proportion z-test with the pooled variance: ``(z, p-value)``."""
        (x1, x2), (n1, n2) = self.successes, self.trials
        pooled = (x1 + x2) / (n1 + n2)
        se = math.sqrt(pooled * (1.0 - pooled) * (1.0 / n1 + 1.0 / n2))
        if se == 0.0:  # both all-success or all-failure: identical
            return 0.0, 1.0
        z = (x1 / n1 - x2 / n2) / se
        return z, float(2.0 * stats.norm.sf(abs(z)))

    def fisher(self) -> float:
        """Two-sided p-value of Fisher's exact test on the 2x2 table."""
        (x1, x2), (n1, n2) = self.successes, self.trials
        return float(stats.fisher_exact([[x1, n1 - x1], [x2, n2 - x2]])[1])

    def as_dict(self) -> dict:
        z, p = self.z_test()
        return dict(local=dict(successes=self.successes[0], trials=self.trials[0], rate=self.rates[0]),
                    ray=dict(successes=self.successes[1], trials=self.trials[1], rate=self.rates[1]),
                    z=z, p_z_test=p, p_fisher=self.fisher())


def compare(primitive: str, steps: int, seeds: int, trials: int, out: Path, workers: int = 1,
            eval_seed: int = 1234, ray_address: str | None = None, progress: bool = True,
            **train_kwargs) -> dict:
    """Train ``seeds`` policies per backend and compare their success; returns the report."""
    owns_ray = connect_ray(ray_address, num_cpus=max(2, workers + 1))  # one Ray instance for every ray run
    runs = []
    try:
        for seed in range(seeds):
            for backend in BACKENDS:  # interleaved: a change in machine load hits both alike
                run_dir = out / f"{backend}_seed{seed}"
                cfg = TrainConfig(primitive=primitive, steps=steps, workers=workers, backend=backend, seed=seed,
                                  out=str(run_dir), ray_address=ray_address if backend == "ray" else None,
                                  checkpoint_minutes=1e9, max_minutes=1e9, **train_kwargs)
                t0 = time.time()
                summary = train(cfg, progress=progress)
                train_s = time.time() - t0
                replay = ckpt.load(run_dir / "checkpoint.pt")["replay"]
                result = evaluate(load_policy(run_dir / "policy.pt", primitive), primitive, "random", trials,
                                  seed=eval_seed, progress=False)
                greedy = [s for v in result.per_object.values() for s in v]
                runs.append(dict(backend=backend, seed=seed, steps=summary["steps"], updates=summary["updates"],
                                 train_seconds=round(train_s, 1), invalid=summary["invalid"],
                                 collect_successes=int(np.sum(replay["success"])),
                                 collect_transitions=int(replay["size"]),
                                 greedy_successes=int(np.sum(greedy)), greedy_trials=len(greedy),
                                 eval_invalid=result.invalid))
                if progress:
                    r = runs[-1]
                    logger.info("%-5s seed %s: %s steps, %s updates, %.0f s; collect success %s/%s, greedy success "
                                "%s/%s", backend, seed, r["steps"], r["updates"], r["train_seconds"],
                                r["collect_successes"], r["collect_transitions"], r["greedy_successes"],
                                r["greedy_trials"])
    finally:
        if owns_ray:
            import_ray().shutdown()

    def pooled(key: str, total: str) -> Proportions:
        return Proportions(tuple(sum(r[key] for r in runs if r["backend"] == b) for b in BACKENDS),
                           tuple(sum(r[total] for r in runs if r["backend"] == b) for b in BACKENDS))

    report = dict(primitive=primitive, steps=steps, seeds=seeds, workers=workers, eval_trials=trials,
                  eval_seed=eval_seed, train=train_kwargs, runs=runs,
                  greedy=pooled("greedy_successes", "greedy_trials").as_dict(),
                  collect=pooled("collect_successes", "collect_transitions").as_dict())
    out.mkdir(parents=True, exist_ok=True)
    (out / "compare.json").write_text(json.dumps(report, indent=2))
    return report


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m primitives.research.compare_backends",
                                description=__doc__.split("\n\n")[0])
    d = TrainConfig()
    p.add_argument("primitive", choices=PRIMITIVES)
    p.add_argument("--steps", type=int, default=600, help="primitives per training run (default: %(default)s)")
    p.add_argument("--seeds", type=int, default=3, help="training seeds per backend (default: %(default)s)")
    p.add_argument("--trials", type=int, default=100, help="greedy evaluation starts per policy (default: %(default)s)")
    p.add_argument("--workers", type=int, default=1, help="rollout workers per run, both backends")
    p.add_argument("--eval-seed", type=int, default=1234, help="seed of the held-out starts")
    p.add_argument("--ray-address", default=None, help="Ray cluster for the ray runs (default: a local instance)")
    p.add_argument("--learning-starts", type=int, default=200, help="(default: %(default)s)")
    p.add_argument("--replay-ratio", type=float, default=d.replay_ratio)
    p.add_argument("--p-params", type=float, default=0.0, help="share of parameterised training episodes "
                   "(default: %(default)s, the seed's objective, which the evaluation judges)")
    p.add_argument("--init", default=None, help="start every run from these weights")
    p.add_argument("--out", default="runs/compare_backends", help="run folders and compare.json go here")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    cli_logging()
    torch.set_num_threads(1)
    report = compare(args.primitive, args.steps, args.seeds, args.trials, Path(args.out), workers=args.workers,
                     eval_seed=args.eval_seed, ray_address=args.ray_address, progress=True,
                     learning_starts=args.learning_starts, replay_ratio=args.replay_ratio, p_params=args.p_params,
                     init=args.init)
    for name, label in (("greedy", "greedy success, held-out starts"), ("collect", "exploring success in training")):
        r = report[name]
        print(f"{label}: local {r['local']['successes']}/{r['local']['trials']} = {r['local']['rate']:.3f}, "
              f"ray {r['ray']['successes']}/{r['ray']['trials']} = {r['ray']['rate']:.3f}; "
              f"z = {r['z']:+.2f}, p = {r['p_z_test']:.3f} (Fisher exact p = {r['p_fisher']:.3f})")
    print(f"report: {Path(args.out) / 'compare.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
