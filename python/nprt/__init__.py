"""nprt from Python: scenes, environment maps, datasets, training, relit frames and
evaluation, with numpy arrays in and out (docs/python.md).

Every function is nprt's command of the same name with the same defaults; errors are
:class:`NprtError` with the command line's message. Images are (H, W, 3) float32 arrays of
linear radiance; cameras are 4 x 4 camera-to-world matrices (Mitsuba's convention) with a
horizontal field of view in degrees.

    >>> import nprt
    >>> model = nprt.Model("models/dsep")
    >>> scene, sky = nprt.load_scene("builtin:room"), nprt.open_envmap("builtin:sky")
    >>> camera, fov, _ = scene.camera()
    >>> frame = model.render(scene, sky, camera, 256, 192, fov)
"""

import csv
import os

from ._nprt import (
    DESIGNS,
    Dataset,
    EnvMap,
    Model,
    NprtError,
    Scene,
    __version__,
    evaluate,
    export,
    generate,
    load_scene,
    look_at,
    model_info,
    open_envmap,
    paper,
    reference,
    render,
    train,
    train_deep_shading,
)

__all__ = [
    "DESIGNS",
    "Dataset",
    "EnvMap",
    "Model",
    "NprtError",
    "Scene",
    "__version__",
    "evaluate",
    "export",
    "generate",
    "load_scene",
    "look_at",
    "loss_curve",
    "model_info",
    "open_envmap",
    "paper",
    "reference",
    "render",
    "train",
    "train_deep_shading",
]


def loss_curve(model_dir):
    """The loss curves of a training run (its model folder's loss.csv) as a dict of lists:
    ``step``, ``epoch``, ``samples``, ``seconds``, ``train_loss`` and ``val_loss`` (None where
    a step was not validated)."""
    path = os.path.join(os.fspath(model_dir), "loss.csv")
    columns = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            for key, value in row.items():
                columns.setdefault(key, []).append(float(value) if value else None)
    return columns
