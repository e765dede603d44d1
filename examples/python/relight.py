# %% [markdown]
# # Relighting builtin:room from Python
#
# Runnable as a script (`python examples/python/relight.py [OUT]`) and readable as a notebook
# (its cells are marked `# %%`, as Jupytext and VS Code read them). It makes a small dataset,
# trains the paper's diffuse/specular design for a minute, relights the room under a sweep of
# sun positions and, with matplotlib, plots each frame beside a path-traced reference of the
# same cost class. Install the package first: `pip install ./python` (docs/python.md).

# %%
import pathlib
import sys

import numpy as np

import nprt

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "relight-example")
out.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# A dataset of builtin:room under procedural lightings (re-running resumes it).

# %%
nprt.generate("builtin:room", "builtin", out / "data", train_views=120, test_views=8,
              train_res=(64, 64), test_res=(64, 64), spp=32, test_spp=256)
data = nprt.Dataset(out / "data")
print(data)

# %% [markdown]
# D/S trained for one minute on the CPU (a larger `minutes` continues the run).

# %%
run = nprt.train(out / "data", "dsep", out / "model", minutes=1.0)
print(f"{run['steps']} steps, validation loss {run['validation_loss']:.4f}")

# %% [markdown]
# The room relit under a sun moving across the sky, from the scene's own camera, beside path
# tracing at 64 paths per pixel.

# %%
model = nprt.Model(out / "model")
scene = nprt.load_scene("builtin:room")
camera, fov, _ = scene.camera()
width, height = 160, 120
frames, references = [], []
for azimuth in range(0, 360, 60):
    sky = nprt.open_envmap(f"builtin:sky:30:{azimuth}")
    frames.append(model.render(scene, sky, camera, width, height, fov))
    references.append(nprt.reference(scene, sky, camera, width, height, fov=fov, spp=64))
for azimuth, f, r in zip(range(0, 360, 60), frames, references):
    print(f"sun at {azimuth:3d} degrees: mean {f.mean():.4f} (path tracing {r.mean():.4f})")

# %% [markdown]
# With matplotlib, the frames beside the references (tone-mapped by a simple exposure).

# %%
try:
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
if plt is not None:
    shown = lambda img: np.clip(img / (img.mean() * 4 + 1e-6), 0, 1) ** (1 / 2.2)
    fig, axes = plt.subplots(2, len(frames), figsize=(2.2 * len(frames), 4))
    for k, (f, r) in enumerate(zip(frames, references)):
        axes[0, k].imshow(shown(f))
        axes[1, k].imshow(shown(r))
        axes[0, k].set_title(f"sun {60 * k}°")
        for a in axes[:, k]:
            a.axis("off")
    axes[0, 0].set_ylabel("nprt")
    fig.savefig(out / "relight.png", dpi=120, bbox_inches="tight")
    print(f"plot in {out / 'relight.png'}")
