"""Shipping a candidate set (primitives.research.ship):
the old files are kept, the new ones copied with their provenance
relabelled and their weights untouched, and a set fitted with other files is refused before anything moves."""

import hashlib
import json
import shutil
from pathlib import Path

import pytest
import torch

from affordplan.errors import InputError
from primitives import load_skill, weights_file
from primitives.research.ship import main, plan_ship, portable, ship
from primitives.weights_file import SHIPPED_DIR as WEIGHTS_DIR

CANDIDATES = Path(__file__).resolve().parents[1] / "candidates"

CORE = ("push.pt", "push_success.pt", "push_frames.json", "push_success_searched.pt")


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def set_info(path: Path, **values) -> None:
    if path.suffix == ".json":
        data = json.loads(path.read_text())
        data["info"].update(values)
        path.write_text(json.dumps(data))
    else:
        content = weights_file.read(path)
        content["payload"]["info"].update(values)
        weights_file.save(path, content["payload"], content["meta"])


@pytest.fixture
def layout(tmp_path):
    """A weights folder holding the shipped push, and a candidate set (the 0.16 push) whose fitted files name
    run paths under ``base``, as a fresh refit's would."""
    weights, cand, base = tmp_path / "weights", tmp_path / "cand", tmp_path / "base"
    weights.mkdir()
    cand.mkdir()
    for name in CORE + ("push_log.csv",):
        shutil.copy2(WEIGHTS_DIR / name, weights / name)
    for name in CORE + ("push.eval_seed7.json",):
        shutil.copy2(CANDIDATES / "push_0.16" / name, cand / name)
    runs = {"policy": "runs/p/policy.pt", "model": "runs/s/success.pt", "frames": "runs/f/frames.json"}
    for role, own in (("policy", "push.pt"), ("model", "push_success.pt"), ("frames", "push_frames.json")):
        (base / runs[role]).parent.mkdir(parents=True)
        shutil.copy2(cand / own, base / runs[role])
    set_info(cand / "push_success.pt", policy=runs["policy"])
    set_info(cand / "push_frames.json", policy=runs["policy"], model=runs["model"])
    set_info(cand / "push_success_searched.pt", **runs)
    # the run files of the two fitted-with files now differ from the set's (their info changed): refresh them
    shutil.copy2(cand / "push_success.pt", base / runs["model"])
    shutil.copy2(cand / "push_frames.json", base / runs["frames"])
    return weights, cand, base, runs


def test_shipping_keeps_the_old_files_and_relabels_the_new(layout):
    weights, cand, base, runs = layout
    old = {p.name: digest(p) for p in weights.iterdir()}
    plan = plan_ship("push", cand, "push_old", weights_dir=weights, base=base)
    assert len(plan.checked) == 6 and not plan.unchecked  # policy x3, model x2, frames x1
    ship(plan, "9.9.9")

    kept = base / "candidates" / "push_old"
    assert {p.name: digest(p) for p in kept.iterdir()} == old  # moved whole, bytes unchanged
    assert not (weights / "push_log.csv").exists()  # a file of the old set that the new one lacks is not left behind
    assert digest(weights / "push.pt") == digest(cand / "push.pt")  # the policy is copied as it is
    assert (weights / "push.eval_seed7.json").read_bytes() == (cand / "push.eval_seed7.json").read_bytes()

    searched = weights_file.read(weights / "push_success_searched.pt")["payload"]
    info = searched["info"]
    assert info["policy"] == info["model"] == info["frames"] == "shipped"
    assert info["trained_with"] == runs and "9.9.9" in info["note"] and digest(cand / "push.pt")[:12] in info["note"]
    source = weights_file.read(cand / "push_success_searched.pt")["payload"]
    assert all(torch.equal(searched["model"][k], source["model"][k]) for k in source["model"])  # weights untouched
    frames = json.loads((weights / "push_frames.json").read_text())
    assert frames["info"]["trained_with"] == {"policy": runs["policy"], "model": runs["model"]}
    assert frames["platt"] == json.loads((cand / "push_frames.json").read_text())["platt"]

    skill = load_skill("push", weights_dir=weights)  # the shipped layout loads, with its search and searched model
    assert skill.frame_search is not None and skill.frame_search.info["policy"] == "shipped"
    assert skill.searched_model is not None


