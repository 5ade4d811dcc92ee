"""Skills run by the finger and by the arm from the same draws."""

from primitives.research.sim2sim import skill_sim2sim


def test_both_sims_run_every_draw_and_the_report_counts_them():
    result = skill_sim2sim("roll", n=2, seed=2, progress=False)
    assert result.errors == 0 and len(result.finger) == len(result.arm) == 2
    report = result.report()
    assert report.startswith("roll: 2 draws with the same start and parameter in both sims")
    assert f"finger {sum(result.finger):3d} successes" in report and f"arm {sum(result.arm):3d}" in report
