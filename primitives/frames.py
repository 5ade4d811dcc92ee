"""Acting in the likeliest of the goal frames a request leaves free (test-time frame selection).

The goal frame (:func:`primitives.params.goal_frame`) fixes what a parameter asks for and nothing else. What it
leaves free are symmetries of the table (friction is isotropic; the physics does not change when the scene turns
about the vertical or is mirrored through a vertical plane):

- spin with an angle: any turn about the vertical (the mirror is taken: it makes every spin counter-clockwise);
- push with a direction, roll to a target: the mirror ``y -> -y`` (the turn is taken: it aims the request at +x);
- the seed's objective (no parameter): any turn, and the mirror.

The policy is a point-cloud network trained from samples, so it is not invariant under these frames. Its success
on one start differs with the frame it sees the start in: the spin success model gives the same 35 deg spin of
one held-out object 0.63 at yaw 0 and 0.02 at yaw 1 rad. Each frame shows the policy a start it could equally
have met in training (the same object turned, or mirrored), so a skill may evaluate ``n`` of them with its
success model in one batch and act in the likeliest. The policy and the success model stay as trained.

A frame is a 3x3 map ``B`` applied on top of the goal frame: ``A_frame_world' = B A_frame_world``. Every feature
block of an observation (position, normal, goal flow) is a vector in the frame, so re-framing is one matrix
product per block (:func:`reframe`).

**Stand-in requests** (``FrameSearch.stand_ins``). The seed's objective asks for less than some requests do: a
push that moved 5 cm within 15 deg of an asked direction without turning 5 deg met the seed's push criterion too;
a spin that turned within 10 deg of 40 or 45 deg turned the seed's 30; a roll into a neighbouring resting state
tips the object about a horizontal axis, as the seed's roll criterion asks (by at least 60 deg where the state's
dihedral angle is that large, as on most objects). So a search for the seed's objective may also try the policy
*as if asked* for each such request, in that request's free frames, and act on the option rated likeliest: push
``stand_ins`` evenly spaced directions, spin 40 and 45 deg each way, roll every state one roll away. The outcome
is still judged by the seed's criterion. The policies were trained mostly on requests (70-85 % of episodes), and
the push conditioned on a direction pushes straighter than unconditioned. On 200 held-out starts: push
0.52 -> 0.685, roll 0.80 -> 0.855 (0.13), spin 0.81 -> 0.85 (0.14).

Options of the two kinds are compared on one scale: each option's best frame rating calibrated for its kind
(``platt`` for a request, ``platt_unparameterised`` for the seed's own observation; the goal-frame success model
rates the two kinds with different biases: roll's best unconditioned rating is far too high). The chosen score
gets a calibration of its own, ``platt_stand_ins``.

**Calibration.** The success model was calibrated on starts in one frame; the best of ``m`` ratings is biased
upwards (it picks the frames the model over-rates as well as those that are good). :class:`FrameSearch` therefore
carries a Platt scaling of the chosen rating, ``sigmoid(a logit(p) + b)``, fitted on frame-searched rollouts of
training objects (``python -m primitives.success frames``) and shipped beside the skill's weights as
``weights/{skill}_frames.json``.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from scipy.special import expit, logit

from affordplan.checks import is_whole, require_whole
from affordplan.errors import InputError
from affordplan.geometry import rot_z
from primitives import params as skill_params
from primitives.observation import OBS_DIM, SkillObservation, observe_cloud
from primitives.option_ranker import OptionRanker, cloud_extents, load_ranker, option_features, request_size
from primitives.weights_file import rating_path

if TYPE_CHECKING:
    from affordplan.sim import Simulator

MIRROR_Y = np.diag([1.0, -1.0, 1.0])


def rating_logit(p: np.ndarray | float) -> np.ndarray:
    """``logit(p)`` of success ratings, clipped to ``[1e-6, 1 - 1e-6]`` first (a rating of 0 or 1 stays finite)."""
    return logit(np.clip(np.asarray(p, dtype=float), 1e-6, 1.0 - 1e-6))


def free_frames(skill: str, params: dict | None, n_turns: int, mirror: bool) -> np.ndarray:
    """The frames ``B`` (``(m, 3, 3)``, the identity first) the request of ``skill`` leaves free.

    ``n_turns``: turns about the vertical to try where a turn is free, evenly spaced (1: none). ``mirror``: also
    try the mirror of each, where it is free.
    """
    require_whole("n_turns", n_turns, 1)
    turn_free = params is None or skill == "spin"
    mirror_free = mirror and (params is None or skill != "spin")
    turns = [rot_z(2.0 * math.pi * k / n_turns) for k in range(n_turns if turn_free else 1)]
    frames = turns + ([MIRROR_Y @ R for R in turns] if mirror_free else [])
    return np.stack(frames)


def reframe_obs(obs: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """Observations ``(..., N, 9)`` seen in each of ``frames`` (``(m, 3, 3)``): ``(..., m, N, 9)`` float32."""
    obs = np.asarray(obs, dtype=np.float32)
    blocks = obs.reshape(*obs.shape[:-1], OBS_DIM // 3, 3)  # (..., N, 3, 3): position, normal, flow
    out = np.einsum("mij,...nbj->...mnbi", frames.astype(np.float32), blocks)
    return out.reshape(*obs.shape[:-2], len(frames), obs.shape[-2], OBS_DIM).astype(np.float32)


def reframe(seen: SkillObservation, B: np.ndarray) -> SkillObservation:
    """``seen`` with its goal frame followed by ``B``: the same cloud and request, the policy's input re-expressed."""
    obs = reframe_obs(seen.obs, np.asarray(B, dtype=float)[None])[0]
    return replace(seen, obs=obs, A_frame_world=np.asarray(B, dtype=float) @ seen.A_frame_world)


