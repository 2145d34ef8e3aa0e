"""Tests of the Python package `animkit` (python/, docs/python.md).

Run by ctest (test_python, through tests/python/run.py) with PYTHONPATH naming the built package,
ANIMKIT_CLI the `animkit` command and ANIMKIT_ASSETS (optional) the shared assets. References:
the command's own outputs (bit for bit), closed forms computed here in numpy (forward kinematics,
linear blend skinning), and physical properties; never the binding's own output.
"""
import json
import os
import struct
import subprocess
import sys
import threading
import tracemalloc
import zlib
from functools import lru_cache

import numpy as np
import pytest

import animkit as ak

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.environ.get("ANIMKIT_CLI", "")
ASSETS = os.environ.get("ANIMKIT_ASSETS") or os.path.join(HERE, "..", "..", "..", "shared", "assets")
CESIUM = os.path.join(ASSETS, "gltf", "CesiumMan", "glTF-Binary", "CesiumMan.glb")
BVH = os.path.join(ASSETS, "bvh", "49_04.bvh")

need_cli = pytest.mark.skipif(not os.access(CLI, os.X_OK), reason="ANIMKIT_CLI (the animkit command) not set")


def models():
    """builtin:humanoid costs 0.35 s to build: the fast checks use the cylinder and CesiumMan."""
    return ["builtin:cylinder"] + ([CESIUM] if os.path.exists(CESIUM) else [])


@lru_cache(maxsize=None)
def load(spec):
    """Scenes are read-only: each test model is loaded once."""
    return ak.load(spec)


# Under AK_SANITIZE this process runs with the sanitizer runtime preloaded; the command links
# its own copy, so its environment goes without the preload.
CLI_ENV = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
SANITIZED = "asan" in os.environ.get("LD_PRELOAD", "")


def cli(*args):
    r = subprocess.run([CLI, args[0], "--quiet", *args[1:]], capture_output=True, text=True, env=CLI_ENV)
    assert r.returncode == 0, r.stderr
    return r.stdout


def obj_vertices(path):
    """The 'v' lines of each 'o' group of an OBJ file, as float32 arrays (9 significant digits
    give every float32 back exactly)."""
    groups, cur = [], None
    with open(path) as f:
        for line in f:
            if line.startswith("o "):
                cur = []
                groups.append(cur)
            elif line.startswith("v "):
                cur.append([float(x) for x in line.split()[1:4]])
    return [np.array(g, dtype=np.float32) for g in groups]


