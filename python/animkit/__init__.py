"""animkit: character animation and deformation (Python bindings of the animkit C library).

    import animkit as ak
    scene = ak.load("CesiumMan.glb")              # also "builtin:humanoid", .bvh, .gltf
    pose = scene.sample(clip=0, time=0.5)         # pose.model_matrices: (J, 4, 4) float32
    verts = scene.skin(pose, method="lbs")        # (N, 3) float32, "dqs" and "cor" too
    img = scene.render(time=0.5, size=(320, 240)) # (240, 320, 4) uint8
    sim = ak.cloth.preset("flag"); sim.step(60); sim.positions   # particles, fluid, boids too

Arrays are numpy arrays without copies: mesh data are read-only views of the scene's memory,
results are written straight into the arrays returned. Failures raise animkit.Error subclasses
carrying the library's message (.message), the file or item (.path) and the result code (.code).
See docs/python.md.
"""
from ._core import (  # noqa: F401
    ArgumentError,
    DataError,
    Error,
    FileError,
    Mesh,
    NoMemoryError,
    NotFoundError,
    ParseError,
    Pose,
    Scene,
    Sim,
    UnsupportedError,
    __version__,
    builtin_names,
    load,
    retarget,
    write_png,
)
from . import boids, cloth, fluid, particles  # noqa: F401,E402  (sim = animkit.cloth.preset("flag"))


def __getattr__(name):
    """animkit.batch (Dask) is imported on first use: dask's import takes a second."""
    if name == "batch":
        import importlib
        return importlib.import_module(".batch", __name__)
    raise AttributeError(f"module 'animkit' has no attribute '{name}'")


__all__ = [
    "ArgumentError", "DataError", "Error", "FileError", "Mesh", "NoMemoryError", "NotFoundError",
    "ParseError", "Pose", "Scene", "Sim", "UnsupportedError", "__version__", "builtin_names", "load",
    "retarget", "write_png", "boids", "cloth", "fluid", "particles",
]
