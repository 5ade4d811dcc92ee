"""Fitting an option ranker: every option of training starts executed (resumable), then the fit."""

import json

import numpy as np
import pytest

from primitives.frames import FrameSearch, load_frame_search
from primitives.option_ranker import load_ranker
from primitives.training.ranker import attach, collect, features_of, fit, main, pick_figures, read_collections


def test_collect_executes_every_option_and_resumes_where_it_stopped(tmp_path):
    out = collect("spin", tmp_path / "c", starts=3, params="random", chunk=2, progress=False)
    rows, sensor = read_collections("spin", [out])
    assert sensor == "cameras" and sorted(set(rows["start"])) == [0, 1, 2]
    n_frames = len(load_frame_search("spin", "shipped", "cameras").frames("spin", {"angle": 0.3}))
    assert len(rows["success"]) == 3 * n_frames  # a request's every free frame, executed
    for s in range(3):
        m = rows["start"] == s
        assert rows["chosen"][m].sum() == 1 and rows["parameterised"][m].all() and not rows["stand_in"][m].any()
        assert np.ptp(rows["extents"][m], axis=0).max() == 0.0
        assert len(set(rows["object"][m])) == 1 and rows["object"][m][0]  # the start's object, by its key
    first = (tmp_path / "c" / "chunk_0001.npz").read_bytes()
    (tmp_path / "c" / "chunk_0001.npz").unlink()  # killed before its last chunk was written
    collect("spin", tmp_path / "c", starts=3, params="random", chunk=2, progress=False)
    again, _ = read_collections("spin", [out])
    assert all(np.array_equal(again[k], rows[k]) for k in rows)
    assert (tmp_path / "c" / "chunk_0001.npz").stat().st_size == len(first)
    assert not list((tmp_path / "c").glob("*.tmp"))
    (tmp_path / "c" / "chunk_0002.npz.tmp").write_bytes(first[:100])  # a write killed half-way: not a chunk
    assert np.array_equal(read_collections("spin", [out])[0]["start"], rows["start"])


def test_pick_figures_score_the_option_a_ranking_acts_in():
    success = np.array([0, 1, 0, 1, 1, 0], dtype=bool)
    starts = np.array([0, 0, 0, 1, 1, 1])
    f = pick_figures(np.array([0.1, 0.9, 0.2, 0.3, 0.1, 0.9]), success, starts)
    assert f["pick"] == 0.5 and f["best"] == 1.0 and f["random"] == pytest.approx(0.5)
    assert f["within_start_auroc"] == pytest.approx((1.0 + 0.0) / 2)  # start 1: its failure ranked first


def test_fit_writes_a_ranker_that_loads_and_says_how_it_was_made(tmp_path):
    out = collect("spin", tmp_path / "c", starts=5, params="random", chunk=5, progress=False)
    info = fit("spin", [out], tmp_path / "spin_ranker.pt", epochs=3, width=8, members=3, progress=False)
    assert info["starts"] == 5 and info["sensor"] == "cameras" and 1 <= info["epoch"] <= 3
    assert info["members"] == 3 and info["refit"] and "--members 3" in info["command"]
    assert 0.0 <= info["held_out"]["pick"] <= info["held_out"]["best"] <= 1.0
    ranker = load_ranker(tmp_path / "spin_ranker.pt", "spin")
    assert ranker.width == 8 and len(ranker.nets) == 3
    kept = fit("spin", [out], tmp_path / "kept.pt", epochs=3, width=8, members=3, refit=False, progress=False)
    assert kept["held_out"] == info["held_out"]  # the same choice, made before the refit
    rows, _ = read_collections("spin", [out])
    x = features_of(rows)[0]
    assert not np.allclose(load_ranker(tmp_path / "kept.pt").score(x), ranker.score(x))  # refitted on all starts
    with pytest.raises(Exception, match="roll"):
        fit("roll", [out], tmp_path / "roll_ranker.pt", epochs=1, progress=False)
    frames = attach("spin", tmp_path / "spin_ranker.pt", tmp_path / "cand")  # the shipped search, ranked
    search = FrameSearch.load(frames)
    shipped = load_frame_search("spin", "shipped", "cameras")
    assert search.ranker_file == "spin_ranker.pt" and (tmp_path / "cand" / "spin_ranker.pt").exists()
    assert (search.turns, search.mirror, search.platt, search.stand_ins) == (
        shipped.turns, shipped.mirror, shipped.platt, shipped.stand_ins)
    (tmp_path / "cand" / "spin_ranker.pt").write_bytes(b"damaged")  # a search whose own ranker no longer loads
    with pytest.raises(Exception, match="spin_ranker"):
        FrameSearch.load(frames)
    assert FrameSearch.load(frames, ranked=False).ranker is None
    again = attach("spin", tmp_path / "spin_ranker.pt", tmp_path / "again", frames=str(frames))  # replaced, not read
    assert FrameSearch.load(again).ranker is not None
    with pytest.raises(Exception, match="push"):
        attach("push", tmp_path / "spin_ranker.pt", tmp_path / "other")
    assert not (tmp_path / "other").exists()


