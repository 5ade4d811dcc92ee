"""Skills (primitives.skills): acting and judging with given weights, the shipped weights offline, the arm (a contact
it cannot reach is masked out and the policy's next best one is tried), and skills loaded from a folder of weights."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch

import affordplan as ap
from affordplan.errors import InputError, ReachabilityError
from affordplan.sim.sensor import SENSORS
from primitives import load_skill, rewards, weights_file
from primitives import params as skill_params
from primitives import skills as skills_module
from primitives.frames import FrameSearch
from primitives.networks import HybridActorCritic
from primitives.params import as_params
from primitives.success_model import SuccessModel, load_success_net
from primitives.training.env import skill_observation


class _ReachLimited(ap.Simulator):
    """A finger simulator that refuses (before any physics, as the arm does) the first ``refuse`` contacts."""

    def __init__(self, *args, refuse: int, **kwargs):
        super().__init__(*args, **kwargs)
        self.refuse = refuse
        self.asked: list[np.ndarray] = []

    def execute(self, contact, motion, normal=None, until=None, steer=None, motion_steps=None):
        self.asked.append(np.asarray(contact, dtype=float))
        if len(self.asked) <= self.refuse:
            raise ReachabilityError("the arm cannot reach this contact (test)")
        return super().execute(contact, motion, normal=normal)


def test_an_unreachable_contact_gives_way_to_the_next_best_reachable_one(cube):
    sim = _ReachLimited(cube, seed=0, refuse=2)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    out = load_skill("push").execute(sim, {"direction": 0.0})
    assert len(sim.asked) == 3 and out.valid and isinstance(out.success, bool)
    assert np.allclose(out.contact, sim.asked[2])  # the third choice was executed
    # each retry is outside the masked neighbourhood of every contact refused before it
    for k in (1, 2):
        gaps = [np.linalg.norm(sim.asked[k] - sim.asked[j]) for j in range(k)]
        assert min(gaps) > skills_module.UNREACHABLE_RADIUS


def test_a_skill_gives_up_after_its_retries_with_the_reachability_error(cube):
    sim = _ReachLimited(cube, seed=0, refuse=10**6)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    with pytest.raises(ReachabilityError):
        load_skill("push").execute(sim, {"direction": 0.0})
    assert len(sim.asked) == skills_module.MAX_REACH_RETRIES + 1


class _DescentBlocked(ap.Simulator):
    """A finger simulator whose pusher cannot come down to the first ``block`` pre-contact points it is asked
    about (a wall over them, as the arm meets beside obstacles)."""

    def __init__(self, *args, block: int, **kwargs):
        super().__init__(*args, **kwargs)
        self.block = block
        self.checked: list[np.ndarray] = []
        self.executed: list[np.ndarray] = []

    def approach_clear(self, contact, normal):
        self.checked.append(np.asarray(contact, dtype=float))
        return len(self.checked) > self.block

    def execute(self, contact, motion, normal=None, until=None, steer=None, motion_steps=None):
        self.executed.append(np.asarray(contact, dtype=float))
        return super().execute(contact, motion, normal=normal)


def test_a_contact_the_pusher_cannot_come_down_to_gives_way_to_the_next_best_one(cube):
    """Blocked descents are refused before any physics, like unreachable contacts; after the retries, the last
    choice is executed as it is (its approach then fails without touching anything)."""
    sim = _DescentBlocked(cube, seed=0, block=2)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    out = load_skill("push").execute(sim, {"direction": 0.0})
    assert len(sim.checked) == 3 and len(sim.executed) == 1
    assert np.allclose(sim.executed[0], sim.checked[2]) and out.approach_ok
    assert min(np.linalg.norm(sim.checked[2] - c) for c in sim.checked[:2]) > skills_module.UNREACHABLE_RADIUS

    sim = _DescentBlocked(cube, seed=0, block=10**6)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    load_skill("push").execute(sim, {"direction": 0.0})
    assert len(sim.checked) == skills_module.MAX_REACH_RETRIES and len(sim.executed) == 1


def test_the_arm_sees_a_wall_over_a_pre_contact_point(cube):
    wall = ap.Box(center=(0.5, -0.09), size=(0.3, 0.02, 0.1))  # 4 cm from the cube's -y side
    sim = ap.Simulator(cube, obstacles=(wall,), pusher="arm", seed=0)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    side = np.array([0.5, -0.05, 0.05])
    assert not sim.approach_clear(side, np.array([0.0, -1.0, 0.0]))  # pre-contact point over the wall
    assert sim.approach_clear(np.array([0.45, 0.0, 0.05]), np.array([-1.0, 0.0, 0.0]))
    assert ap.Simulator(cube, obstacles=(wall,), seed=0).approach_clear(side, np.array([0.0, -1.0, 0.0]))


# ----------------------------------------------------------------------------- a folder of weights
def _copy_skill_files(name: str, folder, files=("{}.pt", "{}_success.pt", "{}_frames.json", "{}_success_searched.pt")):
    """The shipped files of skill ``name``, and its ratings for other sensors' clouds, into ``folder``."""
    for pattern in files:
        shutil.copyfile(skills_module.WEIGHTS_DIR / pattern.format(name), folder / pattern.format(name))
    for sensor in SENSORS:
        for pattern in files:
            source = skills_module.WEIGHTS_DIR / sensor / pattern.format(name)
            if source.exists():
                (folder / sensor).mkdir(exist_ok=True)
                shutil.copyfile(source, folder / sensor / pattern.format(name))


