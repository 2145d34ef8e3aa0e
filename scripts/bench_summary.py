#!/usr/bin/python3
"""Writes DIR/SUMMARY.md from the outputs scripts/bench.sh saved in DIR (NAME.txt, run.log,
machine.txt): one row per program with its key rate, key ratio and CPU path, taken from the
lines each program prints. Python 3 standard library only.

Usage: scripts/bench_summary.py BUILD/bench-results

A line a program no longer prints leaves its cell as "-" (the full output is beside the summary);
a program unknown here gets "see NAME.txt". To add a benchmark, add an entry to EXTRACT: a list
of (column, label, regex or function) whose regex's groups fill the label's {} fields.
"""
import os
import re
import sys

NUM = r"([0-9][0-9.e+]*)"


def noise_peers(text):
    """vs_noise: animkit's fastest batch job against FastNoise2's fastest path, per family
    (ns per point), and the per-point call against FastNoiseLite's."""
    rows = {}
    for m in re.finditer(r"^(\S.*?)\s+" + NUM + r"\s+\[[^\]]*\]\s+" + NUM, text, re.M):
        rows[m.group(1).strip()] = float(m.group(3))  # name -> ns per point
    out = {"rate": [], "ratio": [], "path": []}

    def best(prefix):
        v = [(ns, n) for n, ns in rows.items() if n.startswith(prefix)]
        return min(v) if v else None

    for fam in ("perlin", "fbm5 perlin", "simplex"):
        ak = best(fam + "  ak job") or best(fam + " ak job")
        fn2 = best(fam + "  FastNoise2") or best(fam + " FN2")
        if ak and fn2:
            out["rate"].append("%s: animkit %.2f ns/pt (%s)" % (fam, ak[0], ak[1].split("ak job")[-1].strip()))
            out["ratio"].append("%s animkit/FN2 time x%.2f" % (fam, ak[0] / fn2[0]))
    loop = rows.get("perlin  ak_noise_perlin3 loop")
    fnl = rows.get("perlin  FastNoiseLite")
    if loop and fnl:
        out["ratio"].append("per-point call / FastNoiseLite x%.2f" % (loop / fnl))
    m = re.search(r"FastNoise2 active feature sets: (.*)", text)
    if m:
        out["path"].append("FN2 " + m.group(1).strip())
    return out