def select_frame(seen: SkillObservation, predict, frames: np.ndarray) -> tuple[SkillObservation, float]:
    """``seen`` in the frame of ``frames`` that ``predict`` (observations ``(m, N, 9)`` -> P(success) ``(m,)``)
    rates likeliest, and that rating."""
    if len(frames) == 1:
        return seen, float(predict(seen.obs[None])[0])
    p = np.asarray(predict(reframe_obs(seen.obs, frames)))
    best = int(np.argmax(p))
    return reframe(seen, frames[best]), float(p[best])


SPIN_STAND_INS = np.radians([40.0, 45.0])  # spin angles whose success (within 10 deg) turned at least 30 deg


def stand_in_requests(skill: str, n: int, obj, state: int) -> list[dict]:
    """The requests whose success meets the seed's objective for ``skill`` that a search with ``n`` stand-ins
    tries (module docstring): push ``n`` directions evenly spaced from -pi (radians); spin ``SPIN_STAND_INS``
    each way and roll each target state one roll away from ``state``, for any ``n > 0``. Empty for ``n == 0``."""
    if n <= 0:
        return []
    if skill == "push":
        return [{"direction": -math.pi + 2.0 * math.pi * k / n} for k in range(n)]
    if skill == "spin":
        return [{"angle": float(sense * a)} for sense in (1.0, -1.0) for a in SPIN_STAND_INS]
    return [{"target": t} for t in skill_params.roll_targets(obj, state)]


def _all_frames(options: list[tuple[SkillObservation, np.ndarray]]) -> np.ndarray:
    """Every option's observation in each of its frames, one batch ``(m, N, 9)`` in the options' order."""
    return np.concatenate([reframe_obs(o.obs, f) for o, f in options])


def _per_option(values: np.ndarray, options: list[tuple[SkillObservation, np.ndarray]]) -> list[np.ndarray]:
    """``values`` of a batch of :func:`_all_frames` split back into one array per option (one value per frame)."""
    return np.split(values, np.cumsum([len(f) for _, f in options])[:-1])


