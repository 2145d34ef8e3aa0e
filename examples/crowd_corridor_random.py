#!/usr/bin/env python3
"""Corridor scenes with random starts, for the lane measures of docs/crowd.md ("Lanes").

    crowd_corridor_random.py jitter N SEED   the corridor preset's walls, goal blocks and
        durations, each group's start block as deep as the preset's but its agents placed at
        random across the corridor (|z| <= 3.4 m) and along the block, 0.75 m apart at least
    crowd_corridor_random.py long N SEED [cross]   an 8 m wide corridor, N agents at random over
        |x| <= 40 m (0.75 m apart at least), the two groups mixed, each walking to a goal 50-70 m
        from the centre straight ahead (cross: at a random z), 1,500 steps

Writes the scene (JSON) to stdout. examples/crowd_corridor_jitter.json is `jitter 100 1`,
examples/crowd_corridor_mixed.json is `long 200 1`.
"""
import json, math, random, sys


def apart(p, pts):
    return all((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 >= 0.75 ** 2 for q in pts)


def jitter(n, rnd):
    W, sp, gsp, per_row = 8.0, 1.0, 1.5, 5  # as src/crowd/scene.c's corridor preset
    rows = ((n + 1) // 2 + per_row - 1) // per_row
    L, depth = 30.0, sp * rows
    near = 0.5 * L + depth + 2.0
    far = near + gsp * (rows - 1)
    travel = 0.5 * L + far
    pts, agents = [], []
    for i in range(n):
        g, k = i % 2, i // 2
        side = -1.0 if g == 0 else 1.0
        row, col = k // per_row, (k % per_row) - 0.5 * (per_row - 1)
        while True:
            p = (side * (0.5 * L + rnd.uniform(0.0, depth)), rnd.uniform(-3.4, 3.4))
            if apart(p, pts):
                break
        pts.append(p)
        agents.append({"position": [round(p[0], 4), round(p[1], 4)], "goal": [-side * (far - gsp * row), col * gsp],
                       "group": g})
    steps = math.ceil((2.5 * travel / 1.3 + 120.0 + 0.02 * n) / 0.1)
    walls = [[[-far - 10.0, -0.5 * W], [far + 10.0, -0.5 * W]], [[-far - 10.0, 0.5 * W], [far + 10.0, 0.5 * W]]]
    return steps, walls, agents


def long(n, rnd, cross):
    pts, agents = [], []
    for i in range(n):
        g = i % 2
        side = -1.0 if g == 0 else 1.0
        while True:
            p = (rnd.uniform(-40.0, 40.0), rnd.uniform(-3.4, 3.4))
            if apart(p, pts):
                break
        pts.append(p)
        gx = -side * rnd.uniform(50.0, 70.0)
        gz = rnd.uniform(-3.4, 3.4) if cross else p[1]
        agents.append({"position": [round(p[0], 4), round(p[1], 4)], "goal": [round(gx, 4), round(gz, 4)], "group": g})
    return 1500, [[[-90, -4.0], [90, -4.0]], [[-90, 4.0], [90, 4.0]]], agents


def main():
    kind, n, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    rnd = random.Random(seed)
    if kind == "jitter":
        steps, walls, agents = jitter(n, rnd)
    else:
        steps, walls, agents = long(n, rnd, len(sys.argv) > 4 and sys.argv[4] == "cross")
    scene = {"dt": 0.1, "steps": steps, "contact_iterations": 8,
             "obstacles": [{"vertices": w} for w in walls], "agents": agents}
    print(json.dumps(scene, separators=(", ", ": ")))


if __name__ == "__main__":
    main()
