"""Bad arguments raise a Python exception that names the argument and the
problem; nothing reaches a Rust panic."""

import numpy as np
import pytest

import zumo_swarm


def not_a_panic(error: BaseException) -> bool:
    """PyO3 turns a Rust panic into ``PanicException`` (a ``BaseException``,
    so ``pytest.raises(ValueError)`` would not catch it anyway)."""
    return type(error).__name__ != "PanicException" and isinstance(error, Exception)


BAD_SETTINGS = [
    ({"robots": 0}, ValueError, r"robots = 0: outside its plausible range \[1, 1000\] \(at least one robot"),
    ({"robots": -5}, ValueError, r"robots = -5"),
    ({"pucks": -1}, ValueError, r"pucks = -1"),
    ({"pucks": 100_000}, ValueError, r"robots, pucks = 8, 100000: .* more than fit in the arena"),
    ({"arena": "tv55"}, ValueError, r"arena = \"tv55\": expected \"thesis\" or one of tv75"),
    ({"seed": -1}, ValueError, r"seed = -1"),
    ({"field": "letter:Q"}, ValueError, r"field = \"letter:Q\""),
    ({"field": "/no/such/field.png"}, ValueError, r"/no/such/field.png"),
    ({"sensors": "pixy"}, ValueError, r"sensors = \"pixy\": unknown sensor model; expected disc, disc-thesis, robot"),
    ({"robot_config": {"camera": {"tilt_deg": 5}}}, ValueError, r"robot_config = .*only for sensors=\"robot\""),
    ({"sensors": "robot", "robot_config": {"camera": {"height_mm": 0}}}, ValueError, r"robot_config = .*camera.height_mm"),
    ({"sensors": "robot", "robot_config": {"camra": {}}}, ValueError, r"robot_config = .*unknown field `camra`"),
    ({"robot_config": 5}, TypeError, r"robot_config = 5"),
    ({"max_steps": 0}, ValueError, r"max_steps = 0"),
    ({"thresholds": (0.9, 0.1)}, ValueError, r"thresholds = \(0.9, 0.1\): must be \(outie, innie\)"),
    ({"thresholds": "high"}, ValueError, r"thresholds = 'high'"),
    ({"reward": "eval"}, ValueError, r"reward = \"eval\": unknown reward"),
    ({"observation": "pixels"}, ValueError, r"observation = \"pixels\""),
    ({"observation": "state", "hasher": "md5"}, ValueError, r"hasher = \"md5\": unknown hasher"),
    ({"observation": "state", "hasher": "original-role"}, ValueError, r"hasher = \"original-role\": the role layout needs innies"),
    ({"action": "joystick"}, ValueError, r"action = \"joystick\""),
    ({"actions": [0.3]}, ValueError, r"actions = \[0.3\]: action count 1 is out of range"),
    ({"actions": [0.1, float("nan")]}, ValueError, r"actions = .*not a finite number"),
    ({"forward_speed": -2.0}, ValueError, r"forward_speed = -2"),
    ({"forward_speed": 1e30}, ValueError, r"forward_speed = 1e30: outside its plausible range \[0, 10\] units per step"),
    ({"render_mode": "ansi"}, ValueError, r"render_mode = 'ansi': expected None or 'rgb_array'"),
    ({"render_mode": "rgb_array", "render_size": 5}, ValueError, r"render_size = 5: must be a whole number of pixels"),
    ({"robots": "eight"}, TypeError, r"robots = 'eight': expected a whole number"),
    ({"robots": 2.5}, TypeError, r"robots = 2.5: expected a whole number"),
    ({"pucks": True}, TypeError, r"pucks = True: expected a whole number"),
    ({"seed": 2**70}, ValueError, r"seed = 1180591620717411303424: must be a whole number from 0 to 2\*\*63 - 1"),
    ({"pucks": 2**70}, ValueError, r"pucks = 1180591620717411303424: not a 64-bit whole number"),
    ({"robts": 8}, TypeError, r"unknown keyword argument 'robts' \(did you mean 'robots'\?\): the environment takes field, robots, pucks"),
    ({"robot": 8}, TypeError, r"unknown keyword argument 'robot' \(did you mean 'robots'\?\)"),
    ({"field": "square"}, ValueError, r"no field is named \"square\" .* annulus, letter:X \(X one of T, I, L, V, X, Z\), thesis:X"),
    # the world's settings the environments take by name
    ({"noise": -1}, ValueError, r"noise = -1: outside its plausible range \[0, 5\]"),
    ({"noise": True}, TypeError, r"noise = True: expected a number or a name"),
    ({"walls": "rubber"}, ValueError, r"walls = \"rubber\": unknown variant `rubber`, expected `clamp` or `segments`"),
]


@pytest.mark.parametrize("make", [zumo_swarm.parallel_env, zumo_swarm.gym_env, lambda **s: zumo_swarm.vector_env(2, **s)],
                         ids=["parallel", "gym", "vector"])
@pytest.mark.parametrize("settings, error, message", BAD_SETTINGS, ids=[str(s) for s, _, _ in BAD_SETTINGS])
def test_a_bad_setting_is_refused_with_its_name_and_problem(make, settings, error, message):
    with pytest.raises(error, match=message) as caught:
        make(**settings)
    assert not_a_panic(caught.value)


