"""The safe weights format: nothing executes on load, and files are checked by their metadata."""

from __future__ import annotations

import os

import numpy as np
import pytest
import torch

from affordplan.errors import InputError, WeightsError
from primitives import weights_file
from primitives.networks import HybridActorCritic
from primitives.policy import load_policy
from primitives.training.success import load_success_net


class _Payload:
    """Unpickling this runs code: it creates the file named by ``target``."""

    def __init__(self, target: str):
        self.target = target

    def __reduce__(self):
        return (os.mkdir, (self.target,))


def test_a_file_that_would_run_code_is_refused_and_nothing_runs(tmp_path):
    marker = tmp_path / "pwned"
    torch.save({"model": _Payload(str(marker))}, tmp_path / "push.pt")
    with pytest.raises(WeightsError, match="not a safe weights file"):
        load_policy(tmp_path / "push.pt", "push")
    with pytest.raises(WeightsError, match="not a safe weights file"):
        load_success_net("push", tmp_path / "push.pt")
    assert not marker.exists()


def test_files_are_refused_by_their_metadata_for_another_skill_or_kind(tmp_path):
    state = dict(model=HybridActorCritic().state_dict())
    weights_file.save(tmp_path / "roll.pt", state, weights_file.make_meta("roll", "policy"))
    with pytest.raises(WeightsError, match="for the roll skill, not push"):
        load_policy(tmp_path / "roll.pt", "push")
    with pytest.raises(WeightsError, match="holds a policy file, not a success"):
        load_success_net("roll", tmp_path / "roll.pt")
    assert load_policy(tmp_path / "roll.pt", "roll") is not None


def test_a_file_without_metadata_is_refused_and_stamp_adds_it(tmp_path):
    net = HybridActorCritic()
    torch.save(net.state_dict(), tmp_path / "old.pt")
    with pytest.raises(WeightsError, match="stamp"):
        load_policy(tmp_path / "old.pt", "spin")
    assert weights_file.main(["stamp", str(tmp_path / "old.pt"), "--skill", "spin", "--kind", "policy"]) == 0
    loaded = load_policy(tmp_path / "old.pt", "spin")
    assert all(torch.equal(loaded.state_dict()[k], v) for k, v in net.state_dict().items())
    assert weights_file.main(["stamp", str(tmp_path / "old.pt"), "--skill", "spin", "--kind", "policy"]) == 2


def test_payloads_with_numpy_arrays_round_trip(tmp_path):
    payload = dict(replay=dict(obs=np.arange(12, dtype=np.float32).reshape(3, 4), size=3),
                   rng=np.random.default_rng(5).bit_generator.state, value=np.float64(2.5))
    weights_file.save(tmp_path / "c.pt", payload, weights_file.make_meta("push", "checkpoint"))
    back, meta = weights_file.load(tmp_path / "c.pt", kind="checkpoint", skill="push")
    assert meta["kind"] == "checkpoint" and meta["format_version"] == weights_file.FORMAT_VERSION
    assert np.array_equal(np.asarray(back["replay"]["obs"]), payload["replay"]["obs"])
    rng = np.random.default_rng()
    rng.bit_generator.state = back["rng"]
    assert rng.random() == np.random.default_rng(5).random()
    assert back["value"] == 2.5


def test_damaged_and_missing_files_are_named(tmp_path):
    (tmp_path / "torn.pt").write_bytes(b"PK\x03\x04 not a zip")
    with pytest.raises(WeightsError, match="damaged or truncated"):
        load_policy(tmp_path / "torn.pt", "push")
    with pytest.raises(WeightsError, match="no weights at"):
        load_policy(tmp_path / "missing.pt", "push")
    with pytest.raises(WeightsError, match="folder"):
        load_policy(tmp_path, "push")


def test_every_shipped_file_carries_metadata():
    for path in sorted(weights_file.SHIPPED_DIR.glob("*.pt")):
        kind = "success" if "_success" in path.stem else "policy"
        _, meta = weights_file.load(path, kind=kind, skill=path.stem.split("_")[0])
        assert meta["format"] == weights_file.FORMAT


def test_a_rating_comes_from_the_sensors_subfolder_where_it_is_there(tmp_path):
    (tmp_path / "cameras").mkdir()
    (tmp_path / "cameras" / "push_frames.json").write_text("{}")
    assert weights_file.rating_path("push", "frames", "cameras", tmp_path) == tmp_path / "cameras" / "push_frames.json"
    assert weights_file.rating_path("push", "success", "cameras", tmp_path) == tmp_path / "push_success.pt"  # not there
    assert weights_file.rating_path("push", "frames", None, tmp_path) == tmp_path / "push_frames.json"
    assert weights_file.rating_path("push", "frames", "surface", tmp_path) == tmp_path / "push_frames.json"
    assert weights_file.rated_for("push", "cameras", tmp_path)
    assert not weights_file.rated_for("spin", "cameras", tmp_path)
    assert weights_file.rating_path("push", "success", "cameras") == weights_file.SHIPPED_DIR / "cameras" / \
        "push_success.pt"  # shipped for push
    assert weights_file.rating_path("spin", "success", "cameras") == weights_file.SHIPPED_DIR / "spin_success.pt"
    with pytest.raises(InputError, match="unknown rating"):
        weights_file.rating_path("push", "policy")


def test_ratings_are_the_policys_own_for_the_sensor_it_was_trained_on(tmp_path):
    (tmp_path / "cameras").mkdir()
    (tmp_path / "cameras" / "push_success.pt").write_bytes(b"")  # stale camera ratings beside...
    policy = {"model": {"w": torch.zeros(1)}}
    weights_file.save(tmp_path / "push.pt", policy, weights_file.make_meta("push", "policy", sensor="cameras"))
    assert weights_file.policy_sensor("push", tmp_path) == "cameras"
    assert weights_file.rating_path("push", "success", "cameras", tmp_path) == tmp_path / "push_success.pt"  # unused
    assert not weights_file.rated_for("push", "cameras", tmp_path)
    weights_file.save(tmp_path / "push.pt", policy, weights_file.make_meta("push", "policy", sensor="surface"))
    assert weights_file.rating_path("push", "success", "cameras", tmp_path) == tmp_path / "cameras" / "push_success.pt"
    assert weights_file.policy_sensor("roll", tmp_path) is None  # no policy there
    assert weights_file.policy_sensor("push") == "surface"  # the shipped policies saw the surface sample