def test_a_weights_folder_stands_in_for_the_shipped_files_and_rates_and_acts_the_same(tmp_path, cube):
    _copy_skill_files("push", tmp_path)
    shipped, folder = load_skill("push"), load_skill("push", weights_dir=tmp_path)
    assert folder.frame_search == shipped.frame_search  # the folder's frames.json, loaded
    assert folder._searched_weights == tmp_path / "push_success_searched.pt"
    for a, b in zip(shipped.model.state_dict().values(), folder.model.state_dict().values(), strict=True):
        assert np.array_equal(a.numpy(), b.numpy())
    params = {"direction": 0.7}
    answers = []
    for skill in (shipped, folder):  # each on its own simulator in the same state (a query draws a cloud)
        sim = ap.Simulator(cube, seed=3)
        sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
        answers.append((skill.success_probability(sim, params), *skill.act(sim, params)))
    (p1, c1, m1), (p2, c2, m2) = answers
    assert p1 == pytest.approx(p2)
    np.testing.assert_allclose(c1, c2)
    np.testing.assert_allclose(m1, m2)


def test_a_weights_folder_without_a_skill_leaves_it_shipped(tmp_path):
    _copy_skill_files("push", tmp_path)
    spin = load_skill("spin", weights_dir=tmp_path)
    assert spin._searched_weights == skills_module.WEIGHTS_DIR / "spin_success_searched.pt"
    assert spin.frame_search == load_skill("spin").frame_search


def test_load_skills_takes_a_folder_skill_by_skill():
    # push files only, fitted before the lever arm
    kept = Path(__file__).resolve().parents[1] / "candidates" / "push_0.18"
    shipped, mixed = skills_module.load_skills(), skills_module.load_skills(kept)
    assert set(shipped) == set(mixed) == {"push", "roll", "spin"}
    assert shipped["push"].success_model.net.n_decision == 14 and mixed["push"].success_model.net.n_decision == 13
    assert mixed["push"]._searched_weights == kept / "push_success_searched.pt"
    for name in ("roll", "spin"):  # no files of theirs in the folder: shipped
        assert mixed[name]._searched_weights == shipped[name]._searched_weights
        assert mixed[name].frame_search == shipped[name].frame_search
    with pytest.raises(InputError, match="not a folder"):
        skills_module.load_skills(kept / "missing")


def test_a_weights_folder_is_refused_without_a_success_model_or_beside_other_files(tmp_path):
    _copy_skill_files("push", tmp_path, files=("{}.pt",))
    with pytest.raises(InputError, match="no success model beside it"):
        load_skill("push", weights_dir=tmp_path)
    with pytest.raises(InputError, match="not a folder"):
        load_skill("push", weights_dir=tmp_path / "missing")
    with pytest.raises(InputError, match="not both"):
        load_skill("push", weights=tmp_path / "push.pt", weights_dir=tmp_path)


