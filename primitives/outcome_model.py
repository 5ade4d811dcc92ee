"""What a skill call achieves, as the planner can know it when it plans: the outcome model.

A skill's success model rates a call by its *strict* criterion (a push moved >= 5 cm within 15 deg of its direction
and turned < 5 deg; a spin turned within 10 deg of the asked angle; a roll ended in the asked state). Closed-loop
execution replans after every call, so a push that moved 3.5 cm did most of its job. The outcome model says how
much of the asked effect a call achieves, conditioned on what the planner knows at planning time: the strict
success probability ``p_strict`` the success model gives for that cloud and parameter.

**Units** (``progress``): the share of the asked effect achieved, dimensionless. Push: displacement along the asked
direction over ``PUSH_STEP`` (5 cm), so 1.4 is a push of 7 cm, and a push backwards is negative; spin: the turn in the
asked sense over ``|angle|``; roll: 1 when the object ended in the asked resting state, else 0. A push or spin that
left the object in another resting state counts 0.

**Model**: the rollouts collected by ``python -m primitives.training.outcomes collect`` (each a strict ``p`` and the
``progress`` measured): a query ``p_strict`` takes the ``k`` (default 60) rollouts whose ``p`` is nearest, and
:meth:`OutcomeModel.sample_progress` resamples their progress; :meth:`OutcomeModel.p_progress` is the share of
them that made progress (:func:`primitives.params.made_progress`'s criterion).

**Tips** (:meth:`OutcomeModel.p_tip`): a push or a spin may leave the object in another resting state (a hard drive
stood on its edge falls flat). Where the file records each rollout's start state's drop probability (the column
``state_probability``: the share of random drops that come to rest in that state), the model gives the share of the
``k`` rollouts nearest in log drop probability whose call ended in another state: a state few drops rest in is one a
push easily knocks over (on the training collection: 25 % of pushes in states rarer than 0.13, none above 0.52).

**Limits**: progress conditions on ``p_strict`` only, tips on the drop probability only. The parameter is
marginalised over the planner's distribution (push direction: irrelevant by the table's symmetry; spin ``|angle|``
between 15 and 45 deg; roll target), and so is the object (the collection's objects: procedural training objects and
HACMan's training meshes), the start pose and the sensor's noise. Successive calls on one object are treated as
independent draws, though a call that failed on an object is likelier to fail again. A few hundred rollouts resolve
the distribution coarsely, least well at high ``p`` where few rollouts lie (the ``k`` nearest then reach down to
lower ``p``). ``python -m primitives.training.outcomes check`` measures the intervals' coverage, and the tip rate,
on unseen objects.
"""

from __future__ import annotations

import math
import os
import zipfile
from pathlib import Path

import numpy as np

from affordplan.errors import InputError, WeightsError
from primitives.params import SKILLS
from primitives.weights_file import SHIPPED_DIR

DEFAULT_K = 60  # rollouts nearest in p that a query resamples
REQUIRED = ("p", "progress", "made_progress")
TIP_COLUMNS = ("state_probability", "state_before", "state_after")  # what p_tip needs; older files lack the first


