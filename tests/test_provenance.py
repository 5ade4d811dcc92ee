"""What training commands record of the paths they were given (primitives.training.provenance)."""

from pathlib import Path

from primitives.training.provenance import recorded_path, recorded_paths


def test_a_relative_path_or_a_name_is_recorded_as_typed(tmp_path):
    assert recorded_path("runs/s1/policy.pt", cwd=tmp_path) == "runs/s1/policy.pt"
    assert recorded_path("shipped", cwd=tmp_path) == "shipped"
    assert recorded_path(Path("a/b.npz"), cwd=tmp_path) == "a/b.npz"


def test_an_absolute_path_inside_the_working_directory_is_made_relative(tmp_path):
    inside = tmp_path / "runs" / "s1" / "success.pt"
    assert recorded_path(inside, cwd=tmp_path) == str(Path("runs/s1/success.pt"))
    assert recorded_path(str(inside), cwd=tmp_path / "runs") == str(Path("s1/success.pt"))


def test_an_absolute_path_elsewhere_keeps_only_its_file_name(tmp_path):
    elsewhere = tmp_path / "scratch" / "rollouts_2400_0.npz"
    recorded = recorded_path(elsewhere, cwd=tmp_path / "checkout")
    assert recorded == "rollouts_2400_0.npz" and str(tmp_path) not in recorded


def test_several_paths_are_recorded_in_order(tmp_path):
    assert recorded_paths([tmp_path / "x" / "a.npz", "b.npz", tmp_path / "c.npz"], cwd=tmp_path / "x") == [
        "a.npz", "b.npz", "c.npz"]