@dataclass(frozen=True)
class FrameSearch:
    """Which free frames a skill tries, and the calibration of the chosen frame's rating.

    ``turns``: turns about the vertical where the turn is free (1: none); ``mirror``: the mirror too, where it is
    free; ``platt``: ``(a, b)`` of ``sigmoid(a logit(p) + b)`` on the best rating ``p`` of a request with a
    parameter, ``platt_unparameterised`` the same for the seed's objective (which leaves more frames free, so its
    best rating is biased more); ``(1, 0)``: none. ``stand_ins``: for the seed's objective, also try the
    stand-in requests (:func:`stand_in_requests`; push: that many directions, a multiple of ``turns`` so that
    the set tried is the same from every frame; spin, roll: any number > 0; 0: none), and calibrate the chosen
    score with ``platt_stand_ins`` instead of ``platt_unparameterised``. ``info``: how the calibration was made
    (command, figures). ``ranker``: an :class:`~primitives.option_ranker.OptionRanker` that picks the option to
    act in for the seed's objective instead of the ratings (:meth:`ranks`, :meth:`choose`), loaded from the file
    ``ranker_file`` names beside the JSON file (:meth:`load`); ``None``: the ratings pick. ``reports_rating``: the
    skill reports this search's own calibrated rating of the option it picks as its success probability, and
    no searched success model (:func:`primitives.skills.load_skill`), where that was chosen on validation objects
    (push's search for camera clouds: ``primitives/weights/RECORD.md``); ``False``: a searched model where one ships.
    ``ranker_platt``: ``(a, b)`` of ``sigmoid(a logit(q) + b)`` on the ranker's score ``q`` of the option it picks
    (:func:`primitives.training.ranker.calibrate`); where set, a search with a ranker scores its pick by that
    calibrated score instead of the success model's rating (:meth:`choose`, :meth:`calibrate`); ``None``: the rating.
    """

    turns: int = 1
    mirror: bool = False
    platt: tuple[float, float] = (1.0, 0.0)
    platt_unparameterised: tuple[float, float] = (1.0, 0.0)
    info: dict = field(default_factory=dict, compare=False)
    stand_ins: int = 0
    platt_stand_ins: tuple[float, float] = (1.0, 0.0)
    reports_rating: bool = False
    ranker_file: str = ""
    ranker: OptionRanker | None = field(default=None, compare=False, repr=False)
    ranker_platt: tuple[float, float] | None = None

    def __post_init__(self):
        free_frames("spin", None, self.turns, self.mirror)  # checks turns
        if bool(self.ranker_file) != (self.ranker is not None):
            raise InputError("a FrameSearch names a ranker file exactly when it carries a ranker")
        if not is_whole(self.stand_ins) or self.stand_ins < 0 or (self.stand_ins and self.stand_ins % self.turns):
            raise InputError(f"stand_ins must be 0 or a whole multiple of turns ({self.turns}), got {self.stand_ins!r}")
        for ab in (self.platt, self.platt_unparameterised, self.platt_stand_ins, self.ranker_platt or (1.0, 0.0)):
            if len(ab) != 2 or not all(math.isfinite(v) for v in ab):
                raise InputError(f"a FrameSearch Platt scaling must be two finite numbers, got {ab!r}")

    def frames(self, skill: str, params: dict | None) -> np.ndarray:
        return free_frames(skill, params, self.turns, bool(self.mirror))

    def tries_stand_ins(self, params: dict | None) -> bool:
        """Whether this search tries stand-in requests for ``params`` (the seed's objective, with ``stand_ins``)."""
        return params is None and self.stand_ins > 0

    @property
    def reports_ranking(self) -> bool:
        """Whether this search scores the option it picks by its ranker's calibrated score (``ranker_platt`` set and
        a ranker carried; the ranker then picks for every request, :meth:`ranks`)."""
        return self.ranker is not None and self.ranker_platt is not None

    def ranks(self, params: dict | None) -> bool:
        """Whether this search's ranker picks the option for ``params``: wherever the search has a ranker, for the
        seed's objective (``None``) and for a request with a parameter alike.

        Spin's ranker was fitted on the seed's objective, whose options include stand-in spins by an angle; since a
        spin by an angle ends its motion at the angle (:func:`primitives.params.motion_stop`), what it needs of an
        option, a turn about the vertical at least that far, is what that ranker predicts. On 240
        ``housekeep:validation`` starts (camera clouds) it lifts spin by an asked angle from 0.679 with the ratings'
        pick to 0.742, and the procedural test split from 0.652 to 0.705 (600 starts); a ranker fitted to spins by an
        angle before the stop picked no better than the ratings (``primitives/weights/RECORD.md``)."""
        return self.ranker is not None

    def searches(self, skill: str, params: dict | None) -> bool:
        """Whether a request ``params`` of ``skill`` leaves this search more than one option to rate."""
        return len(self.frames(skill, params)) > 1 or self.tries_stand_ins(params)

    def options(self, skill: str, seen: SkillObservation, sim: Simulator) -> list[tuple[SkillObservation, np.ndarray]]:
        """What this search rates for ``seen`` (of ``sim``'s current cloud): pairs of an observation and its free
        frames ``(m, 3, 3)``, the request itself first, then for the seed's objective with stand-ins each stand-in
        request (:func:`stand_in_requests`) observed on the same cloud."""
        options = [(seen, self.frames(skill, seen.params))]
        if self.tries_stand_ins(seen.params):
            T_world_object = sim.object_pose()
            state = sim.obj.classify(T_world_object)
            for request in stand_in_requests(skill, self.stand_ins, sim.obj, state):
                request = skill_params.check(skill, request, sim.obj, state)
                asked = observe_cloud(sim.obj, skill, request, seen.points, seen.normals, T_world_object)
                options.append((asked, self.frames(skill, request)))
        return options

    @staticmethod
    def rate(options: list[tuple[SkillObservation, np.ndarray]], predict) -> list[np.ndarray]:
        """Each option's ratings, one per frame, from one batch of ``predict`` (observations ``(m, N, 9)`` ->
        P(success) ``(m,)``)."""
        return _per_option(np.asarray(predict(_all_frames(options)), dtype=float), options)

    @staticmethod
    def rate_and_decide(options: list[tuple[SkillObservation, np.ndarray]],
                        decide) -> tuple[list[np.ndarray], np.ndarray]:
        """Each option's ratings (split as :meth:`rate` splits them) and the policy's decision features in each
        option's frame ``(m, 14)``, from one batch of ``decide`` (observations ``(m, N, 9)`` -> ``(P(success) (m,),
        decision features (m, 14))``, e.g. :meth:`primitives.success_model.SuccessModel.rate_and_decide`)."""
        p, decision = decide(_all_frames(options))
        return _per_option(np.asarray(p, dtype=float), options), decision

    def rank(self, skill: str, options: list[tuple[SkillObservation, np.ndarray]], ratings: list[np.ndarray],
             decision: np.ndarray) -> list[np.ndarray]:
        """This search's ranker's P(success) of each option's frames (split as ``ratings``), from the policy's
        ``decision`` features in each (:meth:`rate_and_decide`; :mod:`primitives.option_ranker`). Raises
        :class:`InputError` without a ranker."""
        if self.ranker is None:
            raise InputError("this frame search has no option ranker")
        kinds = [(o.params, k > 0) for k, (o, f) in enumerate(options) for _ in range(len(f))]
        features = option_features(np.asarray(decision), np.concatenate(ratings),
                                   np.array([request_size(skill, p) for p, _ in kinds]),
                                   np.array([p is not None for p, _ in kinds]), np.array([s for _, s in kinds]),
                                   cloud_extents(options[0][0].obs[:, :3]))
        return _per_option(self.ranker.score(features), options)

    def choose(self, options: list[tuple[SkillObservation, np.ndarray]], ratings: list[np.ndarray],
               ranking: list[np.ndarray] | None = None) -> tuple[int, int, float]:
        """The option and frame to act in, ``(k, j)``, given each option's ratings (one per frame), and its score:
        the best raw rating of the one option, or among several the option whose best rating, calibrated for its
        kind, is highest (module docstring), and that calibrated rating.

        ``ranking`` (:meth:`rank`, split as ``ratings``): act in the frame it ranks highest instead; the score is
        still that frame's rating, raw for one option or calibrated for its kind among several, or with
        ``ranker_platt`` the ranker's own score of it (raw: :meth:`calibrate` scales it)."""
        if ranking is not None:
            k = int(np.argmax([q.max() for q in ranking]))
            j = int(np.argmax(ranking[k]))
            if self.reports_ranking:
                return k, j, float(ranking[k][j])
            p = float(ratings[k][j])
            return k, j, p if len(options) == 1 else float(self.calibrate_kind(p, options[k][0].params is not None))
        best = [int(np.argmax(q)) for q in ratings]
        if len(options) == 1:
            return 0, best[0], float(ratings[0][best[0]])
        score = [float(self.calibrate_kind(q[b], option.params is not None)) for q, b, (option, _) in
                 zip(ratings, best, options)]
        k = int(np.argmax(score))
        return k, best[k], score[k]

    @staticmethod
    def acting(options: list[tuple[SkillObservation, np.ndarray]], k: int, j: int) -> SkillObservation:
        """The observation a skill acts on in option ``k``'s frame ``j``: the first option's request, or a stand-in
        request's observation with ``params`` ``None`` (the outcome is judged by the seed's objective) and
        ``acted_as`` naming the request."""
        option, frames = options[k]
        chosen = reframe(option, frames[j])
        return replace(chosen, params=None, acted_as=option.params) if k else chosen

    def select(self, skill: str, seen: SkillObservation, predict, sim: Simulator,
               decide=None) -> tuple[SkillObservation, float]:
        """The observation to act on and its score: ``seen`` (of ``sim``'s current cloud) in the free frame, or
        for the seed's objective with stand-ins the free frame of the stand-in request, that ``predict``
        (observations ``(m, N, 9)`` -> P(success) ``(m,)``) rates likeliest, all in one batch
        (:meth:`options`, :meth:`rate`, :meth:`choose`).

        The returned observation keeps ``seen.params`` (what the outcome is judged by); ``acted_as`` names the
        stand-in request where one was chosen. The score is the best raw rating, or with stand-ins the best rating
        calibrated for its kind (module docstring); :meth:`calibrate` it with ``seen.params is not None``.

        Where the ranker picks (:meth:`ranks`), ``decide`` is required: the ratings and the policy's decision
        features in one pass (:meth:`rate_and_decide`), which the ranker reads (:meth:`rank`); it rates in place
        of ``predict`` there.
        """
        if self.ranks(seen.params):
            if decide is None:
                raise InputError("a frame search with an option ranker needs decide (the ratings and the policy's "
                                 "decisions) to select")
            options = self.options(skill, seen, sim)
            ratings, decision = self.rate_and_decide(options, decide)
            k, j, score = self.choose(options, ratings, self.rank(skill, options, ratings, decision))
            return self.acting(options, k, j), score
        if not self.tries_stand_ins(seen.params):
            return select_frame(seen, predict, self.frames(skill, seen.params))
        options = self.options(skill, seen, sim)
        k, j, score = self.choose(options, self.rate(options, predict))
        return self.acting(options, k, j), score

    def calibrate_kind(self, p: np.ndarray | float, parameterised: np.ndarray | bool) -> np.ndarray:
        """The best rating ``p`` of an option calibrated for its kind: ``platt`` for a request with a parameter,
        ``platt_unparameterised`` for the seed's own observation (the scale :meth:`choose` compares options on)."""
        (a, b), (a0, b0) = self.platt, self.platt_unparameterised
        par = np.asarray(parameterised, dtype=bool)
        return expit(np.where(par, a, a0) * rating_logit(p) + np.where(par, b, b0))

    def calibrate(self, p: np.ndarray | float, parameterised: np.ndarray | bool = True) -> np.ndarray:
        """The calibrated probability of the scores ``p`` (:meth:`select`) of requests with (or without) a
        parameter; ``parameterised`` is one flag for all, or one per score. Where the search scores its pick by the
        ranker (:attr:`reports_ranking`), every score is the ranker's, scaled by ``ranker_platt``."""
        if self.reports_ranking:
            a, b = self.ranker_platt
            return expit(a * rating_logit(p) + b)
        if not self.stand_ins:
            return self.calibrate_kind(p, parameterised)
        a, b = self.platt_stand_ins
        return np.where(parameterised, self.calibrate_kind(p, True), expit(a * rating_logit(p) + b))

    def save(self, path: str | os.PathLike) -> None:
        """Write this search as JSON (a ranker is not written: ``ranker_file`` names its file beside ``path``)."""
        d = asdict(replace(self, ranker=None, ranker_file=""))
        for key in ("platt", "platt_unparameterised", "platt_stand_ins"):
            d[key] = list(d[key])
        del d["ranker"], d["ranker_file"]
        if not self.reports_rating:  # written only where set, as files before it had no such key
            del d["reports_rating"]
        if self.ranker_platt is None:
            del d["ranker_platt"]
        else:
            d["ranker_platt"] = list(self.ranker_platt)
        if self.ranker_file:
            d["ranker"] = self.ranker_file
        Path(path).write_text(json.dumps(d, indent=2) + "\n")

    @classmethod
    def load(cls, path: str | os.PathLike, ranked: bool = True) -> FrameSearch:
        """A frame search from a JSON file (raises :class:`InputError` for an unreadable one). ``ranked=False``:
        without the ranker it names (neither loaded nor kept), as when a new ranker replaces it."""
        try:
            d = json.loads(Path(path).read_text())
            ranker_file = str(d.get("ranker", ""))
            search = cls(int(d["turns"]), bool(d["mirror"]), tuple(float(v) for v in d["platt"]),
                         tuple(float(v) for v in d.get("platt_unparameterised", (1.0, 0.0))), d.get("info", {}),
                         int(d.get("stand_ins", 0)), tuple(float(v) for v in d.get("platt_stand_ins", (1.0, 0.0))),
                         reports_rating=_flag(d.get("reports_rating", False)),
                         ranker_platt=(tuple(float(v) for v in d["ranker_platt"]) if "ranker_platt" in d else None))
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise InputError(f"frame search file {path} is unreadable ({type(exc).__name__}: {exc})") from exc
        if not ranker_file or not ranked:
            return search
        if Path(ranker_file).name != ranker_file:
            raise InputError(f"frame search file {path} names its ranker {ranker_file!r}; it must be a file name "
                             f"beside it")
        return replace(search, ranker_file=ranker_file, ranker=load_ranker(Path(path).parent / ranker_file))


