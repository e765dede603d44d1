"""Type stubs of nprt's compiled module (crates/nprt-py)."""

import os
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

PathLike = Union[str, "os.PathLike[str]"]
SceneLike = Union["Scene", str, "os.PathLike[str]"]  # a loaded scene, a file or builtin:room
MapLike = Union["EnvMap", str, "os.PathLike[str]"]  # a loaded map, a file or a builtin: map
Matrix = npt.ArrayLike  # 4 x 4 camera-to-world, rows first
Image = npt.NDArray[np.float32]  # (H, W, 3) linear radiance

__version__: str
# The transport designs `train` and `model_info` take (`nprt train --arch`).
DESIGNS: List[str]

class Scene:
    """A scene: geometry, materials and, where its file has one, a camera."""
    @property
    def spec(self) -> str: ...
    @property
    def bounds(self) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]: ...
    @property
    def triangles(self) -> int: ...
    @property
    def warnings(self) -> List[str]: ...
    def camera(self) -> Tuple[npt.NDArray[np.float64], float, Tuple[int, int]]:
        """The scene's own camera, or one framing its bounds: (4 x 4 camera-to-world, horizontal
        field of view in degrees, (width, height))."""
    @property
    def envmap(self) -> Optional["EnvMap"]:
        """The environment map the scene's file names, if any."""

class EnvMap:
    """A lat-long environment map (Mitsuba 3's mapping), 2:1, linear RGB radiance."""
    def __init__(self, texels: npt.ArrayLike, name: str = "array") -> None:
        """A map from an (H, 2H, 3) array (negative values are clamped to 0)."""
    def to_array(self) -> Image: ...
    def rotated(self, degrees: float) -> "EnvMap":
        """The same map turned by ``degrees`` about +Y."""
    @property
    def name(self) -> str: ...
    @property
    def shape(self) -> Tuple[int, int]:
        """(height, width) in texels."""

class Dataset:
    """A dataset folder `nprt generate` wrote, its manifest checked."""
    def __init__(self, path: PathLike) -> None: ...
    def __len__(self) -> int: ...
    @property
    def manifest(self) -> Dict[str, Any]: ...
    def split(self, split: str) -> List[int]:
        """The indices of the views of ``split`` ("train" or "test")."""
    def view(self, index: int) -> Dict[str, Any]:
        """View ``index`` (negative from the end): radiance, direct, position, normal, view, kd,
        ks (H, W, 3); alpha, mask (H, W); half for a test view rendered in halves; transfer and
        transfer_direct (H, W, K, 3) for a training view of a dataset with transfer vectors;
        index, split and lighting (map, rotation_deg, gain, mix)."""
    @overload
    def __getitem__(self, key: int) -> Dict[str, Any]: ...
    @overload
    def __getitem__(self, key: slice) -> List[Dict[str, Any]]: ...
    def __iter__(self) -> Iterator[Dict[str, Any]]: ...
    def camera(self, index: int) -> Tuple[npt.NDArray[np.float64], float, Tuple[int, int]]:
        """(4 x 4 camera-to-world, horizontal field of view in degrees, (width, height))."""
    def verify(self) -> Dict[str, Any]:
        """`nprt dataset verify`: views, complete, missing, corrupt, leftovers, packs."""
    def pack(self, direct: str = "learned", progress: bool = True) -> Dict[str, Any]:
        """`nprt dataset pack`: path, records, bytes."""

class Model:
    """A trained model folder, loaded on ``device`` ("cpu", "gpu", "wgpu" or "auto")."""
    def __init__(self, path: PathLike, device: str = "cpu") -> None: ...
    @property
    def info(self) -> Dict[str, Any]:
        """Its settings and training record (model.json)."""
    @property
    def description(self) -> str:
        """What runs: design, basis, direct light, calibration."""
    @property
    def device(self) -> str: ...
    def render(
        self,
        scene: SceneLike,
        envmap: MapLike,
        camera: Matrix,
        width: int,
        height: int,
        fov: float = 60.0,
        rotation: float = 0.0,
        direct_spp: int = 16,
        seed: int = 0,
        denoise_direct: Union[None, bool, str] = None,
    ) -> Image:
        """A relit frame of ``scene`` under ``envmap`` turned by ``rotation`` degrees (a traced
        model's direct light denoised as ``denoise_direct`` says; None: where OIDN is
        installed)."""

def load_scene(spec: PathLike) -> Scene:
    """builtin:room, or a Mitsuba .xml, glTF, .ply or .obj file."""

