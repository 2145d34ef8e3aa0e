"""animkit.batch on a real Dask cluster: a `dask scheduler` and two `dask worker` processes on
127.0.0.1 started here, the shared BVH files retargeted onto builtin:humanoid and CesiumMan, one
worker killed mid-run; the batch still completes (Dask re-runs the lost tasks) with every
output present exactly once and valid (re-loaded: one clip as long as its source). Slow: the
processes take seconds to start on a loaded machine."""
import glob
import importlib.util
import os
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

import animkit as ak

pytestmark = pytest.mark.slow
HERE = os.path.dirname(os.path.abspath(__file__))
ASSETS = os.environ.get("ANIMKIT_ASSETS") or os.path.join(HERE, "..", "..", "..", "shared", "assets")
CESIUM = os.path.join(ASSETS, "gltf", "CesiumMan", "glTF-Binary", "CesiumMan.glb")
# CesiumMan's joints follow no rig convention: TARGET = SOURCE (the CMU BVH names)
CESIUM_MAP = """Skeleton_torso_joint_1 = Hips
leg_joint_L_1 = LeftUpLeg
leg_joint_L_2 = LeftLeg
leg_joint_L_3 = LeftFoot
leg_joint_R_1 = RightUpLeg
leg_joint_R_2 = RightLeg
leg_joint_R_3 = RightFoot
Skeleton_torso_joint_2 = Spine
torso_joint_3 = Spine1
Skeleton_neck_joint_1 = Neck
Skeleton_neck_joint_2 = Head
Skeleton_arm_joint_L__4_ = LeftArm
Skeleton_arm_joint_L__3_ = LeftForeArm
Skeleton_arm_joint_L__2_ = LeftHand
Skeleton_arm_joint_R = RightArm
Skeleton_arm_joint_R__2_ = RightForeArm
Skeleton_arm_joint_R__3_ = RightHand
"""


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start(args, env, log):
    return subprocess.Popen([sys.executable, "-m", *args], env=env, stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None, reason="dask.distributed not installed")
def test_batch_on_dask_survives_a_killed_worker(tmp_path):
    bvhs = sorted(glob.glob(os.path.join(ASSETS, "bvh", "*.bvh")))
    if not bvhs:
        pytest.skip("no BVH assets")
    from dask.distributed import Client

    import animkit.batch as batch
    (tmp_path / "cesium.map").write_text(CESIUM_MAP)
    jobs = []
    for b in bvhs:
        stem = os.path.splitext(os.path.basename(b))[0]
        jobs.append({"kind": "retarget", "id": f"{stem}-humanoid", "inputs": {"source": b, "target": "builtin:humanoid"},
                     "parameters": {"fps": 30}, "output": f"{stem}_humanoid.glb"})
        needed = {line.split("=")[1].strip() for line in CESIUM_MAP.splitlines()}
        if os.path.exists(CESIUM) and needed <= set(ak.load(b).joint_names):  # (131_03 names its joints otherwise)
            jobs.append({"kind": "retarget", "id": f"{stem}-cesium",
                         "inputs": {"source": b, "target": CESIUM, "map": str(tmp_path / "cesium.map")},
                         "parameters": {"fps": 30}, "output": f"{stem}_cesium.glb"})
    out = tmp_path / "out"
    port = free_port()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p), PYTHONDONTWRITEBYTECODE="1")
    log = open(tmp_path / "dask.log", "w")
    addr = f"tcp://127.0.0.1:{port}"
    procs = [start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                   env, log)]
    try:
        for k in range(2):
            procs.append(start(["distributed.cli.dask_worker", addr, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                                "--name", f"w{k}", "--local-directory", str(tmp_path / f"w{k}")], env, log))
        with Client(addr, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
            killed = []

            def kill_one_when_running():
                # the first record on disk: the batch is under way; kill a worker now
                deadline = time.time() + 300
                while time.time() < deadline and not glob.glob(str(out / "*.batch.json")):
                    time.sleep(0.05)
                os.killpg(procs[2].pid, signal.SIGKILL)
                killed.append(time.time())
            t = threading.Thread(target=kill_one_when_running)
            t.start()
            rows = batch.run(jobs, client, output_dir=str(out), manifest=str(tmp_path / "rows.jsonl"))
            t.join()
            assert killed, "no worker was killed"
            # a second run of the same list is idempotent: every job is skipped
            again = batch.run(jobs, client, output_dir=str(out))
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
        log.close()
    assert [r["index"] for r in rows] == list(range(len(jobs)))
    bad = [r for r in rows if r["status"] not in ("ran", "skipped")]
    assert not bad, bad
    assert all(r["status"] == "skipped" for r in again)
    want = sorted(j["output"] for j in jobs)
    assert sorted(os.path.basename(p) for p in glob.glob(str(out / "*.glb"))) == want  # each exactly once
    for job, row in zip(jobs, rows):
        back = ak.load(str(out / job["output"]))
        src = ak.load(job["inputs"]["source"])
        assert len(back.clip_names) == 1
        assert abs(back.clip_durations[0] - src.clip_durations[0]) <= 1.0 / 30 + 1e-6, job["id"]
        assert row["frames"] == round(back.clip_durations[0] * 30) + 1
        assert row["inputs"]["source"]["fnv1a64"] == batch.hash_file(job["inputs"]["source"])
    assert len((tmp_path / "rows.jsonl").read_text().splitlines()) == len(jobs)