def test_skill_acts_and_judges_with_given_weights(tmp_path):
    torch.manual_seed(0)
    weights_file.save(tmp_path / "w.pt", dict(model=HybridActorCritic().state_dict()),
                      weights_file.make_meta("push", "policy"))
    skill = load_skill("push", weights=tmp_path / "w.pt")
    sim = ap.Simulator(ap.load_object("cube"))
    sim.reset()
    contact, motion = skill.act(sim)
    assert contact.shape == (3,) and np.all(np.abs(motion) <= 1.0)
    out = skill.execute(sim)
    assert out.success == (out.valid and rewards_push_success(out))
    contact_dir, _ = skill.act(sim, params={"direction": 0.0})  # the goal flow changes the input
    assert contact_dir.shape == (3,)
    for bad in ({"direction": float("nan")}, {"angle": 0.3}, {"direction": "east"}, [0.0]):
        with pytest.raises(InputError):
            skill.act(sim, params=bad)
    with pytest.raises(InputError):
        load_skill("jump")


def rewards_push_success(out) -> bool:
    return rewards.push_success(out.pose_before, out.pose_after)


@pytest.mark.parametrize("name", ["push", "roll", "spin"])
def test_shipped_weights_load_offline_and_act(name):
    skill = load_skill(name)  # primitives/weights/NAME.pt, package data
    sim = ap.Simulator(ap.load_object("cube"), seed=3)
    sim.reset()
    contact, motion = skill.act(sim)
    assert np.all(np.isfinite(contact)) and np.all(np.abs(motion) <= 1.0)
    again = load_skill(name).act(ap.Simulator(ap.load_object("cube"), seed=3))
    assert np.array_equal(again[0], contact) and np.array_equal(again[1], motion)  # deterministic


# ----------------------------------------------------------------------------- ratings per sensor
def _own_ratings_only(skill: skills_module.Skill) -> skills_module.Skill:
    """``skill`` with the ratings shipped beside its policy alone (those fitted to the policy's own sensor)."""
    return skills_module.Skill(skill.name, skill.model, success_weights=skill._success_weights,
                               frame_search=skill.frame_search, searched_weights=skill._searched_weights)


def _rated(skill: skills_module.Skill, cube, sensor: str, params) -> tuple[float, np.ndarray]:
    """``skill``'s rating of ``params`` and its contact, on a fresh simulator of ``sensor`` in one fixed state."""
    sim = ap.Simulator(cube, seed=3, sensor=sensor)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    p = skill.success_probability(sim, params)
    sim = ap.Simulator(cube, seed=3, sensor=sensor)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    return p, skill.act(sim, params)[0]


def test_a_skill_rates_and_picks_with_the_ratings_fitted_to_its_simulators_sensor(cube):
    push = load_skill("push")  # push's ratings are shipped for its policy's sensor and, in cameras/, for cameras
    assert push.sensor == "surface" and push.rated_sensors == ("surface", "cameras")
    cameras = push.ratings("cameras")
    assert cameras.model is push.model and cameras._success_weights == skills_module.WEIGHTS_DIR / "cameras" / \
        "push_success.pt" and cameras.frame_search != push.frame_search
    assert push.ratings("surface") is push and push.ratings(None) is push
    own = _own_ratings_only(push)
    for params in ({"direction": 0.7}, None):
        p, contact = _rated(push, cube, "cameras", params)
        p_cameras, contact_cameras = _rated(cameras, cube, "cameras", params)
        assert p == pytest.approx(p_cameras) and np.allclose(contact, contact_cameras)
        assert p != pytest.approx(_rated(own, cube, "cameras", params)[0], abs=1e-3)  # the other files' rating
        p, contact = _rated(push, cube, "surface", params)  # a surface cloud: the files beside the policy
        p_own, contact_own = _rated(own, cube, "surface", params)
        assert p == pytest.approx(p_own) and np.allclose(contact, contact_own)
    sim = ap.Simulator(cube, seed=3)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    obs = push.observe(sim, {"direction": 0.0}).obs[None]
    np.testing.assert_allclose(push.success_probability_obs(obs, sensor="cameras"),
                               cameras.success_probability_obs(obs))
    np.testing.assert_allclose(push.success_probability_obs(obs), own.success_probability_obs(obs))
    np.testing.assert_allclose(push.success_spread_obs(obs, sensor="cameras"), cameras.success_spread_obs(obs))


def test_loading_a_skill_takes_its_policys_sensor_from_the_loaded_policy(monkeypatch):
    from primitives import weights_file

    def reread(*args, **kwargs):
        raise AssertionError("the policy's file was read again for its sensor")

    monkeypatch.setattr(weights_file, "policy_sensor", reread)
    push = load_skill("push")  # its camera ratings resolved with the loaded policy's sensor
    assert push.rated_sensors == ("surface", "cameras")


