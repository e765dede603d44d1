"""nprt from Python: scenes, environment maps, datasets, training, relit frames and
evaluation, with numpy arrays in and out (docs/python.md).

Every function is nprt's command of the same name with the same defaults; errors are
:class:`NprtError` (and its :class:`InputError` and :class:`Interrupted`) with the command
line's message. Scenes, maps and files are given as a ``str``, a ``pathlib.Path`` or the
loaded object alike. Images are (H, W, 3) float32 arrays of linear radiance; cameras are 4 x 4
camera-to-world matrices (Mitsuba's convention) with a horizontal field of view in degrees.
``pip install ./python`` also installs the ``nprt`` command (the same command line; also
``python -m nprt``).

    >>> import nprt
    >>> model = nprt.Model("model")
    >>> scene, sky = nprt.load_scene("builtin:room"), nprt.open_envmap("builtin:sky")
    >>> camera, fov, (w, h) = scene.camera()
    >>> frame = model.render(scene, sky, camera, w, h, fov)
    >>> nprt.write_image("frame.png", frame)
"""

from ._loss_curve import loss_curve
from ._nprt import (
    DESIGNS,
    Dataset,
    EnvMap,
    Model,
    Scene,
    __version__,
    bake,
    evaluate,
    export,
    generate,
    load_scene,
    look_at,
    model_info,
    open_envmap,
    paper,
    read_image,
    reference,
    render,
    train,
    train_deep_shading,
    write_image,
)
from .errors import InputError, Interrupted, NprtError

__all__ = [
    "DESIGNS",
    "Dataset",
    "EnvMap",
    "InputError",
    "Interrupted",
    "Model",
    "NprtError",
    "Scene",
    "__version__",
    "bake",
    "evaluate",
    "export",
    "generate",
    "load_scene",
    "look_at",
    "loss_curve",
    "model_info",
    "open_envmap",
    "paper",
    "read_image",
    "reference",
    "render",
    "train",
    "train_deep_shading",
    "write_image",
]
