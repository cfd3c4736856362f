"""Steps per second of a VMAS scenario on CPU, random continuous actions:
`pucks`, the standard configuration's bodies (8 agents and 250 movable
passive discs of the agents' size, at our arena's density: a disc's radius
is 1/80 of the arena side), or a scenario of VMAS's own with its defaults
(`--agents` to set its `n_agents`). Runs in a virtual environment with
VMAS installed (not a dependency of this project; the version
python/benchmarks/throughput.py pins); prints one JSON object, the VMAS
and PyTorch versions among its fields.

    /tmp/vmas-venv/bin/python python/benchmarks/vmas_steps.py --scenario transport --envs 64 --steps 20 --threads 1
"""

import argparse
import json
import time

import torch
import vmas
from vmas import make_env
from vmas.simulator.core import Agent, Landmark, Sphere, World
from vmas.simulator.scenario import BaseScenario
from vmas.simulator.utils import ScenarioUtils

RADIUS = 2.0 / 80  # arena side 2 (semidim 1); ours: radius 10 in 800


class PuckScenario(BaseScenario):
    """Agents among movable pucks that collide with everything: our
    standard configuration's bodies in VMAS's simulator."""

    def make_world(self, batch_dim, device, **kwargs):
        n_agents = kwargs.pop("n_agents", 8)
        n_pucks = kwargs.pop("n_pucks", 250)
        ScenarioUtils.check_kwargs_consumed(kwargs)
        world = World(batch_dim, device, x_semidim=1.0, y_semidim=1.0)
        for i in range(n_agents):
            world.add_agent(Agent(name=f"agent_{i}", shape=Sphere(RADIUS)))
        for i in range(n_pucks):
            world.add_landmark(Landmark(name=f"puck_{i}", collide=True, movable=True, shape=Sphere(RADIUS)))
        return world

    def reset_world_at(self, env_index=None):
        ScenarioUtils.spawn_entities_randomly(
            self.world.entities, self.world, env_index, min_dist_between_entities=2.2 * RADIUS,
            x_bounds=(-1.0, 1.0), y_bounds=(-1.0, 1.0),
        )

    def observation(self, agent):
        return torch.cat([agent.state.pos, agent.state.vel], dim=-1)

    def reward(self, agent):
        return torch.zeros(self.world.batch_dim, device=self.world.device)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--envs", type=int, required=True)
    parser.add_argument("--steps", type=int, default=20, help="env.step calls to time (each steps every env)")
    parser.add_argument("--scenario", default="pucks", help="'pucks' (8 agents, 250 pucks) or a scenario of VMAS's own")
    parser.add_argument("--agents", type=int, help="n_agents of a scenario of VMAS's own [default: the scenario's]")
    parser.add_argument("--threads", type=int, default=2, help="PyTorch's threads")
    parser.add_argument("--warmup", type=int, default=10, help="untimed env.step calls first")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    if args.scenario == "pucks":
        env = make_env(PuckScenario(), num_envs=args.envs, device="cpu", continuous_actions=True, seed=0)
    else:
        own = {} if args.agents is None else {"n_agents": args.agents}
        env = make_env(args.scenario, num_envs=args.envs, device="cpu", continuous_actions=True, seed=0, **own)
    env.reset()
    gen = torch.Generator().manual_seed(0)

    def actions():
        return [torch.rand((args.envs, 2), generator=gen) * 2 - 1 for _ in env.agents]

    for _ in range(args.warmup):  # warm-up: the first calls pay for allocation and caching
        env.step(actions())
    start, cpu = time.perf_counter(), time.process_time()
    for _ in range(args.steps):
        env.step(actions())
    seconds, cpu_seconds = time.perf_counter() - start, time.process_time() - cpu
    print(json.dumps({
        "scenario": args.scenario, "agents": len(env.agents), "bodies": len(env.world.entities), "envs": args.envs,
        "calls": args.steps, "seconds": seconds, "steps_per_second": args.envs * args.steps / seconds,
        "steps_per_cpu_second": args.envs * args.steps / cpu_seconds,
        "vmas": vmas.__version__, "torch": torch.__version__, "threads": torch.get_num_threads(),
    }))


if __name__ == "__main__":
    main()
