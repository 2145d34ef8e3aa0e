"""animkit.cloth: cloth simulations (docs/cloth.md has the scene format).

    sim = animkit.cloth.preset("flag")   # presets: flag, curtain, drape, cape
    sim.step(60)
    sim.positions                  # (N, 3) float32 view of the current state
"""
import os
from typing import Union

from . import _core


def preset(name: str, **options) -> _core.Sim:
    """The cloth preset `name` (flag, curtain, drape, cape). Options: threads (1..64)."""
    return _core.sim_preset("cloth", name, **options)


def load(path: Union[str, os.PathLike], **options) -> _core.Sim:
    """A cloth scene file (JSON, docs/cloth.md); errors name the key path. Options: threads."""
    return _core.sim_load("cloth", path, **options)