def open_envmap(spec: PathLike) -> EnvMap:
    """An .exr/.hdr file, builtin:sky[:ELEV[:AZIM[:TURB]]] or builtin:indoor[:SEED]."""

def look_at(
    origin: Sequence[float], target: Sequence[float], up: Sequence[float] = (0.0, 1.0, 0.0)
) -> npt.NDArray[np.float64]:
    """Mitsuba's lookat as a 4 x 4 camera-to-world matrix."""

def reference(
    scene: SceneLike,
    envmap: MapLike,
    camera: Matrix,
    width: int,
    height: int,
    fov: float = 60.0,
    spp: int = 64,
    seed: int = 0,
    max_depth: Optional[int] = None,
) -> Image:
    """A path-traced frame, as `nprt reference` renders it."""

def generate(
    scene: SceneLike,
    envmaps: PathLike,
    out: PathLike,
    *,
    train_views: Optional[int] = None,
    test_views: Optional[int] = None,
    train_res: Optional[Tuple[int, int]] = None,
    test_res: Optional[Tuple[int, int]] = None,
    spp: Optional[int] = None,
    test_spp: Optional[int] = None,
    seed: Optional[int] = None,
    jitter_exposure: Optional[float] = None,
    jitter_tint: Optional[float] = None,
    test_maps: Optional[int] = None,
    mix_builtin: Optional[float] = None,
    shard: Optional[Tuple[int, int]] = None,
    camera_volume: Optional[PathLike] = None,
    volume_min: Optional[Sequence[float]] = None,
    volume_max: Optional[Sequence[float]] = None,
    look: Optional[Sequence[float]] = None,
    spread: Optional[float] = None,
    fov: Optional[float] = None,
    device: str = "cpu",
    progress: bool = True,
    mix_maps: Optional[int] = None,
    transfer: Optional[str] = None,
) -> Dict[str, Any]:
    """`nprt generate`; None takes its default (``transfer``: ``"sh:L"`` records each
    training pixel's transfer vector on SH bands 0..L, ``"none"`` none; by default the
    recommended recipe's, ``"sh:2"``, on the CPU tracer)."""

def train(
    data: PathLike,
    arch: Optional[str] = None,
    out: Optional[PathLike] = None,
    *,
    minutes: Optional[float] = None,
    epochs: Optional[int] = None,
    activation: Optional[str] = None,
    device: str = "cpu",
    precision: Optional[str] = None,
    batch_size: Optional[int] = None,
    lr: Optional[float] = None,
    schedule: Optional[str] = None,
    seed: Optional[int] = None,
    progress: bool = True,
    callback: Optional[Callable[[Dict[str, Any]], Optional[bool]]] = None,
    basis: Optional[str] = None,
    snapshots: Optional[str] = None,
    targets: Optional[str] = None,
    direct: Optional[str] = None,
    calibrate: Optional[str] = None,
) -> Dict[str, Any]:
    """`nprt train` into ``out`` (required); ``arch`` None trains the recommended recipe (the
    linear design on ``"sh:2"``, its direct light traced, on the dataset's transfer vectors
    where it has them, its level calibrated), a design's name that design with its own
    defaults. None takes the default (``basis``: the linear design's ``"sh:L"`` or
    ``"learned:K"``; ``snapshots``: points such as ``"1m,2m,4m"`` at which the model is kept
    in ``out``/snapshots/POINT; ``targets``: ``"radiance"`` or ``"transfer"``, the vectors
    ``generate(transfer=...)`` recorded; ``direct``: ``"learned"`` or ``"traced"``;
    ``calibrate``: ``"none"`` or ``"level"``). ``callback`` gets each epoch's row of the loss
    curves; returning a false value other than None (False, 0, numpy's False_), or Ctrl-C,
    ends the run there, saved, and the same call resumes it."""

def evaluate(
    data: PathLike,
    models: Union[PathLike, Sequence[PathLike]],
    out: PathLike,
    *,
    deep_shading: Optional[PathLike] = None,
    sh_spp: Optional[int] = None,
    timing_res: Optional[int] = None,
    views: Optional[int] = None,
    shown_views: Optional[int] = None,
    seed: Optional[int] = None,
    direct_spp: Optional[int] = None,
    temporal_frames: Optional[int] = None,
    temporal_res: Optional[int] = None,
    nrc_warmup: Optional[int] = None,
    oracles: bool = False,
    device: str = "cpu",
    progress: bool = True,
) -> Dict[str, Any]:
    """`nprt eval`; returns results.json."""