# column: rate, ratio or path. Each entry: (column, format with {} per group, regex).
EXTRACT = {
    "bench_math": [
        ("rate", "vec3 rotations {} M/s (array func)", r"^vec3 rotations\s+\S+ M/s\s+\S+ M/s\s+" + NUM + " M/s"),
        ("ratio", "rotations array/scalar {}", r"^vec3 rotations.*M/s\s+(\S+x)\s+\S+x"),
        ("ratio", "4x4 array/scalar {}", r"^4x4 products.*M/s\s+(\S+x)\s+\S+x"),
        ("path", "{}", r"array path = (\w+)"),
    ],
    "bench_clip": [
        ("rate", "linear sequential {} joints/s (key cache)", r"^linear\s+sequential\s+" + NUM),
        ("ratio", "cache/bsearch {} (linear seq.)", r"^linear\s+sequential(?:\s+\S+){3}\s+" + NUM),
    ],
    "bench_skeleton": [
        ("rate", "FK matrix chain {} Mjoints/s", r"local_to_model \(matrix chain\)\s+" + NUM),
        ("ratio", "matrix/TRS time {}", r"matrix/TRS time ratio " + NUM),
    ],
    "bench_skin": [
        ("rate", "LBS P+N {} Mvert/s, {} of triad (1 thread)",
         r"LBS positions\+normals \((?:avx512|avx2|scalar)\)\s+" + NUM + r" Mvert/s.*?(\d+%) of triad"),
        ("ratio", "LBS P+N best/scalar {}", r"LBS positions\+normals\s+.*vs scalar (x[0-9.]+)\s*$"),
        ("ratio", "DQS/LBS {}, CoR/DQS {}", r"ratios \(\w+, positions\+normals\): DQS/LBS " + NUM + ", CoR/DQS " + NUM),
        ("ratio", "2 thr/1 thr LBS P+N {}", r"2 threads vs 1 .*LBS positions\+normals (x[0-9.]+)"),
        ("path", "{}", r"kernel (\w+)"),
    ],
    "bench_ik": [
        ("rate", "two-bone {} ns/solve", r"^two-bone job .*?: " + NUM + " ns/solve"),
        ("rate", "batch {} ns/solve", r"two_bone_run_many .*?: " + NUM + " ns/solve"),
        ("rate", "FABRIK 3D 10 {} us", r"^3d\s+10 fabrik(?:\s+\S+){3}\s+" + NUM),
        ("ratio", "batch vs single {}", r"two_bone_run_many .*: (x[0-9.]+)\s*$"),
    ],
    "bench_raster": [
        ("rate", "Phong 1 thread {} ms CPU", r"phong\s+1 thread :\s+\S+\s+" + NUM),
        ("ratio", "Phong 1t/2t wall {}", r"ratios \(wall\): phong 1t/2t " + NUM),
        ("ratio", "SSAA/Phong {}", r"SSAA2x2/phong " + NUM),
    ],
    "bench_blendshape": [
        ("rate", "sparse {} Mvert*tgt/s", r"^set, sparse storage\s+\S+\s+" + NUM),
        ("ratio", "dense vs naive {}", r"^set, dense storage\s+\S+\s+\S+\s+(\S+x)"),
        ("ratio", "sparse vs naive {}", r"^set, sparse storage\s+\S+\s+\S+\s+(\S+x)"),
        ("path", "{} build", r"moved per target \(([^)]*?) build\)"),
    ],
    "bench_noise": [
        ("rate", "Perlin 3D batch {} M samples/s (widest)", r"Perlin\s+batch job, value\s+scalar.*?(?:AVX-512|AVX2)\s+" + NUM + r" M samples/s"),
        ("ratio", "Perlin AVX2/scalar {}", r"Perlin\s+batch job, value\s+.*AVX2/scalar (\S+x)"),
        ("ratio", "simplex AVX2/scalar {}", r"simplex batch job, value\s+.*AVX2/scalar (\S+x)"),
        ("ratio", "fBm grid SIMD/scalar {}", r"1 thread : scalar.*ratio (\S+x)"),
        ("path", "{}", r"widest SIMD kernel (\w[\w-]*)"),
    ],
    "bench_particles": [
        ("rate", "step {} M particles/s", r"1 thread :\s+" + NUM + " M particles/s"),
        ("rate", "grid pairs {} M pairs/s", r"all pairs, 1 thread :.*?" + NUM + " M pairs/s"),
        ("ratio", "step {} of triad", r"1 thread :.*= +(\d+%) of the 1-thread triad"),
        ("ratio", "grid vs brute force {}", r"grid (\d+x) faster"),
    ],
    "bench_boids": [
        ("rate", "100k, 2 threads {} ms wall", r"step, 2 threads\s+" + NUM + " ms wall"),
        ("rate", "1 thread {} ms CPU", r"step, 1 thread\s+\S+ ms wall, " + NUM + " ms CPU"),
        ("ratio", "2 thr/1 thr {}", r"step, 2 threads\s+\S+ ms wall \((x[0-9.]+)\)"),
        ("ratio", "naive/grid {}", r"naive/grid (x\d+)"),
        ("path", "{}", r"kernels (\w+)"),
    ],
    "bench_cloth": [
        ("rate", "64x64 XPBD 1 thr {} ms median", r"^ 64x64\s+XPBD\s+10\s+1\s+" + NUM),
        ("rate", "256x256 {} ms", r"^256x256\s+XPBD\s+10\s+1\s+" + NUM),
        ("ratio", "scalar/{} {}", r"^\s+XPBD\s+scalar.*scalar/(\w+) ([0-9.]+x)\s*$"),
        ("ratio", "springs/XPBD CPU {}", r"substeps per frame .*?: ([0-9.]+x) the CPU"),
        ("path", "{}", r"widest constraint solve: (\w+)"),
    ],
    "bench_fluid": [
        ("rate", "PBF {} 2 thr {} ms wall", r"^PBF \(4 it\)\s+(\w+)\s+2\s+\d+\s+" + NUM),
        ("rate", "1 thr {} ms CPU", r"^PBF \(4 it\)\s+\w+\s+1\s+\d+\s+\S+\s+" + NUM),
        ("ratio", "PBF 2 vs 1 thread wall {}", r"^PBF \(4 it\)\s+\w+\s+2 vs 1 thread: wall (\S+x)"),
        ("ratio", "PBF SIMD/scalar CPU {} (1 thread)", r"^PBF \(4 it\)\s+\w+\s+2 vs 1 thread.*SIMD/scalar cpu time: (\S+) \(1 thread\)"),
        ("ratio", "SPH {}", r"^SPH\s+\w+\s+2 vs 1 thread.*SIMD/scalar cpu time: (\S+) \(1 thread\)"),
        ("ratio", "WCSPH {}", r"^WCSPH\s+\w+\s+2 vs 1 thread.*SIMD/scalar cpu time: (\S+) \(1 thread\)"),
        ("path", "{}", r"default kernels here: (\w+)"),
    ],
    "bench_crowd_frame": [
        ("rate", "1,000 characters, 1 thr {} fps", r"^\s+1\s+\S+\s+" + NUM),
        ("ratio", "2 thr {} ({})", r"^\s+2\s+\S+\s+\S+\s+\S+\s+(\S+x)\s+(\d+%)"),
        ("ratio", "16 thr {} ({})", r"^\s+16\s+\S+\s+\S+\s+\S+\s+(\S+x)\s+(\d+%)"),
    ],
    "bench_retarget": [
        ("rate", "{} frames/s", r"without foot clean-up:\s+" + NUM + " frames/s"),
        ("rate", ".glb {} MB/s", r"\.glb:\s+" + NUM + " MB/s"),
        ("ratio", "clean-up/plain {}", r"ratio clean-up / plain time: " + NUM),
    ],
    "vs_ozz": [
        ("rate", "LBS P+N K=4 {} Mvert/s", r"^LBS P\+N K=4\s+\S+\s+" + NUM),
        ("ratio", "LBS P+N rate vs ozz K=1 {}", r"^LBS P\+N K=1 .*?\s([0-9.]+ \[[^\]]*\])(?:\s+[0-9.]+%)?\s*$"),
        ("ratio", "K=2 {}", r"^LBS P\+N K=2 .*?\s([0-9.]+ \[[^\]]*\])(?:\s+[0-9.]+%)?\s*$"),
        ("ratio", "K=4 {}", r"^LBS P\+N K=4 .*?\s([0-9.]+ \[[^\]]*\])(?:\s+[0-9.]+%)?\s*$"),
        ("ratio", "K=8 {}", r"^LBS P\+N K=8 .*?\s([0-9.]+ \[[^\]]*\])(?:\s+[0-9.]+%)?\s*$"),
        ("ratio", "seq. sample+FK time vs ozz x{}",
         r"sequential sample\+FK\s+animkit LINEAR\(slerp\) cursor.*?time vs ozz x([0-9.]+ \[[^\]]*\])"),
        ("ratio", "FK x{}", r"sequential FK only\s+animkit LINEAR\(slerp\) cursor.*?time vs ozz x([0-9.]+ \[[^\]]*\])"),
        ("ratio", "two-bone x{}", r"two_bone_run, mid_axis z.*?x([0-9.]+ \[[^\]]*\])"),
        ("path", "{}", r"kernel animkit=(\w+)"),
    ],
    "vs_noise": noise_peers,
    "bench_batch": [
        ("rate", "bake run {} ms", r"^bake .*? run\s+" + NUM + " ms"),
        ("rate", "FNV-1a {} MB/s", r"FNV-1a 64 hashing\s+" + NUM + " MB/s"),
        ("ratio", "bake skip/run {}", r"^bake .*skip/run " + NUM),
        ("ratio", "retarget skip/run {}", r"^retarget .*skip/run " + NUM),
    ],
    "bench_implicit": [
        ("rate", "CesiumMan implicit {} ms CPU", r"(?s)^CesiumMan: \d+ vertices.*?1 thread, CPU time: DQS \S+ ms, implicit " + NUM + " ms"),
        ("rate", "cylinder 50k implicit {} ms CPU", r"(?s)^builtin:cylinder.*?1 thread, CPU time: DQS \S+ ms, implicit " + NUM + " ms"),
        ("ratio", "CesiumMan implicit/DQS {}", r"(?s)^CesiumMan: \d+ vertices.*?1 thread, CPU time: .*? \((\S+x)\)"),
        ("ratio", "cylinder implicit/DQS {}", r"(?s)^builtin:cylinder.*?1 thread, CPU time: .*? \((\S+x)\)"),
    ],
    "bench_softskin": [
        ("rate", "CesiumMan soft 1t {} ms", r"^CesiumMan(?:[ \t]+\S+){5}[ \t]+" + NUM),
        ("rate", "cylinder soft 1t {} ms", r"^cylinder 48x32(?:[ \t]+\S+){5}[ \t]+" + NUM),
        ("ratio", "CesiumMan soft/DQS {}", r"^CesiumMan(?:[ \t]+\S+){8}[ \t]+" + NUM),
        ("ratio", "cylinder soft/DQS {}", r"^cylinder 48x32(?:[ \t]+\S+){8}[ \t]+" + NUM),
    ],
    "bench_sprites": [
        ("rate", "10k sprites (alpha) {} ms", r"^\s+10000\s+\S+\s+" + NUM),
        ("ratio", "sprites/points at 1k {}", r"^\s+1000\s+(?:\S+\s+){4}" + NUM),
        ("ratio", "at 50k {}", r"^\s+50000\s+(?:\S+\s+){4}" + NUM),
    ],
    "bench_tasks": [
        ("rate", "2 empty tasks {} us a section", r"^2\s+empty\s+" + NUM),
        ("ratio", "fresh threads/team, 2 empty {}", r"^2\s+empty\s+\S+\s+\S+\s+(\S+x)"),
        ("ratio", "2 x 100 us {}", r"^2\s+100 us\s+\S+\s+\S+\s+(\S+x)"),
    ],
    "bench_scaling": [
        ("rate", "boids100k 2 thr {} ms", r"^boids100k\s+\d+\s+2\s+" + NUM),
        ("ratio", "2 thr efficiency: boids100k {}", r"^boids100k\s+\d+\s+2\s+\S+\s+\S+\s+(\d+%)"),
        ("ratio", "pbf55k {}", r"^pbf55k\s+\d+\s+2\s+\S+\s+\S+\s+(\d+%)"),
        ("ratio", "cloth256 {}", r"^cloth256\s+\d+\s+2\s+\S+\s+\S+\s+(\d+%)"),
        ("ratio", "lbs1m {}", r"^lbs1m\s+\d+\s+2\s+\S+\s+\S+\s+(\d+%)"),
    ],
    "bench_rigid_vs_bullet": [
        ("rate", "pyramid {} ms/step", r"^pyramid \(\d+ bodies\)\s+" + NUM),
        ("rate", "spheres {} ms", r"^spheres \(\d+ bodies\)\s+" + NUM),
        ("rate", "ragdolls {} ms", r"^ragdolls \(\d+ bodies\)\s+" + NUM),
        ("ratio", "Bullet/animkit time: pyramid {}", r"^pyramid \(\d+ bodies\)\s+\S+\s+\S+\s+" + NUM),
        ("ratio", "spheres {}", r"^spheres \(\d+ bodies\)\s+\S+\s+\S+\s+" + NUM),
        ("ratio", "ragdolls {}", r"^ragdolls \(\d+ bodies\)\s+\S+\s+\S+\s+" + NUM),
        ("path", "{}", r"(WARNING: animkit DROPPED)"),
    ],
    "vs_rvo2_agree": [
        ("rate", "{}", r"(circle 250 agents, \d+ steps)"),
        ("ratio", "max |p_animkit - p_rvo2| {} m", r"max \|p_animkit - p_rvo2\| = (\S+) m"),
        ("path", "{}", r"^(PASS|FAIL):"),
    ],
    "vs_rvo2_time": [
        ("rate", "{} agents, 1 thr: animkit {} ms/step", r"^\s*(\d+) agents 1 thread :.*?animkit\s+" + NUM + " ms/step"),
        ("ratio", "animkit/RVO2 speed 1 thr {}", r"agents 1 thread :.*?animkit/RVO2 speed (\S+x)"),
        ("ratio", "CPU {}", r"agents 1 thread :.*?thread CPU time: .*?speed (\S+x)"),
        ("ratio", "2 thr {}", r"agents 2 threads:.*?animkit/RVO2 speed (\S+x)"),
    ],
    "vs_rvo2_work": [
        ("rate", "{} agents, 2 thr: animkit {} CPU ms/step", r"^\s*(\d+) agents 2 threads: CPU time of all threads:.*?animkit\s+" + NUM + " ms/step"),
        ("ratio", "animkit/RVO2 work speed {}", r"animkit/RVO2 work speed (\S+x)"),
    ],
    "bench_python": [
        ("rate", "C loop {} us per sample+skin", r"^C loop\s+" + NUM + " us per"),
        ("ratio", "added by Python: out= {} us", r"^Python, out=\s+\S+ us\s+overhead\s+" + NUM + " us"),
        ("ratio", "keywords {} us", r"^Python, keywords\s+\S+ us\s+overhead\s+" + NUM + " us"),
        ("ratio", "new array {} us", r"^Python, new array\s+\S+ us\s+overhead\s+" + NUM + " us"),
    ],
    "bench_batch_dask": [
        ("rate", "in-process {} jobs/s", r"^in-process\s+" + NUM + " jobs/s"),
        ("rate", "Dask 2 workers {} jobs/s", r"^Dask, 2 workers\s+" + NUM + " jobs/s"),
        ("ratio", "2 vs 1 worker {}", r"scaling 2 vs 1 worker: (\S+)"),
        ("ratio", "Dask overhead {} ms a job", r"Dask overhead per job .*?: " + NUM + " ms"),
    ],
}
EXTRACT["vs_ozz_avx2"] = [e for e in EXTRACT["vs_ozz"] if "LBS" in e[1] or "K=" in e[1] or e[0] == "path"]
for side in ("12", "38", "80", "160"):
    EXTRACT["vs_nsearch_" + side] = [
        ("rate", "{} points, {} pairs", r"^(\d+) points .*\n(?:.*\n)*?pairs: animkit (\d+)"),
        ("rate", "{} points", r"^(\d+) points \("),
        ("rate", "{} pairs, sets {}", r"^pairs (\d+), list entries.*sets (\w+)"),
        ("rate", "1 thr build+pairs CPU {} ms", r"^threads 1\s+animkit build\+pairs\s+CPU\s+" + NUM + " ms"),
        ("ratio", "CNS/animkit CPU, pairs 1 thr {}", r"^threads 1\s+per-round CPU ratio CNS / animkit pairs: median " + NUM),
        ("ratio", "lists 1 thr {}", r"^threads 1\s+per-round CPU ratio .*CNS / animkit lists: median " + NUM),
        ("ratio", "pairs 2 thr {}", r"^threads 2\s+per-round CPU ratio CNS / animkit pairs: median " + NUM),
        ("ratio", "lists 2 thr {}", r"^threads 2\s+per-round CPU ratio .*CNS / animkit lists: median " + NUM),
        # the peers' harness (../shared/peers/nsearch/run.sh)
        ("rate", "1 thr {} ms", r"^threads 1\s+animkit build\+pairs\s+" + NUM + " ms"),
        ("ratio", "CNS/animkit 1 thr x{}", r"^threads 1\s+CNS find_neighbors.*?\(median\) " + NUM),
        ("ratio", "2 thr x{}", r"^threads 2\s+CNS find_neighbors.*?\(median\) " + NUM),
    ]


