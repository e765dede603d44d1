"""What a notebook user trips on (issue 64), each case refused by name or handled, never a
crash of the interpreter, a silently wrong image or a message about flags Python has none of."""

import concurrent.futures
import pathlib
import pickle
import warnings

import numpy as np
import pytest

import nprt


def test_a_huge_map_is_refused_before_it_is_copied():
    # A broadcast view costs nothing; its copy would be 25 GB (the process aborted).
    huge = np.broadcast_to(np.float32(1), (2**15, 2**16, 3))
    with pytest.raises(nprt.NprtError, match="65536×32768 texels needs"):
        nprt.EnvMap(huge)


@pytest.mark.parametrize("bad", [None, "texels", np.zeros((4, 8)), [[1, 2, 3]]])
def test_a_map_that_is_no_array_of_texels_names_the_argument(bad):
    with pytest.raises(nprt.InputError, match="texels"):
        nprt.EnvMap(bad)


def test_a_map_from_nested_lists_is_taken_as_an_array():
    texels = np.arange(4 * 8 * 3, dtype=np.float32).reshape(4, 8, 3) / 96
    np.testing.assert_array_equal(nprt.EnvMap(texels.tolist()).to_array(), texels)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_floats_are_refused_by_name(room, dataset, model, tmp_path, value):
    sky = nprt.open_envmap("builtin:sky")
    camera, fov, _ = room.camera()
    with pytest.raises(nprt.InputError, match="degrees"):
        sky.rotated(value)
    with pytest.raises(nprt.InputError, match="rotation"):
        nprt.Model(model).render(room, sky, camera, 8, 6, fov, rotation=value)
    with pytest.raises(nprt.InputError, match="fov="):
        nprt.reference(room, sky, camera, 8, 6, fov=value)
    with pytest.raises(nprt.InputError, match="origin"):
        nprt.look_at([0, value, 0], [0, 0, -1])
    for arg in ["lr", "minutes"]:
        with pytest.raises(nprt.InputError, match=arg):
            nprt.train(dataset, "baseline", tmp_path / "m", **{arg: value}, progress=False)
    for arg in ["jitter_exposure", "spread", "fov"]:
        with pytest.raises(nprt.InputError, match=arg):
            nprt.generate("builtin:room", "builtin", tmp_path / "d", **{arg: value},
                          progress=False)
    with pytest.raises(nprt.InputError, match="exposure"):
        nprt.write_image(tmp_path / "x.png", np.zeros((2, 2, 3), np.float32), exposure=value)
    assert not (tmp_path / "m").exists() and not (tmp_path / "d").exists()


def test_sizes_name_their_argument(room):
    sky = nprt.open_envmap("builtin:sky")
    camera, fov, _ = room.camera()
    for w, h, arg in [(-1, 4, "width"), (4, 0, "height"), (2**40, 4, "width")]:
        with pytest.raises(nprt.InputError, match=f"{arg}=.*must be a whole number from 1"):
            nprt.reference(room, sky, camera, w, h, fov)


def test_builtin_map_numbers_are_checked():
    for spec in ["builtin:indoor:-1", "builtin:indoor:2.5", "builtin:sky:nan", "builtin:sky:1:2:3:4"]:
        with pytest.raises(nprt.NprtError, match=spec):
            nprt.open_envmap(spec)
    assert nprt.open_envmap("builtin:indoor:7").name == "builtin:indoor:7"


def test_enum_like_strings_list_their_choices(dataset):
    ds = nprt.Dataset(dataset)
    with pytest.raises(nprt.InputError, match="split='tset': must be 'train' or 'test'"):
        ds.split("tset")
    with pytest.raises(nprt.InputError, match="cpu, gpu, wgpu or auto"):
        nprt.Model("anything", device="tpu")


def test_transfer_choices_are_refused_by_name(dataset, tmp_path):
    with pytest.raises(nprt.InputError, match="transfer=.*at most sh:8"):
        nprt.generate("builtin:room", "builtin", tmp_path / "d", transfer="sh:9")
    with pytest.raises(nprt.InputError, match="radiance or transfer"):
        nprt.train(dataset, "linear", tmp_path / "m", targets="vectors")
    # A dataset made without them: the call says how to make one with them.
    with pytest.raises(nprt.NprtError, match="holds no transfer vectors"):
        nprt.train(dataset, "linear", tmp_path / "m", targets="transfer", basis="sh:1")