def test_bad_vector_env_arguments_are_named():
    with pytest.raises(ValueError, match="num_worlds = 0"):
        zumo_swarm.vector_env(0)
    with pytest.raises(ValueError, match="threads = 0"):
        zumo_swarm.vector_env(2, threads=0)
    # refused before a million worlds are allocated
    with pytest.raises(ValueError, match=r"num_worlds = 1000000: outside its plausible range \[1, 4096\]"):
        zumo_swarm.vector_env(10**6)
    with pytest.raises(ValueError, match="autoreset_mode = 'sometimes'"):
        zumo_swarm.vector_env(2, autoreset_mode="sometimes")
    env = zumo_swarm.vector_env(2, robots=2, pucks=5)
    with pytest.raises(ValueError, match="seed: got 3 seeds for 2 worlds"):
        env.reset(seed=[1, 2, 3])
    with pytest.raises(ValueError, match=r"seed = -4: must be a whole number from 0 to 2\*\*63 - 1"):
        env.reset(seed=[1, -4])
    with pytest.raises(ValueError, match="seed = -1"):
        zumo_swarm.parallel_env(robots=2, pucks=5).reset(seed=-1)


@pytest.mark.parametrize(
    "actions, error, message",
    [
        (np.zeros((2, 3), dtype=np.int64), ValueError, r"actions: expected an array of shape \(2, 2\), got shape \(2, 3\)"),
        (np.full((2, 2), 4), ValueError, r"actions\[0, 0\] = 4: must be an action index in 0..4"),
        (np.array([[0, 1], [2, -1]]), ValueError, r"actions\[1, 1\] = -1"),
        (np.zeros((2, 2)), TypeError, r"actions: expected integers"),
        ([["a", "b"], ["c", "d"]], TypeError, r"actions: expected integers"),
    ],
)
def test_bad_actions_are_refused_with_the_world_and_robot_named_and_no_world_moves(actions, error, message):
    env = zumo_swarm.vector_env(2, robots=2, pucks=5)
    obs, _ = env.reset(seed=1)
    with pytest.raises(error, match=message):
        env.step(actions)
    assert np.array_equal(env.batch.observations(), obs)
    _, _, _, _, info = env.step(np.zeros((2, 2), dtype=np.int64))
    assert (info["total_steps"] == 1).all()


def test_a_non_finite_continuous_action_is_named():
    env = zumo_swarm.gym_env(robots=2, pucks=5, action="continuous")
    env.reset()
    with pytest.raises(ValueError, match=r"actions\[0, 1\] = NaN: must be a finite angular speed"):
        env.step(np.array([0.1, np.nan]))


@pytest.mark.parametrize(("settings", "robots", "pucks"), [
    ({}, 8, 250),
    ({"sensors": "disc"}, 8, 250),
    ({"sensors": "disc-thesis"}, 8, 250),
    ({"sensors": "robot"}, 5, 12),  # the settings table: the TV's counts, as tv75 is the robot's default arena
    ({"sensors": "robot", "arena": "thesis"}, 8, 250),
    ({"arena": "tv75"}, 5, 12),
])
def test_the_settings_tables_default_counts_hold_for_every_sensor_model(settings, robots, pucks):
    env = zumo_swarm.parallel_env(**settings)
    env.reset()
    assert len(env.possible_agents) == robots
    assert env.state().shape == (5 * robots + 3 * pucks,), "5 values a robot, 3 a puck"


def test_the_tv_arena_is_the_robot_senses_default_and_brings_its_own_counts():
    robot = zumo_swarm.parallel_env(sensors="robot")
    assert len(robot.possible_agents) == 5
    tv = zumo_swarm.parallel_env(arena="tv75")
    assert len(tv.possible_agents) == 5
    thesis = zumo_swarm.parallel_env(sensors="robot", arena="thesis", robots=3)
    assert len(thesis.possible_agents) == 3


def test_every_world_setting_is_a_keyword_and_reaches_the_world():
    assert set(zumo_swarm._native.WORLD_SETTINGS) <= set(zumo_swarm._settings.SETTINGS)
    # noise: the same seed moves the robots otherwise
    runs = []
    for noise in (0, 1, 1):
        env = zumo_swarm.vector_env(1, robots=2, pucks=5, sensors="robot", noise=noise)
        env.reset(seed=3)
        for _ in range(50):
            obs, *_ = env.step(np.zeros((1, 2), dtype=np.int64))
        runs.append(obs)
    assert not np.array_equal(runs[0], runs[1]) and np.array_equal(runs[1], runs[2])



def test_the_stuck_limit_a_world_setting_truncates_episodes_where_it_says():
    env = zumo_swarm.vector_env(1, robots=2, pucks=5, stuck_limit=30)
    env.reset(seed=1)
    ends = []
    for step in range(1, 31):
        _, _, terminated, truncated, _ = env.step(np.zeros((1, 2), dtype=np.int64))
        if terminated[0] or truncated[0]:
            ends.append(step)
    assert ends == [30]
