"""The replay buffer (primitives.training.replay): fixed memory, a ring that overwrites the oldest, exact restore."""

from __future__ import annotations

import numpy as np
import pytest

from primitives.training.replay import ReplayBuffer


def test_replay_memory_is_fixed_and_ring_overwrites():
    buf = ReplayBuffer(capacity=10, n_points=8)
    before = buf.nbytes
    for i in range(25):
        buf.add(np.full((8, 9), i, dtype=np.float32), i % 8, np.zeros(3), float(i), i % 2 == 0)
    assert buf.nbytes == before and buf.size == 10
    assert set(buf.reward.astype(int)) == set(range(15, 25))
    restored = ReplayBuffer(capacity=10, n_points=8)
    restored.load_state(buf.state())
    assert np.array_equal(restored.obs, buf.obs) and restored.cursor == buf.cursor


def test_samples_come_from_the_filled_part_as_float32():
    buf = ReplayBuffer(capacity=50, n_points=4)
    for i in range(3):
        buf.add(np.full((4, 9), i, dtype=np.float32), i, np.full(3, 0.1 * i), float(i), False)
    batch = buf.sample(200, np.random.default_rng(0))
    assert batch["obs"].dtype == np.float32 and batch["obs"].shape == (200, 4, 9)
    assert set(batch["reward"].astype(int)) == {0, 1, 2}  # never an empty slot
    assert np.array_equal(batch["obs"][:, 0, 0], batch["reward"]) and np.array_equal(batch["index"], batch["reward"])


def test_a_saved_replay_larger_than_the_buffer_is_refused():
    full = ReplayBuffer(capacity=8, n_points=4)
    for i in range(8):
        full.add(np.zeros((4, 9), np.float32), 0, np.zeros(3), float(i), False)
    with pytest.raises(ValueError, match="more than capacity 4"):
        ReplayBuffer(capacity=4, n_points=4).load_state(full.state())
    bigger = ReplayBuffer(capacity=16, n_points=4)
    bigger.load_state(full.state())  # a larger buffer takes it
    assert bigger.size == 8 and np.array_equal(bigger.reward[:8], np.arange(8))
