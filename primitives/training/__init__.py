"""Offline machinery: the one-step environment, rollouts, replay, checkpoints, and the train, evaluate and
success-model commands (``python -m primitives.train|evaluate|success``). Nothing that ``plan()``,
``Plan.execute`` or ``load_skill`` reaches imports it."""