def _flag(value: object) -> bool:
    """A JSON true or false (raises ``TypeError`` for anything else, which :meth:`FrameSearch.load` reports)."""
    if not isinstance(value, bool):
        raise TypeError(f"expected true or false, got {value!r}")
    return value


def shipped_frame_search(name: str, weights_dir: str | os.PathLike | None = None,
                         sensor: str | None = None, *, trained_on: str | None = None,
                         ranked: bool = True) -> FrameSearch | None:
    """The frame search shipped beside a skill's weights (``{weights_dir}/{name}_frames.json``, by default the
    package's ``weights/``; for ``sensor``'s clouds where one was fitted to them,
    :func:`primitives.weights_file.rating_path`, ``trained_on`` as there), if any; ``ranked`` as
    :meth:`FrameSearch.load`."""
    path = rating_path(name, "frames", sensor, weights_dir, trained_on=trained_on)
    return FrameSearch.load(path, ranked) if path.exists() else None


def load_frame_search(skill: str, frames: str | os.PathLike, sensor: str | None = None,
                      ranked: bool = True) -> FrameSearch:
    """``"shipped"``: the frame search shipped beside ``skill``'s weights (for ``sensor``'s clouds); else the
    frames.json at ``frames``; ``ranked=False``: without its ranker (:meth:`FrameSearch.load`). Raises
    :class:`InputError` where none is shipped or the file is unreadable."""
    search = (shipped_frame_search(skill, sensor=sensor, ranked=ranked) if str(frames) == "shipped"
              else FrameSearch.load(frames, ranked))
    if search is None:
        raise InputError(f"no frame search is shipped for {skill}")
    return search
