"""Every argument checked by nprt before conversion (issue 81): a bad value of any class raises
nprt's InputError (a ValueError) naming the keyword, the value and the rule, never the binding
layer's TypeError or OverflowError; keywords in messages, docstrings that name every keyword."""

import inspect
import re

import numpy as np
import pytest

import nprt

# Values no whole-number argument takes, and the class each stands for.
NOT_WHOLE = [-1, 2**70, 16.0, "16", True, [1], 1 + 2j]
NOT_NUMBER = [float("nan"), float("inf"), "1.5", True, 1j, [1.0]]


def _refused(call, arg):
    with pytest.raises(nprt.InputError, match=f"^{re.escape(arg)}=") as raised:
        call()
    assert isinstance(raised.value, ValueError)
    return str(raised.value)


@pytest.mark.parametrize("bad", NOT_WHOLE)
def test_whole_number_arguments_refuse_every_class_by_name(room, dataset, model, tmp_path, bad):
    sky = nprt.open_envmap("builtin:sky")
    camera, fov, _ = room.camera()
    _refused(lambda: nprt.reference(room, sky, camera, bad, 6, fov), "width")
    _refused(lambda: nprt.reference(room, sky, camera, 8, 6, fov, spp=bad), "spp")
    _refused(lambda: nprt.reference(room, sky, camera, 8, 6, fov, seed=bad), "seed")
    _refused(lambda: nprt.Model(model).render(room, sky, camera, 8, bad, fov), "height")
    _refused(lambda: nprt.Model(model).render(room, sky, camera, 8, 6, fov, direct_spp=bad),
             "direct_spp")
    for arg in ["epochs", "batch_size", "seed"]:
        _refused(lambda: nprt.train(dataset, "baseline", tmp_path / "m", **{arg: bad},
                                    progress=False), arg)
    for arg in ["train_views", "spp", "test_maps", "seed"]:
        _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", **{arg: bad},
                                       progress=False), arg)
    _refused(lambda: nprt.evaluate(dataset, model, tmp_path / "r", views=bad), "views")
    _refused(lambda: nprt.render(model, tmp_path / "f", frames=bad), "frames")
    _refused(lambda: nprt.model_info(arch="dsep", encoder_width=bad), "encoder_width")
    if type(bad) is int:  # -1 is the last view, as ds[-1]; past either end an IndexError
        with pytest.raises(IndexError, match="index="):
            nprt.Dataset(dataset).view(2**70)
    else:
        _refused(lambda: nprt.Dataset(dataset).view(bad), "index")
    assert not (tmp_path / "m").exists() and not (tmp_path / "d").exists()


@pytest.mark.parametrize("bad", NOT_NUMBER)
def test_number_arguments_refuse_every_class_by_name(room, dataset, model, tmp_path, bad):
    sky = nprt.open_envmap("builtin:sky")
    camera, _, _ = room.camera()
    _refused(lambda: nprt.reference(room, sky, camera, 8, 6, fov=bad), "fov")
    _refused(lambda: sky.rotated(bad), "degrees")
    _refused(lambda: nprt.Model(model).render(room, sky, camera, 8, 6, rotation=bad), "rotation")
    for arg in ["lr", "minutes"]:
        _refused(lambda: nprt.train(dataset, "baseline", tmp_path / "m", **{arg: bad}), arg)
    _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", mix_builtin=bad),
             "mix_builtin")
    _refused(lambda: nprt.write_image(tmp_path / "x.png", np.zeros((2, 2, 3)), exposure=bad),
             "exposure")