def test_a_model_warns_when_it_renders_another_scene(model, tmp_path):
    cube = tmp_path / "cube.obj"
    cube.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    other = nprt.load_scene(cube)
    camera = nprt.look_at([0.3, 0.3, 3], [0.3, 0.3, 0])
    sky = nprt.open_envmap("builtin:sky")
    m = nprt.Model(model)
    with pytest.warns(UserWarning, match="was trained on scene 'builtin:room'"):
        m.render(other, sky, camera, 8, 6, 40.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m.render("builtin:room", sky, camera, 8, 6, 40.0)  # its own scene: no warning


def test_train_refuses_a_dataset_folder_as_its_output(dataset):
    before = sorted(p.name for p in pathlib.Path(dataset).iterdir())
    with pytest.raises(nprt.NprtError, match="is a dataset folder"):
        nprt.train(dataset, "baseline", dataset, epochs=1, progress=False)
    assert sorted(p.name for p in pathlib.Path(dataset).iterdir()) == before


def _fails_in_a_worker(path):
    return nprt.load_scene(path)


def test_errors_pickle_across_processes(tmp_path):
    missing = str(tmp_path / "missing.xml")
    with concurrent.futures.ProcessPoolExecutor(1) as pool:
        with pytest.raises(nprt.NprtError, match="missing.xml"):
            pool.submit(_fails_in_a_worker, missing).result()
    for error in [nprt.NprtError("a"), nprt.InputError("b"), nprt.Interrupted("c")]:
        again = pickle.loads(pickle.dumps(error))
        assert type(again) is type(error) and str(again) == str(error)
    assert issubclass(nprt.InputError, ValueError)
    assert issubclass(nprt.Interrupted, KeyboardInterrupt)


def test_scenes_maps_and_paths_pass_any_way(room, tmp_path):
    camera, fov, _ = room.camera()
    sky = nprt.open_envmap("builtin:sky")
    by_object = nprt.reference(room, sky, camera, 8, 6, fov, spp=1)
    by_name = nprt.reference("builtin:room", "builtin:sky", camera, 8, 6, fov, spp=1)
    np.testing.assert_array_equal(by_object, by_name)
    nprt.write_image(tmp_path / "sky.exr", sky.to_array())
    assert nprt.open_envmap(tmp_path / "sky.exr").shape == sky.shape
    with pytest.raises(nprt.InputError, match="scene=3: must be an nprt.Scene, a str or an os.PathLike"):
        nprt.reference(3, sky, camera, 8, 6, fov)
    # A loaded scene where generate takes a scene; a single map where it takes a folder is
    # refused saying what it takes.
    done = nprt.generate(room, "builtin", tmp_path / "d", train_views=1, test_views=1,
                         train_res=(8, 8), test_res=(8, 8), spp=1, test_spp=2, progress=False)
    assert done["rendered"] == 2
    with pytest.raises(nprt.NprtError, match="is one map; the maps of a dataset are a folder"):
        nprt.generate(room, tmp_path / "sky.exr", tmp_path / "e", progress=False)


def test_messages_name_python_arguments_and_say_each_cause_once(dataset, tmp_path):
    with pytest.raises(nprt.NprtError) as raised:
        nprt.open_envmap(tmp_path / "missing.exr")
    assert str(raised.value).count("cannot read") == 1, raised.value
    with pytest.raises(nprt.NprtError, match="is a folder") as raised:
        nprt.load_scene(tmp_path)
    out = tmp_path / "data"
    small = dict(train_views=1, test_views=1, train_res=(8, 8), test_res=(8, 8), spp=1,
                 test_spp=2, progress=False)
    nprt.generate("builtin:room", "builtin", out, **small)
    with pytest.raises(nprt.NprtError) as raised:
        nprt.generate("builtin:room", "builtin", out, **{**small, "train_views": 2})
    text = str(raised.value)
    assert "out=" in text and "--out" not in text and len(text) < 600, text


def test_signatures_and_types_match_the_stubs(room):
    assert "up=(0.0, 1.0, 0.0)" in nprt.look_at.__text_signature__
    lo, hi = room.bounds
    assert isinstance(lo, tuple) and isinstance(hi, tuple) and len(lo) == 3
    public = [n for n in dir(nprt) if not n.startswith("_")]
    assert "os" not in public and "csv" not in public
    assert set(nprt.__all__) <= set(dir(nprt))
