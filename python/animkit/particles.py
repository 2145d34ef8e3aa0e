"""animkit.particles: particles simulations (docs/particles.md has the scene format).

    sim = animkit.particles.preset("fountain")   # fountain, rain, fireworks, character, fire, smoke
    sim.step(60)
    sim.positions                  # (N, 3) float32 view of the current state
"""
import os
from typing import Union

from . import _core


def preset(name: str, **options) -> _core.Sim:
    """The particles preset `name` (fountain, rain, fireworks, character, fire, smoke). Options: threads (1..64), seed (default 1)."""
    return _core.sim_preset("particles", name, **options)


def load(path: Union[str, os.PathLike], **options) -> _core.Sim:
    """A particles scene file (JSON, docs/particles.md); errors name the key path. Options: threads, seed."""
    return _core.sim_load("particles", path, **options)