def paper(
    scene: SceneLike,
    envmaps: PathLike,
    out: PathLike,
    *,
    budget: str = "small",
    camera_volume: Optional[PathLike] = None,
    test_maps: Optional[int] = None,
    seed: int = 0,
    device: str = "cpu",
    snapshots: Optional[str] = None,
    training_minutes: Optional[float] = None,
) -> Dict[str, Any]:
    """`nprt paper`: the paper's Tables 1-6 at ``budget`` ("tiny", "small", "medium", "paper"),
    resumable; returns ``paper_md``, ``paper_html``, ``report_html``, ``results`` (results.json)
    and ``orderings`` (table, statement, verdict). ``snapshots`` (``"1m,2m,4m"``) judges the
    orderings as training grows; ``training_minutes`` trains every network that long instead
    of the budget's."""

def bake(
    scene: SceneLike,
    envmaps: PathLike,
    out: PathLike,
    *,
    quality: str = "draft",
    minutes: Optional[float] = None,
    epochs: Optional[int] = None,
    camera_volume: Optional[PathLike] = None,
    test_maps: Optional[int] = None,
    seed: int = 0,
    device: str = "cpu",
    progress: bool = True,
) -> Dict[str, Any]:
    """`nprt bake`: ``scene`` under ``envmaps`` (a folder of maps, or "builtin") to a relit
    model in ``out`` at ``quality`` ("draft", "good", "best"; "tiny" for tests), resumable:
    the dataset, the recommended recipe trained, a check against path tracing of equal cost
    on held-out views. Returns ``model``, ``comparison``, ``preview``, ``report`` (paths),
    ``description``, ``views``, ``held_out_maps``, ``model_errors`` and
    ``path_tracing_errors`` (``name``, ``l1``, ``rmse``, ``dssim``, ``ms_per_view``,
    ``level``) and ``seconds``."""

def train_deep_shading(
    data: PathLike,
    out: PathLike,
    *,
    minutes: Optional[float] = None,
    epochs: Optional[int] = None,
    schedule: Optional[str] = None,
    lr: Optional[float] = None,
    seed: Optional[int] = None,
    batch_views: Optional[int] = None,
    device: str = "cpu",
    progress: bool = True,
    callback: Optional[Callable[[Dict[str, Any]], Optional[bool]]] = None,
) -> Dict[str, Any]:
    """`nprt train-deep-shading` (the U-Net baseline) on `device` ("cpu", "gpu", "wgpu", "auto")."""

def model_info(
    model: Optional[PathLike] = None,
    *,
    arch: Optional[str] = None,
    activation: Optional[str] = None,
    encoder_width: Optional[int] = None,
    encoding: Optional[str] = None,
) -> Dict[str, Any]:
    """`nprt model info`: the layer table and parameter counts of a trained model folder, or of
    a design (`arch`: one of `DESIGNS`) untrained. Keys: config, layers (name, shape,
    params), encoder_params, transport_params (without hash-grid entries, as the paper's Table
    1), paper_params, grid_entries, total_params; for a model also dataset_hash, scene_hash,
    level_gain."""

def export(
    model: PathLike,
    out: PathLike,
    *,
    example_res: Optional[Tuple[int, int]] = None,
    example_map: Optional[str] = None,
) -> Dict[str, Any]:
    """`nprt export`: files, weights, no_example."""

def render(
    model: PathLike,
    out: PathLike,
    *,
    scene: Optional[SceneLike] = None,
    camera_path: Optional[PathLike] = None,
    camera_volume: Optional[PathLike] = None,
    lighting: Optional[str] = None,
    spin: Optional[float] = None,
    frames: Optional[int] = None,
    res: Optional[Tuple[int, int]] = None,
    fps: Optional[int] = None,
    exposure: Optional[float] = None,
    exr: bool = False,
    direct_spp: Optional[int] = None,
    denoise_direct: Union[None, bool, str] = None,
    precision: Optional[str] = None,
    device: str = "cpu",
) -> Dict[str, Any]:
    """`nprt render`: a camera path relit into frames and an animation (``denoise_direct``:
    True, False, "auto", "on" or "off"; None: auto, OIDN where installed)."""

def write_image(path: PathLike, image: npt.ArrayLike, exposure: float = 0.0) -> None:
    """Writes an (H, W, 3) image of linear radiance as .exr (exact), .hdr or .png (sRGB of the
    radiance scaled by 2**exposure), whole or not at all."""

def read_image(path: PathLike) -> Image:
    """An image file (.exr, .hdr, .png, .jpg) as (H, W, 3) float32 linear RGB."""

def cli(argv: Sequence[str]) -> int:
    """Runs nprt's command line on ``argv`` (the program's name first); its exit status."""
