"""animkit.fluid: fluid simulations (docs/fluid.md has the scene format).

    sim = animkit.fluid.preset("dam")   # presets: dam, pour, splash
    sim.step(60)
    sim.positions                  # (N, 3) float32 view of the current state
"""
import os
from typing import Union

from . import _core


def preset(name: str, **options) -> _core.Sim:
    """The fluid preset `name` (dam, pour, splash). Options: threads (1..64), count (particles, 0: 4000)."""
    return _core.sim_preset("fluid", name, **options)


def load(path: Union[str, os.PathLike], **options) -> _core.Sim:
    """A fluid scene file (JSON, docs/fluid.md); errors name the key path. Options: threads."""
    return _core.sim_load("fluid", path, **options)
