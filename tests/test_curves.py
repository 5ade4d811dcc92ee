"""Learning-curve plots from training logs."""

from __future__ import annotations

import pytest

from affordplan.errors import InputError
from primitives.research import curves
from primitives.research.curves import plot_curves, read_log, thousands

HEADER = "step,updates,minutes,success_recent,reward_recent,critic_loss,actor_loss,invalid,steps_per_s,rss_mb_total\n"


def test_thousands_labels():
    assert thousands(120000) == "120k"
    assert thousands(2500) == "2.5k"
    assert thousands(0) == "0"


def test_plot_curves_writes_a_png(tmp_path):
    run = tmp_path / "spin_60"
    run.mkdir()
    (run / "log.csv").write_text(HEADER + "500,16,0.2,0.02,-1.6,3.7,0.02,0,40.7,1117.5\n"
                                          "120000,30000,55.0,0.30,-0.8,0.3,0.5,6,36.0,1300.0\n")
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "log.csv").write_text(HEADER)  # a run killed before its first row: skipped, not an error
    assert read_log(run)["step"] == [500.0, 120000.0]
    assert read_log(empty) == {}
    out = tmp_path / "curves.png"
    plot_curves([run, empty], out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_folder_without_a_log_is_refused_clearly(tmp_path, capsys):
    with pytest.raises(InputError, match="no log.csv"):
        read_log(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        curves.main([str(tmp_path), "--out", str(tmp_path / "c.png")])
    assert exit_info.value.code == 2 and "no log.csv" in capsys.readouterr().err
    assert not (tmp_path / "c.png").exists()
