"""animkit.batch: batches of animkit jobs mapped over a Dask cluster (docs/batch.md).

A job is a small dict (one line of a JSON-lines manifest):

    {"kind": "retarget", "inputs": {"source": "walk.bvh", "target": "builtin:humanoid"},
     "parameters": {"fps": 30}, "output": "out/walk_humanoid.glb"}
    {"kind": "render", "inputs": {"model": "CesiumMan.glb"}, "parameters": {"time": 0.5,
     "size": [320, 240]}, "output": "out/cesium.png"}

Each job writes its output file (atomically) and returns a manifest row: a dict with index, id,
kind, status ("ran", "skipped" or "failed"), output, inputs (path and FNV-1a 64 content hash of
each), parameters, animkit_version, job_hash, seconds, frames and error. Errors are rows, never
exceptions. A job whose output exists beside a record (OUTPUT.batch.json) of the same job hash is
skipped, so re-running a batch (or a task Dask re-runs after losing a worker) is idempotent.

    from dask.distributed import Client
    import animkit.batch
    rows = animkit.batch.run(jobs, Client("tcp://scheduler:8786"))   # or Client(LocalCluster())

Dask does all the scheduling (retries of tasks whose worker died included): the same job list
runs on a laptop (LocalCluster) or a cluster by changing only the scheduler address. Without
Python, `animkit batch MANIFEST.jsonl --shard i/n` runs the same jobs (docs/batch.md).

When the library has the C job runner (animkit/batch.h, ak_batch_run_job), jobs run through it
(every kind, bake included); otherwise this module runs retarget and render jobs itself through
the bindings, with the same row fields and skip rule.
"""
import json
import os
import time
from typing import Any, Dict, Iterable, List, Optional, Sequence

from . import _core

__all__ = ["run", "run_job", "read_manifest", "write_rows", "job_hash", "hash_file", "local_client"]

FNV_BASIS = 0xCBF29CE484222325
FNV_PRIME = 0x100000001B3
RECORD_SUFFIX = ".batch.json"


def _fnv1a64(data: bytes, h: int = FNV_BASIS) -> int:
    for b in data:
        h = ((h ^ b) * FNV_PRIME) & 0xFFFFFFFFFFFFFFFF
    return h


def hash_file(path: str) -> str:
    """FNV-1a 64 of a file's bytes, as 16 hex digits ("builtin:NAME" hashes its name)."""
    if path.startswith("builtin:"):
        return "%016x" % _fnv1a64(path.encode())
    return _core.fnv1a64_file(path)


def _resolve(path: str, base: Optional[str]) -> str:
    if not path or path.startswith("builtin:") or path.startswith("preset:") or os.path.isabs(path) or not base:
        return path
    return os.path.join(base, path)


def job_hash(job: Dict[str, Any], input_hashes: Dict[str, str]) -> str:
    """The hash that decides whether a job must run again: FNV-1a 64 over the animkit version,
    the kind, each input's role and content hash, and the parameters (canonical JSON)."""
    text = json.dumps({"animkit": _core.__version__, "kind": job.get("kind"), "inputs": input_hashes,
                       "parameters": job.get("parameters", {})}, sort_keys=True, separators=(",", ":"))
    return "%016x" % _fnv1a64(text.encode())


def _run_retarget(job, inputs, out):
    from . import load, retarget
    p = job.get("parameters", {})
    src, dst = load(inputs["source"]), load(inputs["target"])
    res = retarget(src, dst, map=inputs.get("map"), clip=p.get("clip", 0), fps=float(p.get("fps", 30.0)),
                   feet=not p.get("skip_foot_contacts", False), scaled=not p.get("unscaled_root_motion", False))
    res.save(out)
    return int(round(res.clip_durations[0] * float(p.get("fps", 30.0)))) + 1


def _run_render(job, inputs, out):
    from . import load, write_png
    p = job.get("parameters", {})
    w, h = p.get("size", [320, 240])
    write_png(out, load(inputs["model"]).render(time=float(p.get("time", 0.0)), size=(int(w), int(h)),
                                               clip=p.get("clip", 0)))
    return 1


_RUNNERS = {"retarget": (_run_retarget, ("source", "target", "map")), "render": (_run_render, ("model",))}


