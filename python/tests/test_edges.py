"""The edges of the environments' API, each refused with a message that
names what is wrong: the seed's bound (2**63 - 1) wherever a seed enters,
the counts worded as the ranges table words them, settings that would be
ignored, Gymnasium's wrappers that cannot work on per-robot rewards, and
the order of calls (reset before step, nothing after close)."""

import numpy as np
import pytest
from gymnasium.wrappers.vector import NormalizeReward, RecordEpisodeStatistics

import zumo_swarm

SMALL = {"robots": 2, "pucks": 5}
MAKERS = {
    "gym": zumo_swarm.gym_env,
    "parallel": zumo_swarm.parallel_env,
    "vector": lambda **s: zumo_swarm.vector_env(2, **s),
}
SEED_BOUND = r"must be a whole number from 0 to 2\*\*63 - 1"


def step_zero(env):
    """One step of every robot standing on action 0."""
    if isinstance(env, zumo_swarm.SwarmParallelEnv):
        return env.step({agent: 0 for agent in env.possible_agents})
    return env.step(np.zeros(env.action_space.shape, dtype=np.int64))


@pytest.mark.parametrize("make", MAKERS.values(), ids=MAKERS.keys())
@pytest.mark.parametrize("seed", [2**63, 2**64 - 1, 2**70, -1])
def test_a_seed_outside_0_to_2_63_minus_1_is_refused_when_the_environment_is_made(make, seed):
    with pytest.raises(ValueError, match=rf"seed = {seed}: {SEED_BOUND}"):
        make(seed=seed, **SMALL)


@pytest.mark.parametrize("make", MAKERS.values(), ids=MAKERS.keys())
def test_a_seed_outside_0_to_2_63_minus_1_is_refused_by_reset_and_the_largest_is_taken(make):
    env = make(**SMALL)
    for seed in (2**63, 2**64 - 1, -3):
        with pytest.raises(ValueError, match=rf"seed = {seed}: {SEED_BOUND}"):
            env.reset(seed=seed if not isinstance(env, zumo_swarm.SwarmVectorEnv) else [seed, 1])
    if isinstance(env, zumo_swarm.SwarmVectorEnv):
        env.reset(seed=[2**63 - 1, 2**63 - 2])
    else:
        env.reset(seed=2**63 - 1)
        assert make(seed=2**63 - 1, **SMALL) is not None
    step_zero(env)


def test_a_vector_envs_seed_leaves_room_for_every_worlds_seed_up_to_2_63_minus_1():
    with pytest.raises(ValueError, match=r"seed = 9223372036854775807: with 2 worlds \(world i is seeded seed \+ i\) "
                                         r"must be a whole number from 0 to 2\*\*63 - 2"):
        zumo_swarm.vector_env(2, seed=2**63 - 1, **SMALL)
    env = zumo_swarm.vector_env(3, seed=2**63 - 3, **SMALL)
    with pytest.raises(ValueError, match=r"seed = 9223372036854775806: with 3 worlds .* from 0 to 2\*\*63 - 3"):
        env.reset(seed=2**63 - 2)
    env.reset(seed=2**63 - 3)
    step_zero(env)


def test_a_seed_that_is_not_a_whole_number_is_a_type_error():
    for seed in (1.5, "1", None, True):
        with pytest.raises(TypeError, match=r"seed = .*: expected a whole number"):
            zumo_swarm.gym_env(seed=seed, **SMALL)
    with pytest.raises(TypeError, match=r"seed = 2.0: expected a whole number"):
        zumo_swarm.gym_env(**SMALL).reset(seed=2.0)


@pytest.mark.parametrize("name, range_", [("pucks", r"\[1, 100000\]"), ("robots", r"\[1, 1000\]"),
                                          ("max_steps", r"\[1, 1e10\] steps")])
