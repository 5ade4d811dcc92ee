"""Replay of one-step transitions in preallocated numpy arrays: memory is fixed at construction.

Observations are stored as float16 (a 256-point cloud is 3 KB), so 50 000 transitions take about
150 MB, committed at construction; the buffer is a ring that overwrites the oldest entries.
"""

from __future__ import annotations

import numpy as np


class ReplayBuffer:
    def __init__(self, capacity: int, n_points: int, obs_dim: int = 9):
        self.capacity = int(capacity)
        self.obs = np.zeros((self.capacity, n_points, obs_dim), dtype=np.float16)
        self.index = np.zeros(self.capacity, dtype=np.int32)
        self.motion = np.zeros((self.capacity, 3), dtype=np.float32)
        self.reward = np.zeros(self.capacity, dtype=np.float32)
        self.success = np.zeros(self.capacity, dtype=bool)
        for array in (self.obs, self.index, self.motion, self.reward, self.success):
            array.fill(0)  # touch every page now, so resident memory does not grow as the ring fills
        self.size = 0
        self.cursor = 0

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.obs, self.index, self.motion, self.reward, self.success))

    def add(self, obs: np.ndarray, index: int, motion: np.ndarray, reward: float, success: bool) -> None:
        i = self.cursor
        self.obs[i] = obs
        self.index[i] = index
        self.motion[i] = motion
        self.reward[i] = reward
        self.success[i] = success
        self.cursor = (i + 1) % self.capacity
        self.size = min(self.size + 1, self.capacity)

    def sample(self, batch_size: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
        idx = rng.integers(self.size, size=batch_size)
        return dict(obs=self.obs[idx].astype(np.float32), index=self.index[idx], motion=self.motion[idx],
                    reward=self.reward[idx])

    def state(self) -> dict[str, np.ndarray | int]:
        """Everything needed to restore the buffer exactly (for checkpoints)."""
        n = self.size
        return dict(obs=self.obs[:n], index=self.index[:n], motion=self.motion[:n], reward=self.reward[:n],
                    success=self.success[:n], size=n, cursor=self.cursor)

    def load_state(self, state: dict) -> None:
        n = int(state["size"])
        if n > self.capacity:
            raise ValueError(f"checkpointed replay holds {n} transitions, more than capacity {self.capacity}")
        for name in ("obs", "index", "motion", "reward", "success"):
            getattr(self, name)[:n] = state[name]
        self.size = n
        self.cursor = int(state["cursor"]) % self.capacity