def read_png_rgba(path):
    """8-bit RGBA PNG (what ak_png_write writes) decoded with zlib and the five filters."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and ctype == 6
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * 4
    img = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        out = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            a = out[x - 4] if x >= 4 else 0
            b = prev[x]
            c = prev[x - 4] if x >= 4 else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            out[x] = (line[x] + p) & 255
        img[y] = out
        prev = out
    return img.reshape(h, w, 4)


# ---- the minimum contract -------------------------------------------------------------------

def test_contract_builtin():
    scene = load("builtin:humanoid")
    assert isinstance(scene.joint_names, list) and "left_wrist" in scene.joint_names
    assert isinstance(scene.clip_names, list) and len(scene.clip_names) >= 1
    mesh = scene.meshes[0]
    pos = mesh.positions
    assert pos.dtype == np.float32 and pos.ndim == 2 and pos.shape[1] == 3 and pos.shape[0] > 0
    assert not pos.flags.writeable  # a view of the scene's memory
    assert np.shares_memory(pos, scene.meshes[0].positions)  # zero copy: the same memory twice
    pose = scene.sample(clip=0, time=0.5)
    m = pose.model_matrices
    assert m.shape == (len(scene.joint_names), 4, 4) and m.dtype == np.float32
    np.testing.assert_array_equal(m[:, 3, :], np.tile([0, 0, 0, 1], (m.shape[0], 1)))
    verts = scene.skin(pose, method="lbs", mesh=0)
    assert verts.shape == pos.shape and verts.dtype == np.float32
    img = scene.render(time=0.5, size=(80, 60))
    assert img.shape == (60, 80, 4) and img.dtype == np.uint8
    assert img[..., 3].min() == 255 and len(np.unique(img.reshape(-1, 4), axis=0)) > 4  # a picture, not a fill
    res = scene.ik(effector="left_wrist", target=(0.3, 1.2, 0.1), solver="fabrik")
    assert res["reached"] and res["joints"][-1] == "left_wrist"
    np.testing.assert_allclose(res["positions"][-1], [0.3, 1.2, 0.1], atol=1e-3)
    assert ak.__version__ and "humanoid" in ak.builtin_names()


def test_model_matrices_are_forward_kinematics():
    """pose.model_matrices against FK composed here from pose.local (T * R * S, parents first)."""
    for spec in models() + ["builtin:humanoid"]:
        scene = load(spec)
        pose = scene.sample(time=0.37)
        local, parents = pose.local.astype(np.float64), scene.parents
        world = []
        for j in range(len(parents)):
            t, q, s = local[j, 0:3], local[j, 3:7], local[j, 7:10]
            x, y, z, w = q / np.linalg.norm(q)
            r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                          [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                          [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            m = np.eye(4)
            m[:3, :3] = r * s
            m[:3, 3] = t
            world.append(m if parents[j] < 0 else world[parents[j]] @ m)
        scale = max(1.0, max(np.abs(w).max() for w in world))
        np.testing.assert_allclose(pose.model_matrices, np.array(world), atol=2e-5 * scale, err_msg=spec)


def test_skin_against_numpy_lbs():
    """LBS as glTF defines it, sum_k w_k world[joint_k] inverse_bind_k p, in float64 here."""
    for spec in models() + ["builtin:humanoid"]:
        scene = load(spec)
        pose = scene.sample(time=0.8)
        world = pose.model_matrices.astype(np.float64)
        for i, mesh in enumerate(scene.meshes):
            if mesh.skin < 0 or mesh.joints.shape[1] == 0:
                continue
            skin = scene.skins[mesh.skin]
            palette = world[skin["joints"]] @ skin["inverse_binds"].astype(np.float64)
            p = np.c_[mesh.positions.astype(np.float64), np.ones(len(mesh.positions))]
            mats = np.einsum("vk,vkij->vij", mesh.weights.astype(np.float64), palette[mesh.joints])
            want = np.einsum("vij,vj->vi", mats, p)[:, :3]
            got = scene.skin(pose, method="lbs", mesh=i)
            np.testing.assert_allclose(got, want, atol=1e-5 * max(1.0, np.abs(want).max()), err_msg=spec)


def test_skin_methods_agree_on_rigid_motion():
    """In the rest pose every method gives the bind vertices of a skinned mesh (identity palette
    relative to the bind pose is a rigid motion all three methods reproduce)."""
    scene = load("builtin:cylinder")
    pose = scene.rest_pose()
    for method in ("lbs", "dqs", "cor"):
        v = scene.skin(pose, method=method)
        np.testing.assert_allclose(v, scene.meshes[0].positions, atol=1e-5)


# ---- equal to the command, bit for bit ------------------------------------------------------

@need_cli
@pytest.mark.parametrize("method", ["lbs", "dqs", "cor"])
def test_skin_equals_export(tmp_path, method):
    for spec in models()[:1] if method != "lbs" else models():  # CoR centres of CesiumMan: 1 s
        scene = load(spec)
        for t in (0.55,):
            out = str(tmp_path / "x.obj")
            cli("export", spec, "--time", repr(t), "--method", method, "-o", out)
            groups = obj_vertices(out)
            pose = scene.sample(time=t)
            assert len(groups) == len(scene.meshes)
            for i, want in enumerate(groups):
                got = scene.skin(pose, method=method, mesh=i)
                assert got.tobytes() == want.tobytes(), f"{spec} t={t} mesh {i}: differs from animkit export"


@need_cli
def test_ik_equals_command():
    spec, target = "builtin:cylinder", (0.3, 1.2, 0.1)
    for solver in ("fabrik", "ccd", "dls", "twobone"):
        want = json.loads(cli("ik", spec, "--effector", "tip", "--target", "0.3,1.2,0.1", "--solver", solver, "--json"))
        got = load(spec).ik(effector="tip", target=target, solver=solver)
        assert got["reached"] == want["reached"] and got["iterations"] == want["iterations"], solver
        assert got["joints"] == [j["name"] for j in want["joints"]]
        np.testing.assert_array_equal(got["positions"], np.array([j["position"] for j in want["joints"]], np.float32))
        np.testing.assert_array_equal(got["initial"], np.array([j["position"] for j in want["initial"]], np.float32))
        assert np.float32(got["error"]) == np.float32(want["error"])


@need_cli
def test_render_equals_command(tmp_path):
    for spec in models():
        out = str(tmp_path / "r.png")
        cli("render", spec, "--time", "0.5", "--size", "72x48", "-o", out)
        got = load(spec).render(time=0.5, size=(72, 48))
        np.testing.assert_array_equal(got, read_png_rgba(out), err_msg=spec)


@need_cli
def test_retarget_save_equals_command(tmp_path):
    if not os.path.exists(BVH):
        pytest.skip("no BVH asset")
    ours, theirs = str(tmp_path / "py.glb"), str(tmp_path / "cli.glb")
    ak.retarget(load(BVH), load("builtin:humanoid"), map=None).save(ours)
    cli("retarget", BVH, "builtin:humanoid", "-o", theirs)
    assert open(ours, "rb").read() == open(theirs, "rb").read()
    back = ak.load(ours)
    assert len(back.clip_names) == 1 and back.clip_durations[0] > 1.0
    assert set(load("builtin:humanoid").joint_names) <= set(back.joint_names)


def test_save_and_load_gltf_round_trip(tmp_path):
    scene = load("builtin:cylinder")
    for ext in (".glb", ".gltf"):
        path = str(tmp_path / ("h" + ext))
        scene.save(path)
        back = ak.load(path)
        assert set(scene.joint_names) <= set(back.joint_names) and back.clip_names == scene.clip_names
        np.testing.assert_array_equal(back.meshes[0].positions, scene.meshes[0].positions)
        t = 0.4
        np.testing.assert_allclose(back.skin(back.sample(time=t)), scene.skin(scene.sample(time=t)), atol=1e-5)


# ---- zero copy, memory, threads -------------------------------------------------------------

def test_out_arrays_are_written_in_place():
    scene = load("builtin:cylinder")
    pose = scene.sample(time=0.3)
    out = np.empty_like(scene.meshes[0].positions)
    res = scene.skin(pose, out=out)
    assert res is out
    np.testing.assert_array_equal(out, scene.skin(pose))
    img = np.zeros((40, 50, 4), np.uint8)
    assert scene.render(size=(50, 40), out=img) is img and img.any()


def rss_kib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024


def test_refcounts_and_memory_stable_over_10000_calls():
    scene = load("builtin:cylinder")
    out = np.empty_like(scene.meshes[0].positions)

    def calls(n):  # 6 calls per round
        for i in range(n):
            pose = scene.sample(clip=0, time=(i % 50) * 0.02)
            scene.skin(pose, method="lbs", out=out)
            scene.skin(pose, method="dqs")
            pose.model_matrices
            scene.meshes[0].positions
            try:
                scene.sample(time=float("nan"))
            except ak.ArgumentError:
                pass
    calls(100)  # warm up caches, the poser and numpy's allocator
    refs = (sys.getrefcount(scene), sys.getrefcount(out), sys.getrefcount(None))
    rss0 = rss_kib()
    tracemalloc.start()
    snap0 = tracemalloc.take_snapshot()
    calls(10000 // 6 + 1)
    snap1 = tracemalloc.take_snapshot()
    tracemalloc.stop()
    grown = sum(s.size_diff for s in snap1.compare_to(snap0, "filename") if s.size_diff > 0)
    assert sys.getrefcount(scene) == refs[0] and sys.getrefcount(out) == refs[1]
    assert abs(sys.getrefcount(None) - refs[2]) < 100
    assert grown < 64 * 1024, f"{grown} bytes of Python memory kept after 10000 calls"
    if not SANITIZED:  # AddressSanitizer's quarantine keeps freed memory resident by design
        assert rss_kib() - rss0 < 4096, "resident memory grew by more than 4 MiB over 10000 calls"


def test_views_keep_the_scene_alive():
    pos = ak.load("builtin:cylinder").meshes[0].positions
    m = ak.load("builtin:cylinder").sample(time=0.2).model_matrices
    assert np.isfinite(pos).all() and np.isfinite(m).all() and pos.shape[0] > 0


def test_threads_share_a_scene():
    scene = load("builtin:cylinder")
    want = [scene.skin(scene.sample(time=k * 0.1)) for k in range(8)]
    bad = []

    def work():
        for _ in range(10):
            for k in range(8):
                if not np.array_equal(scene.skin(scene.sample(time=k * 0.1)), want[k]):
                    bad.append(k)
    ts = [threading.Thread(target=work) for _ in range(4)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not bad


# ---- bad input raises with the message ------------------------------------------------------

def test_errors_carry_message_and_path(tmp_path):
    with pytest.raises(ak.FileError) as e:
        ak.load(str(tmp_path / "missing.glb"))
    assert e.value.path.endswith("missing.glb") and e.value.message == "no such file" and e.value.code == "AK_ERR_IO"
    bad = tmp_path / "bad.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "nodes": [{"children": [5]}]}')
    with pytest.raises(ak.Error) as e:
        ak.load(str(bad))
    assert e.value.path.endswith("bad.gltf") and e.value.message and str(e.value).startswith(str(bad))
    junk = tmp_path / "junk.glb"
    junk.write_bytes(b"glTF\x02\x00\x00\x00\xff\xff\xff\x7f" + b"\x00" * 20)
    with pytest.raises(ak.ParseError):
        ak.load(str(junk))
    with pytest.raises(ak.NotFoundError, match="unknown built-in model"):
        ak.load("builtin:nothing")
    with pytest.raises(ak.FileError, match="is a directory"):
        ak.load(str(tmp_path))
    scene = load("builtin:humanoid")
    pose = scene.sample()
    with pytest.raises(ValueError, match="method must be 'lbs', 'dqs', 'cor', 'implicit' or 'soft', not 'xyz'"):
        scene.skin(pose, method="xyz")
    with pytest.raises(ak.ArgumentError, match="time must be a finite number"):
        scene.sample(time=float("inf"))
    with pytest.raises(ak.NotFoundError, match="no clip named 'nope'"):
        scene.sample(clip="nope")
    with pytest.raises(ak.NotFoundError, match="no clip #99"):
        scene.sample(clip=99)
    with pytest.raises(ak.NotFoundError, match="no mesh #7"):
        scene.skin(pose, mesh=7)
    with pytest.raises(ak.ArgumentError, match="another scene"):
        load("builtin:cylinder").skin(pose)
    with pytest.raises(ak.ArgumentError, match="out= for skin must be"):
        scene.skin(pose, out=np.empty((3, 3), np.float32))
    with pytest.raises(ak.NotFoundError, match="no joint named 'tail'"):
        scene.ik(effector="tail", target=(0, 1, 0))
    with pytest.raises(ak.ArgumentError, match="target must be finite"):
        scene.ik(effector="left_wrist", target=(float("nan"), 1, 0))
    with pytest.raises(ak.ArgumentError, match="size"):
        scene.render(size=(4, 4000000))
    with pytest.raises(ak.FileError, match="cannot read the map file"):
        ak.retarget(load("builtin:cylinder"), scene, map=str(tmp_path / "nomap.txt"))
    badmap = tmp_path / "map.txt"
    badmap.write_text("pelvis = no_such_joint\n")
    with pytest.raises(ak.Error) as e:
        ak.retarget(load("builtin:cylinder"), scene, map=str(badmap))
    assert e.value.path.endswith("map.txt") and "no_such_joint" in e.value.message
    with pytest.raises(ak.FileError):
        scene.save(str(tmp_path / "no" / "dir" / "x.glb"))
    with pytest.raises(TypeError):
        scene.skin("not a pose")
    edited = scene.sample(time=0.3)
    edited.local[1, 3] = float("nan")  # a user's edit: an error, never NaN output
    with pytest.raises(ak.DataError, match="NaN"):
        scene.skin(edited)
    with pytest.raises(ak.DataError, match="NaN"):
        edited.model_matrices


# ---- simulations: ak.cloth / particles / boids / fluid ---------------------------------------

SIMS = [  # (module, preset, command arguments, options, JSON list key)
    ("cloth", "flag", [], {}, "positions"),
    ("particles", "fountain", [], {}, "particles"),
    ("boids", "flock", ["--count", "200"], {"count": 200}, "agents"),
    ("fluid", "dam", ["--count", "500"], {"count": 500}, "particles"),
]


@need_cli
@pytest.mark.parametrize("kind,name,args,options,key", SIMS)
def test_sim_equals_command(tmp_path, kind, name, args, options, key):
    """sim.step(n) ends where `animkit KIND --preset NAME --steps n` does, bit for bit (its JSON's
    9 significant digits give every float32 back)."""
    steps = 12
    out = str(tmp_path / "s.json")
    cli(kind, "--preset", name, "--steps", str(steps), *args, "--json", out)
    rows = json.load(open(out))[key]
    want = np.array([r["p"] if isinstance(r, dict) else r for r in rows], dtype=np.float32)
    sim = getattr(ak, kind).preset(name, **options)
    sim.step(steps // 2)
    sim.step(steps - steps // 2)
    assert sim.steps_done == steps
    got = sim.positions
    assert got.dtype == np.float32 and not got.flags.writeable
    assert got.tobytes() == want.tobytes(), f"{kind} {name}: differs from animkit {kind}"


def test_sim_physics_and_errors(tmp_path):
    """A flag's pinned edge stays put while gravity pulls the rest down; bad input raises."""
    sim = ak.cloth.preset("flag")
    x0 = sim.positions.copy()
    sim.step(30)
    x1 = sim.positions
    still = np.all(x1 == x0, axis=1)
    assert 0 < still.sum() < len(x0) // 4  # the pins, and only them
    assert np.isfinite(x1).all() and x1[~still, 1].mean() < x0[~still, 1].mean()
    with pytest.raises(ak.NotFoundError, match="unknown cloth preset"):
        ak.cloth.preset("sail")
    bad = tmp_path / "bad.json"
    bad.write_text('{"steps": "many"}')
    with pytest.raises(ak.ParseError) as e:
        ak.cloth.load(str(bad))
    assert "steps" in e.value.message
    with pytest.raises(ak.FileError):
        ak.boids.load(str(tmp_path / "missing.json"))
    with pytest.raises(ak.ArgumentError):
        sim.step(-1)