def test_ranges_sizes_points_and_flags_name_their_rule(room, dataset, tmp_path):
    sky = nprt.open_envmap("builtin:sky")
    camera, _, _ = room.camera()
    for fov in [0, 180, 400, -5]:
        assert "fov" in _refused(lambda: nprt.reference(room, sky, camera, 8, 6, fov=fov), "fov")
    message = _refused(lambda: nprt.train(dataset, "baseline", tmp_path / "m", minutes=1e-300),
                       "minutes")
    assert "1e-300" in message and "0.001" in message, message
    _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", train_res=(8,)),
             "train_res")
    _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", train_res=0),
             "train_res")
    _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", look=[0, 1]),
             "look")
    _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", shard=(2, 2)),
             "shard")
    _refused(lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d", progress="no"),
             "progress")
    _refused(lambda: nprt.look_at([0, 0], [0, 0, -1]), "origin")
    _refused(lambda: nprt.look_at("abc", [0, 0, -1]), "origin")
    for camera_bad in [np.eye(4).ravel(), np.eye(3), [["a"] * 4] * 4, np.eye(4) * 1j]:
        _refused(lambda: nprt.reference(room, sky, camera_bad, 8, 6), "camera")
    for arg in ["scene", "out"]:
        with pytest.raises(nprt.InputError, match=arg):
            nprt.generate(*[None if a == arg else v for a, v in
                            [("scene", "builtin:room"), ("envmaps", "builtin"), ("out", tmp_path)]])
    _refused(lambda: nprt.train(dataset, 3, tmp_path / "m"), "arch")
    assert not (tmp_path / "m").exists() and not (tmp_path / "d").exists()


def test_a_callback_that_is_not_callable_is_refused_before_any_work(dataset, tmp_path):
    _refused(lambda: nprt.train(dataset, "baseline", tmp_path / "m", epochs=1, callback=3),
             "callback")
    _refused(lambda: nprt.train_deep_shading(dataset, tmp_path / "u", callback="x"), "callback")
    assert not (tmp_path / "m").exists() and not (tmp_path / "u").exists()


def test_a_size_is_one_number_or_two_as_on_the_command_line(tmp_path):
    done = nprt.generate("builtin:room", "builtin", tmp_path / "d", train_views=1, test_views=1,
                         train_res=8, test_res=np.int64(8), spp=np.uint8(1), test_spp=2,
                         progress=False)
    assert done["rendered"] == 2
    view = nprt.Dataset(tmp_path / "d").view(-1)
    assert view["radiance"].shape == (8, 8, 3) and view["split"] == "test"


def test_maps_refuse_what_is_no_radiance_and_warn_of_what_they_clamp():
    for bad, said in [(np.zeros((8, 8, 3)), "2:1"), (np.zeros((4, 8, 3)) * 1j, "complex"),
                      (np.full((4, 8, 3), np.nan), "texels"), (np.zeros((4, 8, 3), bool), "bools")]:
        with pytest.raises(nprt.InputError, match="texels=") as raised:
            nprt.EnvMap(bad)
        assert said in str(raised.value), raised.value
    with pytest.warns(UserWarning, match="96 negative texel channels clamped to 0"):
        black = nprt.EnvMap(-np.ones((4, 8, 3)))
    assert black.to_array().max() == 0


def test_model_info_says_what_to_give():
    with pytest.raises(nprt.InputError, match="give a model folder .model=. or a design .arch=."):
        nprt.model_info()


def test_progress_false_writes_nothing_and_one_key_names_the_validation_loss(tmp_path, capfd):
    data = tmp_path / "d"
    nprt.generate("builtin:room", "builtin", data, train_views=2, test_views=1, train_res=8,
                  test_res=8, spp=1, test_spp=2, progress=False)
    capfd.readouterr()
    rows = []
    run = nprt.train(data, "baseline", tmp_path / "m", epochs=1, progress=False,
                     callback=rows.append)
    assert capfd.readouterr().err == ""
    assert "val_loss" in run and "validation_loss" not in run
    assert rows[-1]["val_loss"] == pytest.approx(run["val_loss"])


def test_a_dataset_view_carries_its_transfer_vectors(tmp_path):
    data = tmp_path / "d"
    nprt.generate("builtin:room", "builtin", data, train_views=1, test_views=1, train_res=8,
                  test_res=8, spp=1, test_spp=2, transfer="sh:1", progress=False)
    ds = nprt.Dataset(data)
    train, test = ds.view(ds.split("train")[0]), ds.view(ds.split("test")[0])
    assert train["transfer"].shape == (8, 8, 4, 3) == train["transfer_direct"].shape
    assert train["transfer"].dtype == np.float32 and np.isfinite(train["transfer"]).all()
    assert "transfer" not in test


