"""The world the agents live in: arenas, bodies, steps, rewards, observations."""

from .pz import parallel_env
from .vec_env import VecEnv

__all__ = ["VecEnv", "parallel_env"]
