"""``affordplan bench compare``: two sets of saved plan-bench runs of the same tasks, task by task.

Choosing between two versions of the planner or the skills on the plan bench is a paired comparison: both ran the
same tasks (the same seeds draw the same objects, scenes, starts and goals), so what tells them apart is the tasks
one reached and the other did not. :func:`compare` matches the tasks of a *base* set of runs with those of a
*candidate* set by (seed, task, planner), checks that they are the same tasks (the same object and scene), and
reports:

- success of each, and the tasks gained and lost (with their objects);
- the exact two-sided sign test on those discordant tasks (:func:`scipy.stats.binomtest`, McNemar's exact test):
  the probability of a split at least this uneven if neither version were better. Closed-loop runs are chaotic (a
  stroke a millimetre off changes every later call), so a handful of tasks either way is what two equal versions
  give;
- primitives and fingertip strokes per task over the tasks both reached (a change that reaches more tasks by
  spending more primitives on them shows here), and the median primitives over all tasks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import binomtest

from affordplan.errors import InputError


@dataclass(frozen=True)
class TaskPair:
    """One task as both sets ran it: its key ``(seed, task, planner)``, its object, and each set's outcome."""

    key: tuple[int, int, str]
    object_name: str
    base_success: bool
    candidate_success: bool
    base_primitives: int
    candidate_primitives: int
    base_strokes: int
    candidate_strokes: int


@dataclass
class Comparison:
    """The paired comparison of two sets of plan-bench runs (:func:`compare`)."""

    pairs: list[TaskPair] = field(default_factory=list)

    @property
    def gained(self) -> list[TaskPair]:
        """Tasks the candidate reached and the base did not."""
        return [p for p in self.pairs if p.candidate_success and not p.base_success]

    @property
    def lost(self) -> list[TaskPair]:
        """Tasks the base reached and the candidate did not."""
        return [p for p in self.pairs if p.base_success and not p.candidate_success]

    def p_value(self) -> float:
        """Exact two-sided sign test on the gained and lost tasks (1.0 when there are none)."""
        n = len(self.gained) + len(self.lost)
        return float(binomtest(len(self.gained), n, 0.5).pvalue) if n else 1.0

    def summary(self) -> dict:
        """The figures of the module docstring, as a dict (what ``--json`` prints)."""
        both = [p for p in self.pairs if p.base_success and p.candidate_success]

        def mean(values: list[int]) -> float:
            return float(np.mean(values)) if values else float("nan")

        return dict(
            tasks=len(self.pairs),
            base_success=float(np.mean([p.base_success for p in self.pairs])),
            candidate_success=float(np.mean([p.candidate_success for p in self.pairs])),
            base_reached=sum(p.base_success for p in self.pairs),
            candidate_reached=sum(p.candidate_success for p in self.pairs),
            gained=[_describe(p) for p in self.gained],
            lost=[_describe(p) for p in self.lost],
            sign_test_p=self.p_value(),
            both_reached=len(both),
            both_mean_primitives=dict(base=mean([p.base_primitives for p in both]),
                                      candidate=mean([p.candidate_primitives for p in both])),
            both_mean_strokes=dict(base=mean([p.base_strokes for p in both]),
                                   candidate=mean([p.candidate_strokes for p in both])),
            median_primitives=dict(base=float(np.median([p.base_primitives for p in self.pairs])),
                                   candidate=float(np.median([p.candidate_primitives for p in self.pairs]))),
        )

    def report(self) -> str:
        """The summary as text."""
        s = self.summary()
        both_p, both_s, med = s["both_mean_primitives"], s["both_mean_strokes"], s["median_primitives"]
        lines = [
            f"{s['tasks']} tasks: base {s['base_success']:.3f} ({s['base_reached']}), candidate "
            f"{s['candidate_success']:.3f} ({s['candidate_reached']}); {len(s['gained'])} gained, {len(s['lost'])} "
            f"lost (exact sign test p = {s['sign_test_p']:.2f})",
            f"tasks both reached: {s['both_reached']}; mean primitives {both_p['base']:.2f} -> "
            f"{both_p['candidate']:.2f}, mean fingertip strokes {both_s['base']:.2f} -> {both_s['candidate']:.2f}; "
            f"median primitives over all tasks {med['base']:.1f} -> {med['candidate']:.1f}",
        ]
        for name in ("gained", "lost"):
            if s[name]:
                lines.append(f"{name}: " + "; ".join(s[name]))
        return "\n".join(lines)


def _describe(p: TaskPair) -> str:
    seed, task, planner = p.key
    return (f"seed {seed} task {task} {planner} ({p.object_name or 'object unnamed'}: "
            f"{p.base_primitives} -> {p.candidate_primitives} primitives)")


def _tasks(reports: Sequence[dict], which: str) -> dict[tuple[int, int, str], dict]:
    """The tasks of saved runs by (seed, task, planner); raises InputError for runs that are not saved plan-bench
    runs, runs without a seed, or one task given twice."""
    out: dict[tuple[int, int, str], dict] = {}
    for i, report in enumerate(reports):
        try:
            seed = report["seed"]
            if seed is None:
                raise KeyError("seed")
            for task in report["tasks"]:
                key = (int(seed), int(task["task"]), str(task["planner"]))
                if key in out:
                    raise InputError(f"{which} run {i + 1}: seed {key[0]} task {key[1]} ({key[2]}) given twice")
                out[key] = dict(task, budget=int(report["max_primitives"]), objects=str(report["objects"]),
                                draw=int(report.get("draw", 0)))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{which} run {i + 1} is not a saved `affordplan bench plan --json` run with its seed "
                             f"({exc!r:.80})") from None
    return out


def compare(base: Sequence[dict], candidate: Sequence[dict]) -> Comparison:
    """Pair the tasks of the ``base`` runs with those of the ``candidate`` runs (``BenchReport.as_dict``, as
    ``affordplan bench plan --json`` prints it) by (seed, task, planner); tasks only one side ran are left out.

    Raises:
        InputError: either side empty or not saved plan-bench runs; no task in common; a task both ran with other
            objects, scene, budget or draw (they are not the same task).
    """
    if not base or not candidate:
        raise InputError("compare needs saved runs on both sides (base and candidate)")
    a, b = _tasks(base, "base"), _tasks(candidate, "candidate")
    common = sorted(set(a) & set(b))
    if not common:
        raise InputError("the base and candidate runs share no task (seed, task index and planner)")
    pairs = []
    for key in common:
        x, y = a[key], b[key]
        for field_name in ("object_name", "scene", "budget", "objects", "draw"):
            if x.get(field_name) != y.get(field_name):
                raise InputError(f"seed {key[0]} task {key[1]} is not the same task on both sides: {field_name} "
                                 f"{x.get(field_name)!r:.60} against {y.get(field_name)!r:.60}")
        pairs.append(TaskPair(key, str(x.get("object_name", "")), bool(x["success"]), bool(y["success"]),
                              int(x["primitives"]), int(y["primitives"]), int(x.get("strokes", 0)),
                              int(y.get("strokes", 0))))
    return Comparison(pairs)
