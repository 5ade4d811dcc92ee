"""Every option of a start executed from it: the shared data of the option ranker and the frame ceiling."""

import numpy as np

from primitives.frames import load_frame_search
from primitives.policy import greedy_action
from primitives.training.env import EnvConfig, PrimitiveEnv
from primitives.training.evaluate import load_policy
from primitives.training.options import execute_every_option


def test_every_option_is_executed_from_the_same_start_and_the_start_is_left_as_it_was():
    policy = load_policy(None, "spin")
    search = load_frame_search("spin", "shipped", "cameras", ranked=False)
    env = PrimitiveEnv(EnvConfig("spin", objects=("cube",), p_params=0.0, sensor="cameras"), seed=3)
    env.reset(object_key="cube")
    seen, T_world_object = env.seen, env.sim.object_pose()
    done = execute_every_option(env, policy, search)
    # the seed's objective: the request's free frames, then each stand-in request's
    assert done.option[0] == 0 and done.frame[0] == 0 and done.option.max() == len(done.options) - 1 > 0
    assert len(done) == sum(len(frames) for _, frames in done.options) == len(done.decision)
    assert done.decision.shape[1] == 14 and done.success.dtype == bool
    assert not done.parameterised[done.option == 0].any() and done.parameterised[done.option > 0].all()
    assert np.allclose(env.sim.object_pose(), T_world_object) and env.seen is seen
    k, j = int(done.option[-1]), int(done.frame[-1])
    assert done.row(k, j) == len(done) - 1
    # an outcome recorded is the outcome of acting in that option from the start, as the skill acts there
    again = execute_every_option(env, policy, search)
    assert np.array_equal(again.success, done.success) and np.allclose(again.decision, done.decision)
    start = env.sim.snapshot()
    for r in {0, len(done) - 1, int(np.argmax(done.success)), int(np.argmin(done.success))}:
        env.sim.restore(start)
        env.seen = search.acting(done.options, int(done.option[r]), int(done.frame[r]))
        idx, motion, _ = greedy_action(policy, env.seen.obs)
        assert env.step(idx, motion).success == done.success[r]
    env.close()