@pytest.mark.parametrize("value", [-3, 0, 10**11])
def test_a_count_out_of_range_is_worded_as_the_ranges_table_words_it_on_either_side(name, range_, value):
    shown = {-3: "-3", 0: "0", 10**11: "1e11"}[value]  # as the ranges table shows numbers
    with pytest.raises(ValueError, match=rf"^{name} = {shown}: outside its plausible range {range_} \("):
        zumo_swarm.gym_env(**{name: value})


def test_the_vector_envs_worlds_and_threads_are_worded_as_the_ranges_table_words_them():
    for worlds in (0, -2, 5000):
        with pytest.raises(ValueError, match=rf"^num_worlds = {worlds}: outside its plausible range \[1, 4096\]"):
            zumo_swarm.vector_env(worlds, **SMALL)
    for threads in (0, 5000):
        with pytest.raises(ValueError, match=rf"^threads = {threads}: outside its plausible range \[1, 1024\]"):
            zumo_swarm.vector_env(2, threads=threads, **SMALL)


@pytest.mark.parametrize("make", MAKERS.values(), ids=MAKERS.keys())
@pytest.mark.parametrize("observation", ["reading", "state"])
def test_the_role_hasher_is_refused_whatever_the_observation(make, observation):
    with pytest.raises(ValueError, match=r'hasher = "original-role": the role layout needs innies'):
        make(hasher="original-role", observation=observation, **SMALL)
    with pytest.raises(ValueError, match=r'hasher = "md5": unknown hasher'):
        make(hasher="md5", observation=observation, **SMALL)


@pytest.mark.parametrize("wrapper", [RecordEpisodeStatistics, NormalizeReward])
def test_gymnasiums_per_world_reward_wrappers_on_the_per_robot_vector_env_are_refused_by_name(wrapper):
    for worlds in (3, 2):  # 2 worlds of 2 robots: NumPy would broadcast, silently wrong
        env = wrapper(zumo_swarm.vector_env(worlds, **SMALL))
        with pytest.raises(TypeError, match=rf"{wrapper.__name__} cannot wrap zumo_swarm.vector_env: its rewards are "
                                            r"per robot, shape \(worlds, robots\).*single_agent_view\(\)"):
            env.reset(seed=1)
    env = zumo_swarm.vector_env(2, **SMALL)
    env.reset(seed=1)
    wrapped = wrapper(env)
    with pytest.raises(TypeError, match=f"{wrapper.__name__} cannot wrap"):
        wrapped.step(np.zeros((2, 2), dtype=np.int64))


@pytest.mark.parametrize("wrapper", [RecordEpisodeStatistics, NormalizeReward])
def test_the_same_wrappers_work_on_the_single_agent_view(wrapper):
    env = wrapper(zumo_swarm.vector_env(3, max_steps=3, **SMALL).single_agent_view())
    env.reset(seed=1)
    for _ in range(3):
        _, rewards, _, truncated, info = env.step(np.zeros((3, 2), dtype=np.int64))
    assert rewards.shape == (3,) and truncated.all()
    if wrapper is RecordEpisodeStatistics:
        assert info["_episode"].all() and env.episode_count == 3


@pytest.mark.parametrize("make", MAKERS.values(), ids=MAKERS.keys())
def test_step_before_the_first_reset_is_refused(make):
    env = make(**SMALL)
    with pytest.raises(RuntimeError, match=r"step\(\) before reset\(\): call reset\(\) first"):
        step_zero(env)
    env.reset()
    step_zero(env)


@pytest.mark.parametrize("make", MAKERS.values(), ids=MAKERS.keys())
def test_step_and_reset_after_close_are_refused(make):
    env = make(**SMALL)
    env.reset(seed=1)
    step_zero(env)
    env.close()
    env.close()  # closing twice is allowed
    with pytest.raises(RuntimeError, match=r"step\(\) after close\(\): the environment is closed"):
        step_zero(env)
    with pytest.raises(RuntimeError, match=r"reset\(\) after close\(\): the environment is closed"):
        env.reset()
