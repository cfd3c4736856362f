"""PPO (Stable-Baselines3) on the single-agent view: one network acts for every robot of a world."""
import sys

from stable_baselines3 import PPO

from zumo_swarm.sb3 import SB3VecEnv

steps = int(sys.argv[1]) if len(sys.argv) > 1 else 2_000_000
env = SB3VecEnv(16, observation="reading", max_steps=2_000, seed=1)  # 16 worlds in Rust threads
model = PPO("MlpPolicy", env, n_steps=256, batch_size=1024, learning_rate=3e-4, verbose=1, seed=1)
model.learn(total_timesteps=steps)
model.save("out/ppo-annulus")
