"""Python overhead per call of animkit's bindings (docs/BENCHMARKS.md, "batch jobs and Python bindings").

    make python && PYTHONPATH=python /usr/bin/python3 bench/bench_python.py [MODEL]

For sample + skin (LBS, one mesh) of CesiumMan (or MODEL; builtin:humanoid without the assets):
the same C functions timed in a C loop (animkit._core._bench_c) and called from Python, side by
side in one run, best of several rounds each. The difference is what Python adds per
sample + skin pair (argument parsing, the Pose object, the numpy array, the GIL and the scene's
lock); the target is <= 2 us. Also: the cost of skin with a new array vs out=.
"""
import os
import sys
import time

import numpy as np

import animkit as ak
from animkit import _core

HERE = os.path.dirname(os.path.abspath(__file__))
ASSETS = os.environ.get("ANIMKIT_ASSETS") or os.path.join(HERE, "..", "..", "shared", "assets")


def once(f, n):
    t0 = time.thread_time()  # CPU time of this thread: steadier than wall time on a shared machine
    f(n)
    return (time.thread_time() - t0) / n


def main():
    spec = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ASSETS, "gltf", "CesiumMan", "glTF-Binary", "CesiumMan.glb")
    if not os.path.exists(spec) and not spec.startswith("builtin:"):
        spec = "builtin:humanoid"
    scene = ak.load(spec)
    mesh = scene.meshes[0]
    out = np.empty_like(mesh.positions)
    t = 0.5

    def py_out(n):
        for _ in range(n):
            scene.skin(scene.sample(0, t), "lbs", 0, out)

    def py_new(n):
        for _ in range(n):
            scene.skin(scene.sample(0, t), "lbs", 0)

    def py_kw(n):
        for _ in range(n):
            scene.skin(scene.sample(clip=0, time=t), method="lbs", mesh=0, out=out)

    n = 2000
    py_out(200)
    # rounds interleaved (C, then each Python form), best of each: load on the machine hits all alike
    c, p_out, p_kw, p_new = [], [], [], []
    for _ in range(9):
        c.append(_core._bench_c(scene, 0, t, "lbs", 0, n))
        p_out.append(once(py_out, n))
        p_kw.append(once(py_kw, n))
        p_new.append(once(py_new, n))
    c1, c2 = c[0], c[-1]
    c, p_out, p_kw, p_new = min(c), min(p_out), min(p_kw), min(p_new)
    print(f"model {scene.name}: {len(mesh.positions)} vertices, {len(scene.joint_names)} joints")
    print(f"C loop            {c * 1e6:9.2f} us per sample+skin   ({1 / c:10.0f} per s)")
    print(f"Python, out=      {p_out * 1e6:9.2f} us   overhead {(p_out - c) * 1e6:6.2f} us   ratio {p_out / c:5.3f}")
    print(f"Python, keywords  {p_kw * 1e6:9.2f} us   overhead {(p_kw - c) * 1e6:6.2f} us   ratio {p_kw / c:5.3f}")
    print(f"Python, new array {p_new * 1e6:9.2f} us   overhead {(p_new - c) * 1e6:6.2f} us   ratio {p_new / c:5.3f}")
    print(f"C loop: first round {c1 * 1e6:.2f} us, last {c2 * 1e6:.2f} us (CPU time of the thread, best of 9 rounds)")


if __name__ == "__main__":
    main()
