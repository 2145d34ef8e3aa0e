"""animkit.boids: boids simulations (docs/boids.md has the scene format).

    sim = animkit.boids.preset("flock")   # presets: flock, obstacles, predator
    sim.step(60)
    sim.positions                  # (N, 3) float32 view of the current state
"""
import os
from typing import Union

from . import _core


def preset(name: str, **options) -> _core.Sim:
    """The boids preset `name` (flock, obstacles, predator). Options: threads (1..64), count (agents), seed."""
    return _core.sim_preset("boids", name, **options)


def load(path: Union[str, os.PathLike], **options) -> _core.Sim:
    """A boids scene file (JSON, docs/boids.md); errors name the key path. Options: threads, seed."""
    return _core.sim_load("boids", path, **options)
