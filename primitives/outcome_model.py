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

**Limits**: it conditions on ``p_strict`` only. The parameter is marginalised over the planner's distribution
(push direction: irrelevant by the table's symmetry; spin ``|angle|`` between 15 and 45 deg; roll target), and so
is the object (the collection's objects: procedural training objects and HACMan's training meshes), the start pose
and the sensor's noise. Successive calls on one object are treated as independent draws, though a call that failed
on an object is likelier to fail again. A few hundred rollouts resolve the distribution coarsely, least well at
high ``p`` where few rollouts lie (the ``k`` nearest then reach down to lower ``p``). ``python -m
primitives.training.outcomes check`` measures the intervals' coverage on unseen objects.
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import numpy as np

from affordplan.errors import InputError, WeightsError
from primitives.params import SKILLS
from primitives.weights_file import SHIPPED_DIR

DEFAULT_K = 60  # rollouts nearest in p that a query resamples
REQUIRED = ("p", "progress", "made_progress")


class OutcomeModel:
    """A skill's outcome model (module docstring): ``p`` and ``progress`` of collected rollouts, and whether each
    made progress.

    Args:
        skill: ``"push"``, ``"roll"`` or ``"spin"``.
        p: ``(m,)`` strict success probabilities the success model gave the rollouts.
        progress: ``(m,)`` the share of the asked effect each achieved.
        made_progress: ``(m,)`` bools; default ``progress >= 1`` for roll, ``progress > 0`` otherwise.
        k: rollouts nearest in ``p`` that a query takes (capped at ``m``).
    """

    def __init__(self, skill: str, p, progress, made_progress=None, k: int = DEFAULT_K):
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
        except WeightsError:
            raise
        except (OSError, ValueError, zipfile.BadZipFile, EOFError, KeyError) as exc:
            raise WeightsError(f"{path} is not a readable outcome model ({type(exc).__name__}: {exc})") from exc
        if stored != skill:
            raise WeightsError(f"{path} is the {stored} outcome model, not {skill}'s")
        try:
            return cls(skill, cols["p"], cols["progress"], cols["made_progress"], k=k)
        except (InputError, ValueError, TypeError) as exc:
            raise WeightsError(f"{path} holds a damaged outcome model: {exc}") from exc

    def __len__(self) -> int:
        return len(self.p)

    def __repr__(self) -> str:
        return f"OutcomeModel({self.skill!r}, {len(self)} rollouts, k={self.k})"

    def _check_p(self, p_strict) -> np.ndarray:
        q = np.asarray(p_strict, dtype=float)
        if not np.all(np.isfinite(q)) or np.any(q < 0.0) or np.any(q > 1.0):
            raise InputError(f"p_strict must be a probability in [0, 1], got {np.round(q, 3).tolist()}")
        return q

    def neighbours(self, p_strict: float) -> np.ndarray:
        """Indices (into the sorted rollouts) of the ``k`` whose ``p`` is nearest ``p_strict``: a window of the
        sorted ``p`` (ties broken towards lower ``p``)."""
        q = float(self._check_p(p_strict))
        m, k = len(self.p), self.k
        # the k nearest of a sorted array form a contiguous window [lo, lo + k); choose lo by two-pointer search
        lo = int(np.clip(np.searchsorted(self.p, q) - k, 0, m - k))
        hi = min(lo + 2 * k, m)
        d = np.abs(self.p[lo:hi] - q)
        # the window of k consecutive elements with the smallest largest distance
        if hi - lo > k:
            worst = np.maximum(d[: hi - lo - k + 1], d[k - 1:])
            lo += int(np.argmin(worst))
        return np.arange(lo, lo + k)

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