def extract(name, text):
    spec = EXTRACT.get(name)
    if spec is None:
        return None
    if callable(spec):
        return spec(text)
    out = {"rate": [], "ratio": [], "path": []}
    for col, fmt, rx in spec:
        m = re.search(rx, text, re.M)
        if m:
            out[col].append(fmt.format(*[g.strip() for g in m.groups()]))
    return out


def cell(items):
    return "; ".join(items).replace("|", "/") if items else "-"


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: bench_summary.py BUILD/bench-results\n")
        return 2
    d = sys.argv[1]
    runs = []
    try:
        with open(os.path.join(d, "run.log"), encoding="utf-8", errors="replace") as f:
            for line in f:
                parts = line.rstrip("\n").split("\t")
                if len(parts) >= 4:
                    runs.append(parts)
    except OSError as e:
        sys.stderr.write("bench_summary.py: %s\n" % e)
        return 1
    machine = ""
    try:
        with open(os.path.join(d, "machine.txt"), encoding="utf-8", errors="replace") as f:
            machine = f.read()
    except OSError:
        pass
    lines = ["# animkit benchmark summary", ""]
    lines += ["    " + ln for ln in machine.splitlines()]
    if "mode: quick" in machine:
        lines += ["", "**Quick mode: smallest sizes, fewest rounds. These numbers check the pipeline; "
                  "they are not measurements.**"]
    lines += ["", "Full outputs: NAME.txt beside this file. Ratios were measured side by side in one run; "
              "absolute rates depend on the machine and its load.", "",
              "| benchmark | key rate | key ratio | CPU path | s | status |", "|---|---|---|---|---:|---|"]
    for name, rc, secs, what in runs:
        if rc == "skip":
            lines.append("| %s | - | - | - | - | SKIP: %s |" % (name, what.replace("|", "/")))
            continue
        try:
            with open(os.path.join(d, name + ".txt"), encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError:
            text = ""
        got = extract(name, text)
        status = "ok" if rc == "0" else "FAILED (exit %s)" % rc
        if got is not None and not any(got.values()):
            got = None  # its key lines changed: say so rather than print an empty row
            sys.stderr.write("bench_summary.py: no key line found in %s.txt (did its output change?)\n" % name)
        if got is None:
            lines.append("| %s | see %s.txt | - | - | %s | %s |" % (name, name, secs, status))
        else:
            lines.append("| %s | %s | %s | %s | %s | %s |" % (name, cell(got["rate"]), cell(got["ratio"]),
                                                             cell(got["path"]), secs, status))
    with open(os.path.join(d, "SUMMARY.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