def test_a_weights_folder_gives_ratings_for_a_sensor_in_its_subfolder(tmp_path, cube):
    _copy_skill_files("push", tmp_path, files=("{}.pt", "{}_success.pt"))
    assert load_skill("push", weights_dir=tmp_path).rated_sensors == ("surface", "cameras")
    shutil.rmtree(tmp_path / "cameras")
    (tmp_path / "cameras").mkdir()  # an empty folder gives no ratings
    push = load_skill("push", weights_dir=tmp_path)
    assert push.rated_sensors == ("surface",) and push.ratings("cameras") is push
    # one rating refitted: the camera ratings take it, and the policy's own files for the others
    for own in ("push_frames.json", "push_success_searched.pt"):
        shutil.copyfile(skills_module.WEIGHTS_DIR / own, tmp_path / own)
    _perturbed_policy("push", tmp_path / "cameras" / "push_success_searched.pt", kind="success")
    push = load_skill("push", weights_dir=tmp_path)
    cameras = push.ratings("cameras")
    assert push.rated_sensors == ("surface", "cameras") and cameras is not push
    assert cameras._searched_weights == tmp_path / "cameras" / "push_success_searched.pt"
    assert cameras._success_weights == push._success_weights == tmp_path / "push_success.pt"
    assert cameras.frame_search == push.frame_search is not None
    sim = ap.Simulator(cube, seed=3)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    obs = push.observe(sim, {"direction": 0.0}).obs[None]  # rated by the searched model: the camera one differs
    assert push.success_probability_obs(obs, sensor="cameras") != pytest.approx(push.success_probability_obs(obs),
                                                                                abs=1e-3)
    roll = load_skill("roll")  # its camera frame search has no ranker
    assert roll.rated_sensors == ("surface", "cameras") and roll.ratings("cameras").frame_search.ranker is None
    assert load_skill("push", frame_search=False).rated_sensors == ("surface",)  # given files: those alone


def test_a_sensor_search_that_reports_its_own_rating_rates_without_a_searched_model(tmp_path, cube):
    _copy_skill_files("push", tmp_path)
    _perturbed_policy("push", tmp_path / "cameras" / "push_success_searched.pt", kind="success")
    frames = tmp_path / "cameras" / "push_frames.json"
    replace(FrameSearch.load(frames), reports_rating=False).save(frames)
    with_model = load_skill("push", weights_dir=tmp_path).ratings("cameras")
    assert with_model._searched_weights == tmp_path / "cameras" / "push_success_searched.pt"
    replace(FrameSearch.load(frames), reports_rating=True).save(frames)
    push = load_skill("push", weights_dir=tmp_path)
    cameras = push.ratings("cameras")
    assert cameras.searched_model is None and cameras.frame_search.reports_rating
    assert push.searched_model is not None  # the surface sample's ratings keep theirs

    def scanned():  # the same start and the same camera noise draws each time
        sim = ap.Simulator(cube, seed=3)
        sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
        return sim

    params = as_params("push", {"direction": 0.3})
    sim = scanned()
    seen = skill_observation(sim, "push", params, cameras.n_points)
    # what it reports: the search's calibrated rating of the frame it picks, not the searched model's answer
    p_search = float(cameras.frame_search.calibrate(cameras.frame_search.select(
        "push", seen, cameras.success_model.predict, sim, decide=cameras.success_model.rate_and_decide)[1]))
    reported = push.success_probability(scanned(), params)
    assert reported == pytest.approx(p_search, abs=1e-6)
    assert reported != pytest.approx(float(with_model.searched_model.predict(seen.obs)), abs=1e-3)
    shipped = load_skill("push").ratings("cameras")  # as shipped: chosen on validation objects (RECORD.md)
    assert shipped.frame_search.reports_rating and shipped.searched_model is None


