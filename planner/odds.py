"""A plan's odds under closed-loop execution: the probability of reaching the goal within a primitive budget, and
the primitives it is expected to spend.

Closed-loop execution (:mod:`planner.execute`) observes after every primitive and replans from where the object
lies, so a step that misses its own criterion is not the end of the plan: it costs the primitives that put the
object back on a way to the goal. The model here takes that literally. Step ``i`` of a plan is retried until it
succeeds, each try succeeding with the step's predicted probability ``q_i`` independently of the others, so it
takes ``N_i ~ Geometric(q_i)`` primitives; the plan reaches the goal within a budget ``B`` when
``N_1 + ... + N_n <= B``. The distribution of that sum is computed exactly (a convolution of truncated geometric
distributions, ``O(n B^2)``, no sampling), so a plan's odds are deterministic.

What the model leaves out, and what it is checked against: a failed primitive may leave the object worse off than
before (one retry is not always enough) or better (a push that fell short still moved it), and a step the executor
gives up on is replaced by another. ``affordplan bench plan`` compares the predicted odds with what happened
(calibration bins and the Brier score).

**Monte Carlo through the outcome model** (:func:`mc_odds`): a strict criterion undersells a step, since a push that
moved 3.5 cm did most of its job and the executor replans from there. :func:`mc_odds` instead draws what each
primitive achieves from the skill's outcome model (:class:`primitives.outcome_model.OutcomeModel`: the share of the
asked effect, given the step's strict probability) and counts the primitives until the plan's effect is achieved.

**Stuck steps.** Retries are not independent: a roll that fails on this object because the fingertip cannot get under
it fails again, and a push against a clamp stays clamped. Treating every try as a fresh draw makes a long budget look
like certain success (0.23's plans all predicted 1.00 and reached 0.83). :func:`mc_odds` therefore lets each step of a
run be *stuck* with probability ``r[skill] * (1 - q)`` (``q``: the step's predicted success of one try): a stuck
step makes no progress however often it is tried. The rates ``r``, one per skill, are fitted to plan outcomes on
training objects (:data:`STUCK_RATES`, :func:`fit_stuck_rates`). Stuck draws are independent of progress draws, so
``p_success`` is the product of the stuck-free odds and every step's ``1 - r * (1 - q)``.

**Pushes of several strides.** A straight run of pushes is made as calls of up to four 5 cm strides that correct
their course between strokes (:func:`primitives.strokes.push_to`): such a call is one primitive of the budget however
many strokes it makes, and :func:`mc_odds` draws its strokes within it.

**Tips.** A push or spin in a resting state that few drops come to rest in may knock the object into another state
(a hard drive on its edge falls flat; the outcome model's :meth:`~primitives.outcome_model.OutcomeModel.p_tip`).
Closed-loop execution then replans from the new state and sometimes rolls back, but often not within the budget.
A step may carry its tip probability ``t`` per try; each try of it then loses the run with probability
``f * t``, ``f`` the share of tips a plan does not recover from (:data:`TIP_FATAL`, fitted with the stuck rates,
:func:`fit_odds`). On the plan bench's 400 tasks (``affordplan bench plan --tasks 50 --sim arm --objects mixed``,
seeds 0-7; the same plans and outcomes as before) the Brier score of ``p_success`` went from 0.141 to 0.128.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from affordplan.checks import as_finite, as_whole
from affordplan.errors import InputError
from primitives.strokes import EXTRA_STROKES

if TYPE_CHECKING:
    from primitives.outcome_model import OutcomeModel

DEFAULT_BUDGET = 60  # primitives: Plan.execute's default max_primitives
Q_FLOOR = 0.02  # a step rated below this is treated as this: the executor replaces a step that keeps failing
# P(a step of skill k is stuck in a run) = STUCK_RATES[k] * (1 - q). Fitted by fit_stuck_rates to the first plans of
# `affordplan bench plan --objects training` runs (`affordplan bench fit-stuck`; training objects only; the
# commands and the figures: docs/guide.md, "What a plan predicts").
# 0.24.0: `affordplan bench fit-stuck runs/train_s100.json ... runs/train_s131.json`, thirty-two runs of `affordplan
# bench plan --tasks 24 --sim arm --planner affordplan --objects training --seed S --json` (S = 100-131) with pushes of
# up to four strides per call (planner.plan.MAX_STRIDES) and push failures remembered where they happened, 765 plans,
# 0.78 reached: Brier 0.097 (0.174 with neither stuck steps nor tips). Fitted on the even seeds and scored on the odd
# ones: 0.105 (roll 0.8); the other way round: 0.091 (roll 0.6); push 0.0, spin 0.1, fatal tips 0.2 in both. Until
# then the fit read a push of several strides as one stride; sixteen runs read so fitted roll 0.8, spin 0.2, fatal
# tips 0.3. Before strides, push 0.0, roll 0.6, spin 0.2, fatal tips 0.2; before tips, roll 0.9, spin 0.3.
STUCK_RATES: dict[str, float] = {"push": 0.0, "roll": 0.7, "spin": 0.1}
# The share of tips (a push or spin that leaves the object in another resting state) after which a run does not
# reach the goal; fitted with STUCK_RATES (fit_odds), the record beside them.
TIP_FATAL = 0.2


@dataclass(frozen=True)
class Odds:
    """A plan's odds: ``p_success`` (probability of reaching the goal within ``budget`` primitives) and
    ``expected_primitives`` (the mean primitives spent, counting a run that exhausts the budget as ``budget``)."""

    p_success: float
    expected_primitives: float
    budget: int


def primitives_pmf(step_probabilities: Sequence[float], budget: int) -> np.ndarray:
    """``pmf[k]`` = P(the steps take exactly ``k`` primitives in all), ``k = 0 .. budget``; the mass beyond the
    budget is ``1 - pmf.sum()``. Each step is retried until it succeeds, with success probability ``q_i`` per try
    (clipped to ``[Q_FLOOR, 1]``)."""
    budget = as_whole("budget", budget, 0, 100_000)
    q = np.asarray(step_probabilities, dtype=float).reshape(-1)
    if not np.all(np.isfinite(q)):
        raise InputError("step probabilities must be finite numbers in [0, 1]")
    if np.any(q < 0.0) or np.any(q > 1.0):
        raise InputError(f"step probabilities must lie in [0, 1], got {np.round(q, 3).tolist()[:8]}")
    q = np.clip(q, Q_FLOOR, 1.0)
    pmf = np.zeros(budget + 1)
    pmf[0] = 1.0
    k = np.arange(1, budget + 1)
    for qi in q:
        tries = np.zeros(budget + 1)
        tries[1:] = qi * (1.0 - qi) ** (k - 1)  # P(N = k), N >= 1
        pmf = np.convolve(pmf, tries)[: budget + 1]
    return pmf


def plan_odds(step_probabilities: Sequence[float], budget: int = DEFAULT_BUDGET) -> Odds:
    """The :class:`Odds` of a plan whose steps succeed with ``step_probabilities`` per try (module docstring)."""
    pmf = primitives_pmf(step_probabilities, budget)
    reach = float(pmf.sum())
    spent = float(np.dot(np.arange(len(pmf)), pmf) + (1.0 - reach) * budget)
    return Odds(p_success=min(max(reach, 0.0), 1.0), expected_primitives=spent, budget=int(budget))


def mc_odds(steps: Sequence[tuple[str, float] | tuple[str, float, float]], models: Mapping[str, OutcomeModel],
            budget: int = DEFAULT_BUDGET, seed: int = 0, n: int = 2000,
            stuck_rate: float | Mapping[str, float] | None = None, tip_fatal: float | None = None) -> Odds:
    """The :class:`Odds` of a plan by Monte Carlo through the skills' outcome models.

    ``steps``: the plan's ``(skill, strict p)``, ``(skill, strict p, tip)`` or ``(skill, strict p, tip, strides)``
    in order (``tip``: the probability that one try leaves the object in another resting state, 0 when not given;
    ``strides``: a push of k > 1 strides, :class:`planner.plan.Step`, counts as k steps made by one call of up to
    k + ``EXTRA_STROKES`` strokes, each stroke drawn as a primitive is below, the call ending when its strides are
    covered; 1 when not given); ``models``: an outcome model per skill used, anything with
    ``sample_progress(p, rng, n)`` (:class:`primitives.outcome_model.OutcomeModel`).

    Model: every step asks for one unit of its skill's effect (a push 5 cm, a spin its angle, a roll its state).
    Each of ``n`` runs spends primitives on its current step; a primitive draws a progress for that step's ``p``
    (below 0 counts 0: the planner replans from where the object is); progress accumulates over a stretch of
    consecutive steps of one skill, so a surplus carries over to the next step of the same skill (a push of 7 cm
    covers 1.4 push steps) but not across a change of skill; a roll counts only when it reached its state (a
    progress of at least 1 counts 1, less counts 0). ``p_success`` is the share of runs done within ``budget``
    primitives, ``expected_primitives`` their mean, counting a run that is not done as ``budget``. In each run, each
    step is stuck (makes no progress at all) with probability ``r * (1 - p)``, ``r`` its skill's entry of
    ``stuck_rate`` (a number: the same for every skill; ``None``: :data:`STUCK_RATES`; the module docstring). Each
    stroke made on a step with tip probability ``t`` loses its run (it never finishes) with probability
    ``tip_fatal * t`` (``None``: :data:`TIP_FATAL`).

    Each step's draws come from a pool of ``n`` samples of its model drawn once (``sample_progress(p, rng, n)``),
    resampled by the runs; the result is deterministic for a ``seed`` (``np.random.default_rng``). Vectorised over
    the runs: about a millisecond for a 10-step plan.

    Raises:
        InputError: a step that is not ``(skill, p[, tip])`` with ``p`` and ``tip`` in [0, 1], a skill with no
            model, a bad budget, ``n`` or ``tip_fatal``.
    """
    budget = as_whole("budget", budget, 0, 100_000)
    n = as_whole("n", n, 1, 10_000_000)
    rates = _stuck_rates(stuck_rate)
    fatal = as_finite("tip_fatal", TIP_FATAL if tip_fatal is None else tip_fatal, 0.0, 1.0)
    skills, q, tips, group, strokes = _expand(steps)
    for skill in skills:
        if skill not in models:
            raise InputError(f"no outcome model for {skill!r} (models for {sorted(models)})")
    m = len(skills)
    if m == 0:
        return Odds(p_success=1.0, expected_primitives=0.0, budget=int(budget))
    rng = np.random.default_rng(seed)
    pool = np.empty((m, n))
    for i, (skill, p) in enumerate(zip(skills, q)):
        draws = np.asarray(models[skill].sample_progress(p, rng, n), dtype=float).reshape(-1)
        if len(draws) != n or not np.all(np.isfinite(draws)):
            raise InputError(f"the {skill} outcome model gave {len(draws)} samples, not {n} finite ones")
        pool[i] = (draws >= 1.0 - 1e-9).astype(float) if skill == "roll" else np.maximum(draws, 0.0)
    # stretches of consecutive steps of one skill: every step's stretch start and end (exclusive)
    start = np.zeros(m, dtype=np.int64)
    for i in range(1, m):
        start[i] = start[i - 1] if skills[i] == skills[i - 1] else i
    end = np.empty(m, dtype=np.int64)
    end[-1] = m
    for i in range(m - 2, -1, -1):
        end[i] = end[i + 1] if skills[i] == skills[i + 1] else i + 1
    start, end = np.append(start, m), np.append(end, m)  # step m: done, absorbing
    pool = np.vstack([pool, np.zeros((1, n))])
    # per run and step: whether it can progress at all (stuck steps cannot); step m (done) is free
    free = np.ones((n, m + 1), dtype=bool)
    stuck = np.array([rates.get(skill, 0.0) for skill in skills]) * (1.0 - np.asarray(q))
    if np.any(stuck > 0.0):
        free[:, :m] = rng.random((n, m)) >= stuck
    # per step: the probability that a try loses the run (a tip not recovered from); step m (done) never does
    lose = np.append(fatal * np.asarray(tips), 0.0)
    can_tip = bool(np.any(lose > 0.0))  # tips are drawn only then, so plans that cannot tip keep their odds exactly
    alive = np.ones(n, dtype=bool)
    runs = np.arange(n)
    step = np.zeros(n, dtype=np.int64)  # each run's current step (m: done)
    acc = np.zeros(n)  # progress accumulated in the run's current stretch
    spent = np.full(n, budget, dtype=np.int64)
    group = np.append(group, -1)  # step m (done) is in no call
    for t in range(1, budget + 1):
        call = group[step]  # the call each run makes with this primitive
        for stroke in range(int(strokes.max())):
            if stroke == 0:
                active = np.ones(n, dtype=bool)
            else:  # further strokes: runs still in their call's steps and within its strokes
                active = (group[step] == call) & (call >= 0) & (stroke < strokes[np.maximum(call, 0)])
                if not active.any():
                    break
            if can_tip:
                alive &= ~active | (rng.random(n) >= lose[step])
            acc += pool[step, rng.integers(n, size=n)] * (free[runs, step] & alive & active)
            covered = start[step] + np.floor(acc + 1e-9).astype(np.int64)
            finished = covered >= end[step]
            step = np.where(finished, end[step], np.minimum(covered, end[step]))
            acc[finished] = 0.0
        newly = (step == m) & (spent == budget)
        spent[newly] = t
        if np.all(step == m):
            break
    done = step == m
    # a run that finished on the budget's last primitive has spent == budget either way
    return Odds(p_success=float(done.mean()), expected_primitives=float(spent.mean()), budget=int(budget))


def _expand(steps: Sequence[tuple]) -> tuple[list[str], list[float], list[float], np.ndarray, np.ndarray]:
    """``steps`` (:func:`mc_odds`) checked and spread into unit steps: per unit its skill, strict p, tip and call
    (index into the returned strokes per call); a step of ``strides`` k > 1 becomes k units of one call of at most
    k + 1 strokes (:data:`primitives.strokes.EXTRA_STROKES`), any other step one unit of a one-stroke call."""
    skills: list[str] = []
    q: list[float] = []
    tips: list[float] = []
    group: list[int] = []
    strokes: list[int] = []
    for step in steps:
        try:
            skill, p, *rest = step
            p, tip = float(p), float(rest[0]) if rest else 0.0
            k = as_whole("strides", rest[1], 1, 1000) if len(rest) > 1 else 1
            if len(rest) > 2:
                raise ValueError
        except (TypeError, ValueError):
            raise InputError(f"a step must be (skill, strict p[, tip[, strides]]), got {step!r:.60}") from None
        for name, value in (("step probabilities", p), ("tip probabilities", tip)):
            if not (np.isfinite(value) and 0.0 <= value <= 1.0):
                raise InputError(f"{name} must lie in [0, 1], got {value!r} for {skill!r}")
        skills += [skill] * k
        q += [p] * k
        tips += [tip] * k
        group += [len(strokes)] * k
        strokes.append(k + EXTRA_STROKES if k > 1 else 1)
    return skills, q, tips, np.array(group, dtype=np.int64), np.array(strokes or [1], dtype=np.int64)


def _stuck_rates(stuck_rate: float | Mapping[str, float] | None) -> dict[str, float]:
    """``stuck_rate`` as a rate per skill (:func:`mc_odds`), checked."""
    if stuck_rate is None:
        return dict(STUCK_RATES)
    rates = dict(stuck_rate) if isinstance(stuck_rate, Mapping) else {skill: stuck_rate for skill in STUCK_RATES}
    for skill, rate in rates.items():
        if not (isinstance(rate, (int, float, np.floating)) and np.isfinite(rate) and 0.0 <= rate <= 1.0):
            raise InputError(f"stuck_rate must lie in [0, 1], got {rate!r} for {skill!r}")
    return {skill: float(rate) for skill, rate in rates.items()}


def fit_stuck_rates(plans: Sequence[Sequence[tuple]], reached: Sequence[bool], models: Mapping[str, OutcomeModel],
                    budget: int = DEFAULT_BUDGET, grid: Sequence[float] = tuple(np.linspace(0.0, 1.0, 21)),
                    seed: int = 0, n: int = 2000, tip_fatal: float | None = None
                    ) -> tuple[dict[str, float], float, float]:
    """The stuck rates (one per skill, :func:`mc_odds`) whose predicted ``p_success`` fits ``reached`` best: the
    rates on ``grid`` (every combination for the skills the plans use) with the least Brier score over the
    ``plans`` (each a plan's ``(skill, p)`` or ``(skill, p, tip)`` steps, tips lost at ``tip_fatal``) and their
    outcomes.

    Each plan's stuck-free odds are simulated once; the stuck steps then multiply them (module docstring).
    Returns ``(rates, brier, brier_without)``: the rates, their Brier score, and the score with no stuck steps.
    Fit on plans of training objects only, and judge the rates on others.

    Raises:
        InputError: no plans, or ``plans`` and ``reached`` of different lengths.
    """
    if len(plans) != len(reached) or not plans:
        raise InputError(f"need as many outcomes as plans, at least one; got {len(plans)} and {len(reached)}")
    y = np.asarray(reached, dtype=float)
    base = np.array([mc_odds(steps, models, budget, seed=seed, n=n, stuck_rate=0.0, tip_fatal=tip_fatal).p_success
                     for steps in plans])
    used = sorted({step[0] for steps in plans for step in steps})
    grid = np.asarray(grid, dtype=float)
    # misses[i][j]: every (1 - q) of plan j's steps of skill used[i]
    units = [_expand(steps)[:2] for steps in plans]  # a step of several strides is stuck per stride, as in mc_odds
    misses = [[np.array([1.0 - p for s, p in zip(*u) if s == skill]) for u in units] for skill in used]
    # factors[i][g, j]: plan j's stuck factor from skill used[i]'s steps at rate grid[g], prod of 1 - r * (1 - q)
    factors = [np.array([[np.prod(1.0 - r * miss) for miss in skill_misses] for r in grid])
               for skill_misses in misses]
    # every combination of rates at once: p[g_0, ..., g_k, j] = base[j] * prod_i factors[i][g_i, j]
    p = base
    for i, f in enumerate(factors):
        p = p[..., None, :] * f.reshape((1,) * i + f.shape)
    scores = np.mean((p - y) ** 2, axis=-1)
    best = [grid[g] for g in np.unravel_index(int(np.argmin(scores)), scores.shape)]
    best_score = float(scores.min())
    rates = {skill: 0.0 for skill in STUCK_RATES} | {skill: float(r) for skill, r in zip(used, best)}
    return rates, best_score, float(np.mean((base - y) ** 2))


def fit_odds(plans: Sequence[Sequence[tuple]], reached: Sequence[bool], models: Mapping[str, OutcomeModel],
             budget: int = DEFAULT_BUDGET, grid: Sequence[float] = tuple(np.linspace(0.0, 1.0, 21)),
             fatal_grid: Sequence[float] = tuple(np.linspace(0.0, 1.0, 11)), seed: int = 0, n: int = 2000
             ) -> tuple[dict[str, float], float, float, float]:
    """The stuck rates and the share of fatal tips (:data:`STUCK_RATES`, :data:`TIP_FATAL`) that fit ``reached``
    best: for each ``tip_fatal`` on ``fatal_grid``, the best rates on ``grid`` (:func:`fit_stuck_rates`), and of
    those the pair with the least Brier score. Returns ``(rates, tip_fatal, brier, brier_without)``, the last with
    neither stuck steps nor tips. Fit on plans of training objects only.

    Raises:
        InputError: as :func:`fit_stuck_rates`.
    """
    best, without = None, None
    for fatal in np.asarray(fatal_grid, dtype=float):
        rates, score, bare = fit_stuck_rates(plans, reached, models, budget, grid, seed, n, tip_fatal=float(fatal))
        if fatal == 0.0:
            without = bare  # the score with neither stuck steps nor tips
        if best is None or score < best[2] - 1e-12:
            best = (rates, float(fatal), score)
    if without is None:  # a grid without 0: simulate the bare odds once more
        without = fit_stuck_rates(plans, reached, models, budget, grid, seed, n, tip_fatal=0.0)[2]
    rates, fatal, score = best
    return rates, fatal, score, without