def test_a_set_fitted_with_another_policy_is_refused_before_anything_moves(layout):
    weights, cand, base, runs = layout
    shutil.copy2(WEIGHTS_DIR / "push.pt", base / runs["policy"])  # the run's policy is not the set's
    before = {p.name: digest(p) for p in weights.iterdir()}
    with pytest.raises(InputError, match="fitted with runs/p/policy.pt, which is not the set's push.pt"):
        plan_ship("push", cand, "push_old", weights_dir=weights, base=base)
    assert {p.name: digest(p) for p in weights.iterdir()} == before


def test_run_paths_absent_here_are_reported_not_refused(layout, capsys):
    weights, cand, base, _ = layout
    plan = plan_ship("push", cand, "push_old", weights_dir=weights, base=base / "elsewhere")
    assert len(plan.unchecked) == 6 and not plan.checked
    assert main(["push", "--from", str(cand), "--keep", "push_old", "--weights-dir", str(weights), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "not checked (absent here)" in out and "dry run: nothing changed" in out
    assert not (base / "candidates").exists() and not (weights / "candidates").exists()


@pytest.mark.parametrize("case", ["keep exists", "no success model", "bad keep name", "unknown skill", "same folder"])
def test_sets_that_cannot_ship_are_refused(layout, case):
    weights, cand, base, _ = layout
    skill, keep, source = "push", "push_old", cand
    if case == "keep exists":
        (base / "candidates" / "push_old").mkdir(parents=True)
    elif case == "no success model":
        (cand / "push_success.pt").unlink()
    elif case == "bad keep name":
        keep = "../push_old"
    elif case == "unknown skill":
        skill = "throw"
    else:
        source = weights
    before = sorted(p.name for p in weights.rglob("*"))
    with pytest.raises(InputError):
        plan_ship(skill, source, keep, weights_dir=weights, base=base)
    assert sorted(p.name for p in weights.rglob("*")) == before


def test_portable_drops_the_checkout_s_path_from_every_string(tmp_path):
    info = {"model": f"{tmp_path}/runs/a/success.pt", "command": f"python -m x --out {tmp_path}/runs/b --flag",
            "nested": [f"{tmp_path}", 3, {"frames": "shipped"}]}
    assert portable(info, tmp_path) == {"model": "runs/a/success.pt", "command": "python -m x --out runs/b --flag",
                                        "nested": [".", 3, {"frames": "shipped"}]}


@pytest.fixture
def camera_layout(tmp_path):
    """A weights folder with the shipped push (a policy trained on the surface sample) and its camera ratings, and
    a set holding one camera rating refitted with a run's copy of the shipped policy."""
    weights, cand, base = tmp_path / "weights", tmp_path / "cand", tmp_path / "base"
    (weights / "cameras").mkdir(parents=True)
    cand.mkdir()
    for name in CORE:
        shutil.copy2(WEIGHTS_DIR / name, weights / name)
    for name in ("push_success.pt", "push_frames.json"):  # what ships for camera clouds (no searched model)
        shutil.copy2(WEIGHTS_DIR / "cameras" / name, weights / "cameras" / name)
    shutil.copy2(WEIGHTS_DIR / "cameras" / "push_frames.json", cand / "push_frames.json")
    (base / "runs" / "p").mkdir(parents=True)
    shutil.copy2(weights / "push.pt", base / "runs" / "p" / "policy.pt")
    set_info(cand / "push_frames.json", policy="runs/p/policy.pt", model="shipped", platt_note="refit")
    return weights, cand, base


def test_camera_ratings_ship_into_the_sensor_folder_and_only_what_they_replace_is_kept(camera_layout):
    weights, cand, base = camera_layout
    before = {p.name: digest(p) for p in (weights / "cameras").iterdir()}
    beside = {p.name: digest(p) for p in weights.iterdir() if p.is_file()}
    plan = plan_ship("push", cand, "push_cam_old", weights_dir=weights, base=base, sensor="cameras")
    assert plan.target == weights / "cameras" and [p.name for p in plan.to_keep] == ["push_frames.json"]
    policy = digest(weights / "push.pt")[:12]
    assert plan.checked == [f"push_frames.json: policy runs/p/policy.pt = push.pt (sha256 {policy})"]
    ship(plan, "9.9.9")

    assert {p.name: digest(p) for p in (base / "candidates" / "push_cam_old").iterdir()} == {
        "push_frames.json": before["push_frames.json"]}
    after = {p.name: digest(p) for p in (weights / "cameras").iterdir()}
    assert after.keys() == before.keys() and after["push_success.pt"] == before["push_success.pt"]
    assert {p.name: digest(p) for p in weights.iterdir() if p.is_file()} == beside  # the policy's own files untouched
    frames = json.loads((weights / "cameras" / "push_frames.json").read_text())["info"]
    assert frames["policy"] == "shipped" and frames["trained_with"]["policy"] == "runs/p/policy.pt"
    assert frames["platt_note"] == "refit"
    skill = load_skill("push", weights_dir=weights)
    assert skill.rated_sensors == ("surface", "cameras")
    assert skill.ratings("cameras").frame_search.info["platt_note"] == "refit"


@pytest.mark.parametrize("case", ["a policy without its success model", "the policy's own sensor", "no rating",
                                  "another policy", "unknown sensor"])
def test_camera_ratings_that_cannot_ship_are_refused_before_anything_moves(camera_layout, case):
    weights, cand, base = camera_layout
    sensor = "cameras"
    if case == "a policy without its success model":
        shutil.copy2(weights / "push.pt", cand / "push.pt")
    elif case == "the policy's own sensor":
        sensor = "surface"
    elif case == "no rating":
        (cand / "push_frames.json").unlink()
    elif case == "another policy":
        shutil.copy2(CANDIDATES / "push_0.16" / "push.pt", base / "runs" / "p" / "policy.pt")
    else:
        sensor = "lidar"
    before = {p.relative_to(weights): digest(p) for p in weights.rglob("*") if p.is_file()}
    with pytest.raises(InputError):
        plan_ship("push", cand, "push_cam_old", weights_dir=weights, base=base, sensor=sensor)
    assert {p.relative_to(weights): digest(p) for p in weights.rglob("*") if p.is_file()} == before
    assert not (base / "candidates").exists()


def test_a_policy_for_a_sensor_ships_into_its_folder_keeping_every_file_of_the_skill_there(camera_layout):
    weights, cand, base = camera_layout
    for name in CORE:  # the 0.16 push with its own ratings, as the policy for camera clouds
        shutil.copy2(CANDIDATES / "push_0.16" / name, cand / name)
    beside = {p.name: digest(p) for p in weights.iterdir() if p.is_file()}
    before = {p.name: digest(p) for p in (weights / "cameras").iterdir()}
    plan = plan_ship("push", cand, "push_cam_old", weights_dir=weights, base=base, sensor="cameras")
    assert plan.target == weights / "cameras" and {p.name for p in plan.to_keep} == set(before)
    ship(plan, "9.9.9")
    assert {p.name: digest(p) for p in (base / "candidates" / "push_cam_old").iterdir()} == before
    assert {p.name for p in (weights / "cameras").iterdir()} == set(CORE)
    assert digest(weights / "cameras" / "push.pt") == digest(cand / "push.pt")  # the policy itself is never touched
    assert {p.name: digest(p) for p in weights.iterdir() if p.is_file()} == beside
    skill = load_skill("push", weights_dir=weights)
    cameras = skill.ratings("cameras")
    assert skill.rated_sensors == ("surface", "cameras") and cameras.model is not skill.model
    assert cameras._success_weights == weights / "cameras" / "push_success.pt"
    assert torch.equal(cameras.model.state_dict()["actor.0.weight"],
                       load_skill("push", weights_dir=CANDIDATES / "push_0.16").model.state_dict()["actor.0.weight"])