def test_a_search_that_reports_its_rankers_score_rates_a_simulator_by_it_and_an_observation_by_the_searched_model(
        tmp_path, cube):
    _copy_skill_files("spin", tmp_path)
    shutil.copyfile(skills_module.WEIGHTS_DIR / "cameras" / "spin_ranker.pt", tmp_path / "cameras" / "spin_ranker.pt")
    frames = tmp_path / "cameras" / "spin_frames.json"
    replace(FrameSearch.load(frames), reports_rating=True, ranker_platt=(0.8, 0.3)).save(frames)
    cameras = load_skill("spin", weights_dir=tmp_path).ratings("cameras")
    assert cameras.frame_search.reports_ranking and cameras.searched_model is None

    def scanned():  # the same start and the same camera noise draws each time
        sim = ap.Simulator(cube, seed=3)
        sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
        return sim

    search, model = cameras.frame_search, cameras.success_model
    for params in (None, as_params("spin", {"angle": 0.5})):
        sim = scanned()
        seen = skill_observation(sim, "spin", params, cameras.n_points)
        q = search.select("spin", seen, model.predict, sim, decide=model.rate_and_decide)[1]
        assert 0.0 < q < 1.0
        assert cameras.success_probability(scanned(), params) == pytest.approx(float(search.calibrate(q)), abs=1e-6)
        # an observation alone (a planner's predicted cloud) is rated by the searched model
        searched = SuccessModel(cameras.model, load_success_net("spin", frames.with_name("spin_success_searched.pt")))
        assert np.allclose(cameras.success_probability_obs(seen.obs[None], params is not None),
                           searched.predict(seen.obs[None]), atol=1e-6)


def test_a_sensor_skill_of_another_name_or_with_sensors_of_its_own_is_refused():
    push, spin = load_skill("push"), load_skill("spin")
    with pytest.raises(InputError, match="must be a push skill"):
        skills_module.Skill("push", push.model, ratings_by_sensor={"cameras": skills_module.Skill("spin", spin.model)})
    inner = skills_module.Skill("push", push.model)
    nested = skills_module.Skill("push", push.model, ratings_by_sensor={"cameras": inner})
    with pytest.raises(InputError, match="without sensors of its own"):
        skills_module.Skill("push", push.model, ratings_by_sensor={"cameras": nested})


def _perturbed_policy(name: str, path: Path, seed: int = 0, kind: str = "policy") -> None:
    """The shipped policy of ``name`` (or its file of another ``kind``: ``"success"``, its searched model) with every
    weight nudged (a different network of the same shape), at ``path``."""
    source = f"{name}.pt" if kind == "policy" else weights_file.rating_name(name, "searched")
    payload, meta = weights_file.load(skills_module.WEIGHTS_DIR / source, kind=kind, skill=name)
    generator = torch.Generator().manual_seed(seed)
    state = {key: value + 0.05 * value.std().nan_to_num() * torch.randn(value.shape, generator=generator)
             if value.is_floating_point() and value.numel() > 1 else value for key, value in payload["model"].items()}
    weights_file.save(path, dict(payload, model=state), meta)


def test_a_sensor_folder_with_a_policy_of_its_own_acts_and_rates_on_that_sensors_clouds_with_it(tmp_path, cube):
    _copy_skill_files("push", tmp_path, files=("{}.pt", "{}_success.pt"))
    shutil.rmtree(tmp_path / "cameras")
    (tmp_path / "cameras").mkdir()
    _perturbed_policy("push", tmp_path / "cameras" / "push.pt")
    with pytest.raises(InputError, match="no success model beside it"):  # ratings fitted to another policy: refused
        load_skill("push", weights_dir=tmp_path)
    shutil.copyfile(skills_module.WEIGHTS_DIR / "cameras" / "push_success.pt", tmp_path / "cameras" / "push_success.pt")
    push = load_skill("push", weights_dir=tmp_path)
    cameras = push.ratings("cameras")
    assert push.rated_sensors == ("surface", "cameras") and cameras.model is not push.model
    assert cameras._success_weights == tmp_path / "cameras" / "push_success.pt"
    assert cameras.frame_search is None and cameras._searched_weights is None  # its folder's alone: none
    assert weights_file.policy_path("push", "cameras", tmp_path) == tmp_path / "cameras" / "push.pt"
    assert weights_file.policy_path("push", "surface", tmp_path) == tmp_path / "push.pt"
    assert weights_file.sensor_policy("push", "cameras", tmp_path) == tmp_path / "cameras" / "push.pt"
    assert weights_file.sensor_policy("push", "surface", tmp_path) is None
    assert weights_file.sensor_policy("push", None, tmp_path) is None
    assert weights_file.rating_path("push", "frames", "cameras", tmp_path) == tmp_path / "cameras" / "push_frames.json"
    alone = skills_module.Skill("push", cameras.model, success_weights=tmp_path / "cameras" / "push_success.pt")
    moved = []
    for params in ({"direction": 0.7}, {"direction": -2.0}, None):
        p, contact = _rated(push, cube, "cameras", params)  # a camera cloud: the folder's policy and its rating
        p_alone, contact_alone = _rated(alone, cube, "cameras", params)
        assert p == pytest.approx(p_alone) and np.allclose(contact, contact_alone)
        p, contact = _rated(push, cube, "surface", params)  # a surface cloud: the policy beside the ratings
        p_own, contact_own = _rated(_own_ratings_only(push), cube, "surface", params)
        assert p == pytest.approx(p_own) and np.allclose(contact, contact_own)
        moved.append(not np.allclose(_rated(alone, cube, "surface", params)[1], contact_own))
    sim = ap.Simulator(cube, seed=3, sensor="cameras")
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    out = push.execute(sim, {"direction": 0.7})
    sim_alone = ap.Simulator(cube, seed=3, sensor="cameras")
    sim_alone.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    out_alone = alone.execute(sim_alone, {"direction": 0.7})
    np.testing.assert_allclose(out.pose_after, out_alone.pose_after)
    obs = push.observe(sim, {"direction": 0.0}).obs[None]
    np.testing.assert_allclose(push.success_probability_obs(obs, sensor="cameras"), alone.success_probability_obs(obs))
    assert any(moved)  # the folder's policy is another policy: it picks another contact on some of these clouds


