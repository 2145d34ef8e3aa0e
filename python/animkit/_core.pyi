"""Type stubs of animkit._core, the C extension behind the package `animkit` (docs/python.md)."""
import os
from typing import List, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, bytes, os.PathLike]
ClipRef = Union[int, str, None]

class Error(Exception):
    """An animkit failure: message (the library's message), path (the file or item it is
    about, or None) and code (the ak_result name, e.g. 'AK_ERR_PARSE')."""
    message: str
    path: Optional[str]
    code: str

class FileError(Error):
    """A file could not be opened, read or written (AK_ERR_IO)."""

class ParseError(Error):
    """A file is malformed (AK_ERR_PARSE)."""

class DataError(Error):
    """Bad values: NaN or infinity, indices out of range, bad weights, hierarchy or keys."""

class NotFoundError(Error):
    """A named item (joint, clip, mesh, built-in model) is not there (AK_ERR_NOT_FOUND)."""

class UnsupportedError(Error):
    """A feature animkit does not support, or a work or memory budget exceeded."""

class ArgumentError(Error, ValueError):
    """An argument outside its documented range."""

class NoMemoryError(Error, MemoryError):
    """Out of memory."""

class SkinInfo(TypedDict):
    name: str
    joints: npt.NDArray[np.int32]
    """Skeleton joint per skin slot (read-only view)."""
    inverse_binds: npt.NDArray[np.float32]
    """(slots, 4, 4) model-space inverse bind matrices (read-only view)."""

class IKResult(TypedDict):
    reached: bool
    error: float
    """Distance from the effector to the target after solving, model units."""
    iterations: int
    solver: str
    joints: List[str]
    """The chain, root to effector."""
    positions: npt.NDArray[np.float32]
    """(n, 3) model-space positions of the chain's joints after solving."""
    initial: npt.NDArray[np.float32]
    """(n, 3) the same before solving."""
    pose: "Pose"
    """The solved pose (feed it to Scene.skin)."""

class Mesh:
    """One mesh of a scene (Scene.meshes[i]); its arrays are read-only views of the scene's memory."""
    @property
    def name(self) -> str: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]:
        """(N, 3) bind-space vertex positions."""
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]:
        """(N, 3) bind-space normals, or None."""
    @property
    def indices(self) -> npt.NDArray[np.uint32]:
        """(T, 3) triangles, counter-clockwise from outside."""
    @property
    def joints(self) -> npt.NDArray[np.uint16]:
        """(N, K) skin slots per vertex (K = 0 when unskinned)."""
    @property
    def weights(self) -> npt.NDArray[np.float32]:
        """(N, K) skin weights per vertex."""
    @property
    def skin(self) -> int:
        """Index into Scene.skins, -1 when unskinned."""

class Pose:
    """A pose of a scene's skeleton (Scene.sample, Scene.rest_pose, Scene.ik)."""
    @property
    def local(self) -> npt.NDArray[np.float32]:
        """(J, 10) writable view: translation xyz, rotation quaternion xyzw, scale xyz."""
    @property
    def model_matrices(self) -> npt.NDArray[np.float32]:
        """(J, 4, 4) model-space joint matrices, forward kinematics of `local` (recomputed on
        each access); m[j] @ (x, y, z, 1) maps joint space to model space. Read-only."""
    @property
    def morph_weights(self) -> npt.NDArray[np.float32]:
        """Morph target weights in the scene's flat morph index space (writable view)."""
    @property
    def scene(self) -> "Scene": ...