def test_the_command_refuses_held_out_objects_and_empty_folders(tmp_path, capsys):
    assert main(["collect", "spin", "--starts", "2", "--objects", "housekeep:unseen", "--out", str(tmp_path)]) == 2
    assert "held out" in capsys.readouterr().err
    assert main(["fit", "spin", str(tmp_path), "--out", str(tmp_path / "r.pt")]) == 2
    assert "no collected chunks" in capsys.readouterr().err
    one = collect("spin", tmp_path / "one", starts=1, params="random", progress=False)
    assert main(["fit", "spin", str(one), "--out", str(tmp_path / "r.pt")]) == 2
    assert "at least 2" in capsys.readouterr().err and not (tmp_path / "r.pt").exists()
    out = collect("spin", tmp_path / "c", starts=2, params="random", chunk=2, progress=False)
    assert main(["fit", "spin", str(out), "--out", str(tmp_path / "r.pt"), "--epochs", "2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["options"] == 24
    assert main(["fit", "spin", str(out), "--out", str(tmp_path / "r0.pt"), "--members", "0"]) == 2
    assert "--members" in capsys.readouterr().err and not (tmp_path / "r0.pt").exists()


def test_calibrate_writes_the_search_reporting_its_rankers_scaled_score_beside_a_copy_of_its_ranker(tmp_path, capsys):
    """``calibrate``: frame-searched rollouts of training objects, the ranker's raw score of each pick, a Platt scaling
    of them; the search written with ``ranker_platt`` and ``reports_rating`` and its ranker beside it, ready to load.
    A search without a ranker, held-out objects or no rollouts are refused before anything is written."""
    assert main(["calibrate", "spin", "--rollouts", "8", "--seed", "3", "--out", str(tmp_path / "k"), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    search = FrameSearch.load(tmp_path / "k" / "spin_frames.json")
    shipped = load_frame_search("spin", "shipped", "cameras")
    assert search.reports_rating and search.reports_ranking and search.ranker_file == "spin_ranker.pt"
    assert (search.turns, search.mirror, search.platt) == (shipped.turns, shipped.mirror, shipped.platt)
    assert search.info["ranker_calibration"] == info and info["rollouts"] == 8
    assert info["command"] == "python -m primitives.training.ranker calibrate spin --rollouts 8 --seed 3"
    assert 0.0 <= info["success_rate"] <= 1.0 and np.isfinite(search.ranker_platt).all()
    for bad, says in ((["roll"], "no option ranker"), (["spin", "--objects", "housekeep:unseen"], "held out"),
                      (["spin", "--rollouts", "0"], "--rollouts")):
        assert main(["calibrate", *bad, "--out", str(tmp_path / "no")]) == 2
        assert says in capsys.readouterr().err and not (tmp_path / "no").exists()
