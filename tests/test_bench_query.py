"""The query bench (affordplan.app.bench.query): the thread count put back, skills timed in interleaved rounds."""

from __future__ import annotations

import pytest

from affordplan.errors import InputError


def test_bench_query_puts_the_thread_count_back_when_it_refuses_a_folder(tmp_path):
    import torch

    from affordplan.app.bench.query import bench_queries
    from primitives.skills import WEIGHTS_DIR

    for name in ("spin.pt", "spin_success.pt", "push.pt"):  # spin loads (and caps the threads); push has no model
        (tmp_path / name).write_bytes((WEIGHTS_DIR / name).read_bytes())
    before = torch.get_num_threads()
    torch.set_num_threads(3)  # more than loading a skill allows
    try:
        with pytest.raises(InputError, match="no success model beside it"):
            bench_queries(("spin", "push"), weights_dir=tmp_path)
        assert torch.get_num_threads() == 3
    finally:
        torch.set_num_threads(before)


@pytest.mark.slow
def test_bench_query_interleaves_the_skills_in_rounds(monkeypatch):
    import affordplan.app.bench.query as qb

    order = []
    real = qb.time_calls

    def recording(query, x, n, warm_up=1):
        order.append(query.__self__.name)
        return real(query, x, n, warm_up)

    monkeypatch.setattr(qb, "time_calls", recording)
    rows = qb.bench_queries(("spin", "push"), repeats=3, batch=2, threads=(1,), rounds=3)
    # each round times every cell (2 raters x one and a batch) of spin, then of push; three rounds
    assert order == (["spin"] * 4 + ["push"] * 4) * 3
    assert len(rows) == 4 and {r.skill for r in rows} == {"spin", "push"}
    for r in rows:  # the median of all calls lies between the fastest and the slowest round's median
        lo, hi = r.single_ms_rounds
        assert 0 < lo <= r.single_ms <= hi
    with pytest.raises(InputError, match="rounds"):
        qb.bench_queries(("spin",), rounds=0)