def _run_job_python(job, index, input_dir, output_dir, force):
    t0 = time.perf_counter()
    row = {"index": index, "id": job.get("id", "") if isinstance(job, dict) else "", "kind": None, "status": "failed",
           "output": None, "inputs": {}, "parameters": {}, "animkit_version": _core.__version__, "job_hash": None,
           "seconds": 0.0, "frames": None, "error": None}
    try:
        if not isinstance(job, dict):
            raise ValueError("a job must be a JSON object (dict)")
        kind = job.get("kind")
        row["kind"], row["parameters"] = kind, job.get("parameters", {})
        if kind not in _RUNNERS:
            raise ValueError(f"kind: '{kind}' is not one of {', '.join(sorted(_RUNNERS))}"
                             + ("" if kind != "bake" else " (bake needs the library's job runner, animkit/batch.h)"))
        if not job.get("output"):
            raise ValueError("output: is required")
        runner, roles = _RUNNERS[kind]
        given = job.get("inputs", {})
        unknown = set(given) - set(roles)
        if unknown:
            raise ValueError(f"inputs.{sorted(unknown)[0]}: unknown input of a {kind} job")
        inputs = {r: _resolve(given[r], input_dir) for r in roles if given.get(r)}
        for r in roles[:1] if kind == "render" else roles[:2]:
            if r not in inputs:
                raise ValueError(f"inputs.{r}: is required")
        hashes = {}
        for r, path in inputs.items():
            hashes[r] = hash_file(path)
            row["inputs"][r] = {"path": path, "fnv1a64": hashes[r]}
        out = _resolve(job["output"], output_dir)
        row["output"] = out
        h = job_hash(job, hashes)
        row["job_hash"] = h
        record = out + RECORD_SUFFIX
        if not force and os.path.exists(out) and os.path.exists(record):
            try:
                with open(record) as f:
                    old = json.load(f)
                if old.get("job_hash") == h:
                    row.update(status="skipped", frames=old.get("frames"),
                               seconds=time.perf_counter() - t0)
                    return row
            except (OSError, ValueError):
                pass
        if os.path.dirname(out):
            os.makedirs(os.path.dirname(out), exist_ok=True)
        row["frames"] = runner(job, inputs, out)
        row["status"] = "ran"
        row["seconds"] = time.perf_counter() - t0
        tmp = f"{record}.{os.getpid()}.tmp"
        with open(tmp, "w") as f:
            json.dump(row, f)
        os.replace(tmp, record)
    except (_core.Error, ValueError, TypeError, KeyError, OSError) as e:
        row["error"] = str(e)
        row["seconds"] = time.perf_counter() - t0
    return row


def run_job(job: Dict[str, Any], index: int = 0, input_dir: Optional[str] = None, output_dir: Optional[str] = None,
            force: bool = False) -> Dict[str, Any]:
    """Run one job (in this process) and return its manifest row; never raises for a bad job."""
    if hasattr(_core, "batch_run_job"):
        try:
            line = json.dumps(job)
        except (TypeError, ValueError) as e:
            return {"index": index, "status": "failed", "error": f"the job is not JSON: {e}"}
        return json.loads(_core.batch_run_job(line, name=f"job {index}", input_dir=input_dir, output_dir=output_dir,
                                              index=index, force=force))
    return _run_job_python(job, index, input_dir, output_dir, force)


def run(jobs: Sequence[Dict[str, Any]], client=None, *, input_dir: Optional[str] = None,
        output_dir: Optional[str] = None, force: bool = False, manifest: Optional[str] = None,
        retries: int = 0) -> List[Dict[str, Any]]:
    """Map jobs over a dask.distributed client (None: the current default client) and gather
    their rows, in job order. Each job is one task (pure=False: a re-run runs again; the skip
    rule makes it cheap); Dask re-runs the tasks of a worker that dies. manifest: also write the
    rows there as JSON lines. retries: extra attempts of a task that raised (a row never does)."""
    from dask.distributed import default_client
    client = client or default_client()
    jobs = list(jobs)
    futures = client.map(run_job, jobs, range(len(jobs)), input_dir=input_dir, output_dir=output_dir, force=force,
                         pure=False, retries=retries)
    rows = client.gather(futures)
    if manifest:
        write_rows(manifest, rows)
    return rows


def local_client(workers: int = 2, threads_per_worker: int = 1, **kwargs):
    """A dask.distributed Client on a LocalCluster of `workers` processes (a laptop's batch)."""
    from dask.distributed import Client, LocalCluster
    return Client(LocalCluster(n_workers=workers, threads_per_worker=threads_per_worker, processes=True, **kwargs))


def read_manifest(path: str) -> List[Dict[str, Any]]:
    """The jobs of a JSON-lines manifest (blank lines and lines starting with # skipped)."""
    jobs = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if line.strip() and not line.lstrip().startswith("#"):
                try:
                    jobs.append(json.loads(line))
                except ValueError as e:
                    raise _core.ParseError(f"{path}:{n}: {e}") from None
    return jobs


def write_rows(path: str, rows: Iterable[Dict[str, Any]]) -> None:
    """Rows as JSON lines, written atomically."""
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        for r in rows:
            f.write(json.dumps(r, sort_keys=True) + "\n")
    os.replace(tmp, path)