def test_a_sensor_folder_policy_serves_that_sensor_even_where_the_main_policy_was_trained_on_it(tmp_path, cube):
    _copy_skill_files("push", tmp_path, files=("{}.pt", "{}_success.pt"))
    shutil.rmtree(tmp_path / "cameras")
    (tmp_path / "surface").mkdir()  # the main push.pt was trained on the surface sample
    _perturbed_policy("push", tmp_path / "surface" / "push.pt")
    shutil.copyfile(skills_module.WEIGHTS_DIR / "push_success.pt", tmp_path / "surface" / "push_success.pt")
    push = load_skill("push", weights_dir=tmp_path)
    assert push.sensor == "surface" and push.ratings("surface").model is not push.model
    alone = skills_module.Skill("push", push.ratings("surface").model,
                                success_weights=tmp_path / "surface" / "push_success.pt")
    p, contact = _rated(push, cube, "surface", {"direction": 0.7})
    p_alone, contact_alone = _rated(alone, cube, "surface", {"direction": 0.7})
    assert p == pytest.approx(p_alone) and np.allclose(contact, contact_alone)


class _Recording(ap.Simulator):
    """A finger simulator that records the ``until`` and ``steer`` each primitive is given."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.untils: list = []
        self.steers: list = []
        self.motion_steps: list = []

    def execute(self, contact, motion, normal=None, until=None, steer=None, motion_steps=None):
        self.untils.append(until)
        self.steers.append(steer)
        self.motion_steps.append(motion_steps)
        return super().execute(contact, motion, normal=normal, until=until, steer=steer, motion_steps=motion_steps)


def test_a_spin_by_an_angle_stops_at_it_unless_told_to_run_its_full_motion(lunch_box):
    import math

    spin = load_skill("spin")
    sim = _Recording(lunch_box, seed=0)
    for stop in (True, False):
        sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
        spin.execute(sim, {"angle": math.radians(30.0)}, stop_at_angle=stop)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    spin.execute(sim, None)  # the seed's objective: no angle to stop at
    assert callable(sim.untils[0]) and sim.untils[1] is None and sim.untils[2] is None
    assert sim.steers == [None, None, None]  # spins run straight


def test_a_push_steers_against_the_turn_unless_told_to_push_straight(cube):
    push = load_skill("push")
    sim = _Recording(cube, seed=0)
    for asked, steer in ((None, True), ({"direction": 0.3}, True), (None, False)):
        sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
        push.execute(sim, asked, steer=steer)
    assert callable(sim.steers[0]) and callable(sim.steers[1]) and sim.steers[2] is None
    # a steered push goes on until the object has travelled far enough; a straight one runs the protocol's motion
    assert callable(sim.untils[0]) and callable(sim.untils[1]) and sim.untils[2] is None
    assert sim.motion_steps == [skill_params.PUSH_REACH_STEPS, skill_params.PUSH_REACH_STEPS, None]