def _public_callables():
    for name in nprt.__all__:
        obj = getattr(nprt, name)
        if inspect.isclass(obj):
            yield name, obj
            for member, f in vars(obj).items():
                if callable(f) and not member.startswith("_"):
                    yield f"{name}.{member}", f
        elif callable(obj):
            yield name, obj


def test_every_keyword_of_every_function_is_in_its_docstring():
    missing = []
    for name, f in _public_callables():
        try:
            params = inspect.signature(f).parameters
        except (TypeError, ValueError):
            continue
        doc = inspect.getdoc(f) or ""
        for p in params:
            if p not in ("self", "cls") and f"`{p}`" not in doc and p not in doc:
                missing.append(f"{name}({p})")
    assert not missing, missing


def test_scenes_maps_and_models_pickle_by_their_source_and_maps_are_arrays(room, model):
    import pickle

    sky = nprt.open_envmap("builtin:sky")
    again = pickle.loads(pickle.dumps(sky))
    np.testing.assert_array_equal(np.asarray(again), sky.to_array())
    assert again.name == sky.name and np.asarray(sky, dtype=np.float64).dtype == np.float64
    assert np.asarray(sky).shape == (*sky.shape, 3)
    scene = pickle.loads(pickle.dumps(room))
    assert scene.spec == room.spec and scene.triangles == room.triangles
    m = pickle.loads(pickle.dumps(nprt.Model(model)))
    camera, fov, _ = room.camera()
    np.testing.assert_array_equal(m.render(room, sky, camera, 8, 6, fov),
                                  nprt.Model(model).render(room, sky, camera, 8, 6, fov))


def test_the_network_runs_on_a_dataset_view_s_arrays(dataset, model, room):
    m, ds = nprt.Model(model), nprt.Dataset(dataset)
    view = ds.view(ds.split("test")[0])
    sky = nprt.open_envmap(view["lighting"]["map"]).rotated(view["lighting"]["rotation_deg"])
    radiance = m(view, sky)
    assert radiance.shape == view["radiance"].shape and radiance.dtype == np.float32
    background = view["mask"] == 0
    assert (radiance[background] == 0).all() and np.isfinite(radiance).all()
    # The frame render makes of the same view: the same networks on its own G-buffer.
    camera, fov, (w, h) = ds.camera(view["index"])
    frame = m.render(room, sky, camera, w, h, fov)
    both = (view["mask"] > 0) & (np.abs(frame - radiance).max(axis=2) < 1e9)
    assert np.median(np.abs(frame[both] - radiance[both])) < 1e-3 * max(frame[both].mean(), 1e-6)
    _refused(lambda: m({"position": view["position"]}, sky), "gbuffer")
    with pytest.raises(nprt.InputError, match=r"gbuffer\['kd'\] is 2 × 32 pixels"):
        m({**view, "kd": view["kd"][:2]}, sky)
    _refused(lambda: m({**view, "alpha": view["kd"]}, sky), "gbuffer['alpha']")
    weights = m.weights()
    info = nprt.model_info(model)
    assert sum(w.size for w in weights.values()) == info["total_params"]
    assert all(w.dtype == np.float32 for w in weights.values())
    code = m.light_code(sky)
    assert code["code"].shape == (64,) and code["scale"].shape == (3,)


def test_render_without_out_returns_the_frames(model, tmp_path):
    import glob
    import tempfile

    done = nprt.render(model, frames=2, res=(16, 12))
    assert done["frames"].shape == (2, 12, 16, 3) and done["frames"].dtype == np.float32
    assert "frames_dir" not in done and np.isfinite(done["frames"]).all()
    assert not glob.glob(f"{tempfile.gettempdir()}/nprt-render-*")


def test_messages_name_keywords_not_flags(dataset, tmp_path):
    texts = []
    for kwargs in [dict(arch="dsep", targets="transfer"), dict(arch="dsep", basis="sh:2")]:
        with pytest.raises(nprt.NprtError) as raised:
            nprt.train(dataset, out=tmp_path / "m", epochs=1, progress=False, **kwargs)
        texts.append(str(raised.value))
    assert not any("--" in t for t in texts), texts
    assert "targets=" in texts[0] and "basis sh:2" in texts[1], texts
