"""animkit.batch on Dask: throughput with 1 and 2 workers and per-job overhead
(docs/BENCHMARKS.md, "batch jobs and Python bindings").

    make python && PYTHONPATH=build/python /usr/bin/python3 bench/bench_batch_dask.py [JOBS] [WxH]

JOBS render jobs (CesiumMan, or builtin:cylinder without the assets, WxH (160x120), each at its own
time) run three ways in one run: in this process one after another (animkit.batch.run_job), and
through animkit.batch.run on a LocalCluster of 1 and of 2 single-threaded worker processes
(force=True so no job is skipped). Prints jobs/s of each, the 2-worker scaling (target >= 1.8x
on a machine with 2 free cores) and the per-job overhead of Dask (1 worker vs in-process).
"""
import os
import shutil
import sys
import tempfile
import time

import animkit.batch as batch

HERE = os.path.dirname(os.path.abspath(__file__))
ASSETS = os.environ.get("ANIMKIT_ASSETS") or os.path.join(HERE, "..", "..", "shared", "assets")


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 48
    w, h = (int(v) for v in (sys.argv[2] if len(sys.argv) > 2 else "160x120").split("x"))
    model = os.path.join(ASSETS, "gltf", "CesiumMan", "glTF-Binary", "CesiumMan.glb")
    if not os.path.exists(model):
        model = "builtin:cylinder"
    jobs = [{"kind": "render", "inputs": {"model": model}, "parameters": {"time": 0.04 * i, "size": [w, h]},
             "output": f"frame_{i:03d}.png"} for i in range(n)]
    out = tempfile.mkdtemp(prefix="bench_batch_")
    try:
        batch.run_job(jobs[0], 0, output_dir=out, force=True)  # warm the page cache
        t0 = time.perf_counter()
        for i, j in enumerate(jobs):
            assert batch.run_job(j, i, output_dir=out, force=True)["status"] == "ran"
        local = time.perf_counter() - t0
        rates = {}
        for workers in (1, 2):
            with batch.local_client(workers=workers) as client:
                batch.run(jobs[:workers * 2], client, output_dir=out, force=True)  # workers import animkit
                t0 = time.perf_counter()
                rows = batch.run(jobs, client, output_dir=out, force=True)
                rates[workers] = time.perf_counter() - t0
                assert all(r["status"] == "ran" for r in rows), [r for r in rows if r["status"] != "ran"][:1]
    finally:
        shutil.rmtree(out, ignore_errors=True)
    print(f"{n} render jobs of {os.path.basename(model)} at {w}x{h}")
    print(f"in-process        {n / local:8.1f} jobs/s   ({local / n * 1e3:7.2f} ms per job)")
    for w in (1, 2):
        print(f"Dask, {w} worker{'s' if w > 1 else ' '}    {n / rates[w]:8.1f} jobs/s   ({rates[w] / n * 1e3:7.2f} ms per job)")
    print(f"scaling 2 vs 1 worker: x{rates[1] / rates[2]:.2f}")
    print(f"Dask overhead per job (1 worker vs in-process): {(rates[1] - local) / n * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