# ---- animkit.batch without a cluster (the Dask run is test_batch_dask.py, slow) ---------------

def test_batch_jobs_rows_and_skip(tmp_path):
    import animkit.batch as batch
    for text, want in ((b"", "cbf29ce484222325"), (b"a", "af63dc4c8601ec8c"), (b"foobar", "85944171f73967e8")):
        (tmp_path / "h").write_bytes(text)  # FNV-1a 64 test vectors (Fowler, Noll, Vo)
        assert batch.hash_file(str(tmp_path / "h")) == want
    job = {"kind": "render", "inputs": {"model": "builtin:cylinder"}, "parameters": {"time": 0.5, "size": [40, 30]},
           "output": "sub/r.png"}
    row = batch.run_job(job, 3, output_dir=str(tmp_path))
    assert row["status"] == "ran" and row["index"] == 3 and row["error"] is None and row["job_hash"]
    img = read_png_rgba(str(tmp_path / "sub" / "r.png"))
    assert img.shape == (30, 40, 4) and len(np.unique(img.reshape(-1, 4), axis=0)) > 1  # a picture, not a fill
    if os.access(CLI, os.X_OK):  # the same picture as `animkit batch` draws (docs/batch.md)
        (tmp_path / "cli").mkdir()
        (tmp_path / "cli" / "m.jsonl").write_text(json.dumps(job) + "\n")
        cli("batch", str(tmp_path / "cli" / "m.jsonl"), "--out", str(tmp_path / "cli"))
        assert read_png_rgba(str(tmp_path / "cli" / "sub" / "r.png")).tobytes() == img.tobytes()
    assert batch.run_job(job, 3, output_dir=str(tmp_path))["status"] == "skipped"
    changed = dict(job, parameters={"time": 0.25, "size": [40, 30]})
    assert batch.run_job(changed, 3, output_dir=str(tmp_path))["status"] == "ran"  # new parameters: runs again
    for bad, msg in (({"kind": "dance", "output": "x"}, "kind"), ({"kind": "render", "inputs": {}, "output": "x.png"},
                     "inputs.model: is required"), ({"kind": "render", "inputs": {"model": str(tmp_path / "no.glb")},
                     "output": "y.png"}, "no.glb"), ("junk", "not an object")):
        r = batch.run_job(bad, 0, output_dir=str(tmp_path))
        assert r["status"] == "failed" and msg in r["error"], r