class Scene:
    """A skeleton, its meshes, skins and clips (animkit.load, animkit.retarget). Read-only;
    safe to share between threads."""
    @property
    def name(self) -> str:
        """File name or 'builtin:NAME'."""
    @property
    def joint_names(self) -> List[str]:
        """Names of the skeleton's joints, parents first."""
    @property
    def parents(self) -> npt.NDArray[np.int32]:
        """Parent index per joint, -1 for roots (read-only view)."""
    @property
    def clip_names(self) -> List[str]: ...
    @property
    def clip_durations(self) -> List[float]:
        """Seconds per clip."""
    @property
    def meshes(self) -> Tuple[Mesh, ...]: ...
    @property
    def skins(self) -> List[SkinInfo]: ...
    def sample(self, clip: ClipRef = 0, time: float = 0.0) -> Pose:
        """The local pose of clip (index or name; None: the rest pose; default the first clip)
        at time seconds (clamped to the clip), as `animkit export --clip C --time T` poses it."""
    def rest_pose(self) -> Pose:
        """The skeleton's rest pose."""
    def skin(self, pose: Pose, method: str = "lbs", mesh: int = 0,
             out: Optional[npt.NDArray[np.float32]] = None) -> npt.NDArray[np.float32]:
        """(N, 3) float32 world-space vertices of mesh `mesh` in `pose` ('lbs', 'dqs', 'cor', 'implicit' or 'soft'):
        bit for bit what `animkit export --time T --method M` writes. out: a writable
        C-contiguous (N, 3) float32 array to write into (returned)."""
    def ik(self, effector: str, target: Sequence[float], solver: Optional[str] = "fabrik",
           root: Optional[str] = None, iterations: int = 0, tolerance: float = 0.0,
           clip: ClipRef = None, time: float = 0.0) -> IKResult:
        """Solve root..effector towards target (x, y, z) as `animkit ik` does ('ccd', 'fabrik',
        'twobone', 'dls'; from the rest pose, or clip at time)."""
    def render(self, time: float = 0.0, size: Tuple[int, int] = (640, 480), clip: ClipRef = 0,
               method: Optional[str] = "lbs", camera: Optional[Tuple[float, ...]] = None,
               fov: float = 0.0, skeleton: bool = False,
               out: Optional[npt.NDArray[np.uint8]] = None) -> npt.NDArray[np.uint8]:
        """(H, W, 4) uint8 RGBA frame, the pixels `animkit render --time T --size WxH` writes.
        camera: (yaw, pitch[, distance]) degrees; fov: degrees (0 -> 40)."""
    def save(self, path: PathLike) -> None:
        """Write the scene as glTF 2.0 (.glb, or .gltf + .bin), atomically."""

class Sim:
    """A running simulation (animkit.cloth / particles / boids / fluid .preset or .load)."""
    @property
    def positions(self) -> npt.NDArray[np.float32]:
        """(N, 3) current positions: a read-only view that changes with each step (copy it to
        keep a frame). Particles and fluid: the live particles."""
    @property
    def velocities(self) -> npt.NDArray[np.float32]:
        """(N, 3) current velocities, a read-only view."""
    @property
    def kind(self) -> str:
        """'cloth', 'particles', 'boids' or 'fluid'."""
    @property
    def name(self) -> str:
        """The preset name or scene file."""
    @property
    def steps_done(self) -> int: ...
    @property
    def steps(self) -> int:
        """The scene's own step count (what the command runs by default)."""
    @property
    def dt(self) -> float:
        """Seconds per step."""
    def step(self, steps: int = 1) -> None:
        """Advance by `steps` steps (GIL released); after n steps the state is the one
        `animkit KIND --preset NAME --steps n` ends with, bit for bit."""

def sim_preset(kind: str, name: str, count: int = 0, seed: int = -1, threads: int = 1) -> Sim:
    """A preset of kind 'cloth', 'particles', 'boids' or 'fluid' (animkit.<kind>.preset)."""

def sim_load(kind: str, path: PathLike, seed: int = -1, threads: int = 1) -> Sim:
    """A scene file of that kind (animkit.<kind>.load); errors name the key path."""

def fnv1a64_file(path: PathLike) -> str:
    """FNV-1a 64 of a file's bytes as 16 hex digits."""

def write_png(path: PathLike, image: npt.ArrayLike) -> None:
    """Write an (H, W, 4) uint8 RGBA array as a PNG file, atomically."""

def batch_run_job(line: str, name: Optional[str] = None, input_dir: Optional[str] = None,
                  output_dir: Optional[str] = None, index: int = 0, force: bool = False) -> str:
    """Only when the library has animkit/batch.h: one job line run by ak_batch_run_job; the
    row as JSON (animkit.batch.run_job uses it when present)."""

def _bench_c(scene: Scene, clip: int, time: float, method: str, mesh: int, count: int) -> float:
    """Seconds per sample + skin in a C loop (bench/bench_python.py's reference)."""

def load(path: PathLike) -> Scene:
    """Load a model file (.glb, .gltf, .bvh; FBX/Collada/OBJ through Assimp when built with
    it) or a built-in model ('builtin:humanoid', 'builtin:cylinder')."""

def retarget(source: Scene, target: Scene, map: Optional[PathLike] = None, clip: ClipRef = 0,
             fps: float = 30.0, feet: bool = True, scaled: bool = True) -> Scene:
    """Retarget a clip of source onto target's skeleton as `animkit retarget` does; returns the
    target with the one retargeted clip (.save('out.glb') writes it)."""

def builtin_names() -> List[str]:
    """Names of the built-in models."""