class OutcomeModel:
    """A skill's outcome model (module docstring): ``p`` and ``progress`` of collected rollouts, and whether each
    made progress.

    Args:
        skill: ``"push"``, ``"roll"`` or ``"spin"``.
        p: ``(m,)`` strict success probabilities the success model gave the rollouts.
        progress: ``(m,)`` the share of the asked effect each achieved.
        made_progress: ``(m,)`` bools; default ``progress >= 1`` for roll, ``progress > 0`` otherwise.
        k: rollouts nearest in ``p`` that a query takes (capped at ``m``).
        state_probability: ``(m,)`` drop probability of each rollout's start state, in (0, 1]; with ``tipped``,
            what :meth:`p_tip` reads. ``None``: the model knows nothing of tips (``p_tip`` is 0).
        tipped: ``(m,)`` bools, the call ended in another resting state than it started in.
    """

    def __init__(self, skill: str, p, progress, made_progress=None, k: int = DEFAULT_K, state_probability=None,
                 tipped=None):
        if skill not in SKILLS:
            raise InputError(f"unknown skill {skill!r}; expected one of {SKILLS}")
        p = np.asarray(p, dtype=float).reshape(-1)
        progress = np.asarray(progress, dtype=float).reshape(-1)
        made = (progress >= 1.0 if skill == "roll" else progress > 0.0) if made_progress is None else \
            np.asarray(made_progress, dtype=bool).reshape(-1)
        if not (len(p) == len(progress) == len(made)) or len(p) == 0:
            raise InputError(f"an outcome model needs as many p, progress and made_progress values, at least one; "
                             f"got {len(p)}, {len(progress)}, {len(made)}")
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(progress))) or np.any(p < 0) or np.any(p > 1):
            raise InputError("an outcome model's p must be finite numbers in [0, 1] and its progress finite")
        if int(k) < 1:
            raise InputError(f"k must be at least 1, got {k}")
        order = np.argsort(p, kind="stable")
        self.skill = skill
        self.p, self.progress, self.made_progress = p[order], progress[order], made[order]
        self.k = min(int(k), len(p))
        # tips, sorted by log drop probability (None: unknown)
        self._tip_log_prob: np.ndarray | None = None
        self._tipped: np.ndarray | None = None
        if (state_probability is None) != (tipped is None):
            raise InputError("an outcome model needs both state_probability and tipped, or neither")
        if state_probability is not None:
            sp = np.asarray(state_probability, dtype=float).reshape(-1)
            tip = np.asarray(tipped, dtype=bool).reshape(-1)
            if not (len(sp) == len(tip) == len(p)):
                raise InputError(f"state_probability and tipped need one value per rollout ({len(p)}), got "
                                 f"{len(sp)} and {len(tip)}")
            if not np.all(np.isfinite(sp)) or np.any(sp <= 0.0) or np.any(sp > 1.0):
                raise InputError("an outcome model's state_probability must lie in (0, 1]")
            by_prob = np.argsort(sp, kind="stable")
            self._tip_log_prob, self._tipped = np.log(sp[by_prob]), tip[by_prob]

    @property
    def knows_tips(self) -> bool:
        """Whether the model was given each rollout's drop probability and state change (:meth:`p_tip`)."""
        return self._tipped is not None

    @classmethod
    def load(cls, skill: str, path: str | os.PathLike | None = None, k: int = DEFAULT_K) -> OutcomeModel:
        """The model in ``path`` (default: the shipped ``primitives/weights/{skill}_outcome.npz``).

        Raises:
            WeightsError: the file is missing, unreadable, not a plain ``.npz``, lacks a column, holds bad values
                or was collected for another skill.
        """
        if skill not in SKILLS:
            raise InputError(f"unknown skill {skill!r}; expected one of {SKILLS}")
        path = Path(SHIPPED_DIR / f"{skill}_outcome.npz" if path is None else path)
        if not path.is_file():
            raise WeightsError(f"no {skill} outcome model at {str(path)!r} "
                               f"(python -m primitives.training.outcomes collect {skill} ... --out FILE)")
        if not zipfile.is_zipfile(path):
            raise WeightsError(f"{path} is not an outcome model: not an .npz file (damaged or another kind of file)")
        try:
            with np.load(path, allow_pickle=False) as f:
                missing = [c for c in REQUIRED if c not in f.files]
                if missing:
                    raise WeightsError(f"{path} is not an outcome model: it has no {', '.join(missing)}")
                stored = str(f["skill"]) if "skill" in f.files else skill
                cols = {c: np.array(f[c]) for c in REQUIRED}
                tips = {c: np.array(f[c]) for c in TIP_COLUMNS} if all(c in f.files for c in TIP_COLUMNS) else None
        except WeightsError:
            raise
        except (OSError, ValueError, zipfile.BadZipFile, EOFError, KeyError) as exc:
            raise WeightsError(f"{path} is not a readable outcome model ({type(exc).__name__}: {exc})") from exc
        if stored != skill:
            raise WeightsError(f"{path} is the {stored} outcome model, not {skill}'s")
        try:
            if tips is None:
                return cls(skill, cols["p"], cols["progress"], cols["made_progress"], k=k)
            return cls(skill, cols["p"], cols["progress"], cols["made_progress"], k=k,
                       state_probability=tips["state_probability"],
                       tipped=tips["state_before"] != tips["state_after"])
        except (InputError, ValueError, TypeError) as exc:
            raise WeightsError(f"{path} holds a damaged outcome model: {exc}") from exc

    def __len__(self) -> int:
        return len(self.p)

    def __repr__(self) -> str:
        return f"OutcomeModel({self.skill!r}, {len(self)} rollouts, k={self.k}{', tips' if self.knows_tips else ''})"

    def _check_p(self, p_strict) -> np.ndarray:
        q = np.asarray(p_strict, dtype=float)
        if not np.all(np.isfinite(q)) or np.any(q < 0.0) or np.any(q > 1.0):
            raise InputError(f"p_strict must be a probability in [0, 1], got {np.round(q, 3).tolist()}")
        return q

    def neighbours(self, p_strict: float) -> np.ndarray:
        """Indices (into the sorted rollouts) of the ``k`` whose ``p`` is nearest ``p_strict``: a window of the
        sorted ``p`` (ties broken towards lower ``p``)."""
        q = float(self._check_p(p_strict))
        window = _nearest_window(self.p, q, self.k)
        return np.arange(window.start, window.stop)

    def support(self, p_strict: float) -> np.ndarray:
        """The ``k`` progress values a query for ``p_strict`` resamples (equally likely)."""
        return self.progress[self.neighbours(p_strict)]

    def sample_progress(self, p_strict: float, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` progress samples (share of the asked effect; module docstring) for a call the success model rates
        ``p_strict``: the progress of the ``k`` rollouts nearest in ``p``, resampled with replacement."""
        values = self.support(p_strict)
        return values[rng.integers(len(values), size=int(n))]

    def p_progress(self, p_strict):
        """The share of the ``k`` rollouts nearest in ``p`` that made progress; a float, or an array for an array."""
        q = self._check_p(p_strict)
        out = np.array([self.made_progress[self.neighbours(v)].mean() for v in q.reshape(-1)]).reshape(q.shape)
        return float(out) if out.ndim == 0 else out

    def mean_progress(self, p_strict):
        """The mean progress of the ``k`` rollouts nearest in ``p``; a float, or an array for an array."""
        q = self._check_p(p_strict)
        out = np.array([self.support(v).mean() for v in q.reshape(-1)]).reshape(q.shape)
        return float(out) if out.ndim == 0 else out

    def progress_quantiles(self, p_strict, quantiles=(0.1, 0.9)) -> np.ndarray:
        """The ``quantiles`` of progress (``(..., len(quantiles))``) among the ``k`` rollouts nearest in ``p``
        (numpy's default, linear, interpolation)."""
        q = self._check_p(p_strict)
        out = np.array([np.quantile(self.support(v), quantiles) for v in q.reshape(-1)])
        return out.reshape(*q.shape, len(quantiles))

    def p_tip(self, state_probability):
        """The probability that a call made in a resting state with drop probability ``state_probability`` (in
        (0, 1]) leaves the object in another resting state: the share of the ``k`` rollouts nearest in log drop
        probability that did (module docstring). 0 for a roll (changing the state is its job; a roll into the
        wrong state is its progress of 0) and for a model that knows nothing of tips. A float, or an array for an
        array."""
        q = np.asarray(state_probability, dtype=float)
        if not np.all(np.isfinite(q)) or np.any(q <= 0.0) or np.any(q > 1.0):
            raise InputError(f"state_probability must lie in (0, 1], got {np.round(q, 3).tolist()}")
        if self.skill == "roll" or self._tipped is None:
            out = np.zeros(q.shape)
        else:
            keys, k = self._tip_log_prob, min(self.k, len(self._tipped))
            out = np.array([self._tipped[_nearest_window(keys, math.log(v), k)].mean() for v in q.reshape(-1)])
            out = out.reshape(q.shape)
        return float(out) if out.ndim == 0 else out


def _nearest_window(sorted_values: np.ndarray, x: float, k: int) -> slice:
    """The ``k`` consecutive entries of ``sorted_values`` nearest ``x`` (the window whose farthest entry is nearest;
    ties towards lower values)."""
    m = len(sorted_values)
    lo = int(np.clip(np.searchsorted(sorted_values, x) - k, 0, m - k))
    hi = min(lo + 2 * k, m)
    d = np.abs(sorted_values[lo:hi] - x)
    if hi - lo > k:
        lo += int(np.argmin(np.maximum(d[: hi - lo - k + 1], d[k - 1:])))
    return slice(lo, lo + k)
