"""Notebook-style tour of the Python package `animkit`, plotted with matplotlib (Agg: no display).

    make python && PYTHONPATH=python /usr/bin/python3 examples/python/skinning_plot.py [MODEL] [-o OUT.png]

MODEL defaults to builtin:humanoid (any .glb/.gltf/.bvh works). Writes one PNG (default
skinning_plot.png) with four panels: a rendered frame, the skinned mesh seen from the side
under LBS and DQS, the paths of the hands over the clip, and where LBS and DQS differ most.
"""
import argparse

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import animkit as ak  # noqa: E402

# %% Load a model and look at it
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("model", nargs="?", default="builtin:humanoid")
parser.add_argument("-o", "--output", default="skinning_plot.png")
args = parser.parse_args()

scene = ak.load(args.model)
print(scene, "clips:", scene.clip_names)
duration = scene.clip_durations[0] if scene.clip_names else 0.0
t = 0.5 * duration

# %% Pose it and skin it two ways (arrays are numpy, no copies)
pose = scene.sample(clip=0 if scene.clip_names else None, time=t)
have_mesh = len(scene.meshes) > 0
if have_mesh:
    lbs = scene.skin(pose, method="lbs")
    dqs = scene.skin(pose, method="dqs")
    diff = np.linalg.norm(lbs - dqs, axis=1)

# %% Joint paths over the clip: translation column of each model matrix
times = np.linspace(0.0, duration, 48)
paths = np.array([scene.sample(time=float(x)).model_matrices[:, :3, 3] for x in times])  # (F, J, 3)
hands = [i for i, n in enumerate(scene.joint_names) if "wrist" in n.lower() or "hand" in n.lower()][:2] or [
    len(scene.joint_names) - 1]

# %% Plot
fig, ax = plt.subplots(2, 2, figsize=(10, 9))
ax[0, 0].imshow(scene.render(time=t, size=(320, 320)))
ax[0, 0].set_title(f"render at t={t:.2f}s")
ax[0, 0].axis("off")
if have_mesh:
    ax[0, 1].scatter(lbs[:, 2], lbs[:, 1], s=0.3, label="LBS")
    ax[0, 1].scatter(dqs[:, 2], dqs[:, 1], s=0.3, label="DQS")
    ax[0, 1].legend(markerscale=10)
ax[0, 1].set_title("skinned vertices, side view (z, y)")
ax[0, 1].set_aspect("equal")
for j in hands:
    ax[1, 0].plot(paths[:, j, 2], paths[:, j, 1], label=scene.joint_names[j])
ax[1, 0].set_title("joint paths over the clip, side view (z, y)")
ax[1, 0].legend()
if have_mesh:
    sc = ax[1, 1].scatter(lbs[:, 0], lbs[:, 1], c=diff, s=0.5, cmap="magma")
    fig.colorbar(sc, ax=ax[1, 1], label="|LBS - DQS|")
    print(f"LBS vs DQS: largest difference {diff.max():.4g} at vertex {int(diff.argmax())}")
ax[1, 1].set_title("where LBS and DQS differ (front view)")
ax[1, 1].set_aspect("equal")
fig.tight_layout()
fig.savefig(args.output, dpi=80)
print("wrote", args.output)
