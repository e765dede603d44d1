"""The conveniences a notebook expects: images to and from files, datasets indexed and
iterated with each view's lighting, clean loss curves and callbacks, and Ctrl-C that stops
every long call within a moment, leaving its outputs resumable."""

import os
import signal
import threading

import numpy as np
import pytest

import nprt


def test_images_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    image = rng.random((5, 7, 3), dtype=np.float32) * 4
    nprt.write_image(tmp_path / "a.exr", image)
    np.testing.assert_array_equal(nprt.read_image(tmp_path / "a.exr"), image)
    nprt.write_image(str(tmp_path / "a.hdr"), image)
    # RGBE: an 8-bit mantissa per channel under the pixel's largest channel's exponent.
    hdr_step = image.max(axis=2, keepdims=True) / 128
    assert np.all(np.abs(nprt.read_image(tmp_path / "a.hdr") - image) <= hdr_step)
    # PNG: sRGB of the radiance scaled by 2**exposure, clamped to 1.
    nprt.write_image(tmp_path / "a.png", image / 8, exposure=1)
    np.testing.assert_allclose(nprt.read_image(tmp_path / "a.png"), np.minimum(image / 4, 1),
                               atol=0.01)
    bad = image.copy()
    bad[1, 2, 0] = np.nan
    with pytest.raises(nprt.NprtError, match=r"pixel \(2, 1\)"):
        nprt.write_image(tmp_path / "b.exr", bad)
    assert not (tmp_path / "b.exr").exists()
    with pytest.raises(nprt.NprtError, match=".exr, .hdr or .png"):
        nprt.write_image(tmp_path / "a.tiff", image)
    with pytest.raises(nprt.InputError, match=r"\(H, W, 3\)"):
        nprt.write_image(tmp_path / "c.exr", image[..., :2])


def test_datasets_index_slice_and_iterate_with_their_lighting(dataset):
    ds = nprt.Dataset(dataset)
    first, last = ds[0], ds[-1]
    assert first["index"] == 0 and first["split"] == "train"
    assert last["index"] == len(ds) - 1 and last["split"] == "test"
    np.testing.assert_array_equal(first["radiance"], ds.view(0)["radiance"])
    assert [v["index"] for v in ds[1:5:2]] == [1, 3]
    assert [v["index"] for v in ds] == list(range(len(ds)))
    light = first["lighting"]
    assert light["map"].startswith("builtin:") and len(light["gain"]) == 3
    assert np.isfinite(light["rotation_deg"]) and light["mix"] == []
    with pytest.raises(IndexError):
        ds[len(ds)]
    with pytest.raises(IndexError):
        ds[-len(ds) - 1]
    with pytest.raises(nprt.InputError, match="int or a slice"):
        ds["radiance"]


def test_callbacks_get_numbers_and_loss_curves_are_arrays(dataset, tmp_path):
    rows = []
    nprt.train(dataset, "baseline", tmp_path / "m", epochs=2, callback=rows.append,
               progress=False)
    assert len(rows) == 2
    for row in rows:
        assert np.isfinite(row["train_loss"]) and np.isfinite(row["val_loss"]), row
    curve = nprt.loss_curve(tmp_path / "m")
    assert set(curve) == {"step", "epoch", "samples", "seconds", "train_loss", "val_loss"}
    n = len(curve["step"])
    assert n >= 2 and all(isinstance(a, np.ndarray) and a.shape == (n,) for a in curve.values())
    assert np.all(np.isfinite(curve["train_loss"]))
    validated = curve["val_loss"][np.isfinite(curve["val_loss"])]
    assert len(validated) == 2 and np.all(np.diff(curve["step"]) >= 0)


def _ctrl_c_after(seconds):
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_stops_long_calls_within_a_second(room, dataset, model, tmp_path):
    import time

    camera, fov, _ = room.camera()
    sky = nprt.open_envmap("builtin:sky")
    calls = {
        "reference": lambda: nprt.reference(room, sky, camera, 640, 480, fov, spp=4096),
        "generate": lambda: nprt.generate("builtin:room", "builtin", tmp_path / "d",
                                          train_views=200, test_views=1, train_res=(96, 96),
                                          spp=256, progress=False),
        "render": lambda: nprt.render(model, tmp_path / "film", frames=2000, res=(64, 48)),
        # A network's timing frame is not cut short: at timing_res=512 one takes seconds.
        "evaluate": lambda: nprt.evaluate(dataset, [model], tmp_path / "report",
                                          sh_spp=4096, timing_res=64, progress=False),
    }
    for name, call in calls.items():
        timer = _ctrl_c_after(1.0)
        start = time.monotonic()
        with pytest.raises(nprt.Interrupted):
            call()
        timer.join()
        assert time.monotonic() - start < 1.0 + 1.5, name
    # What generate wrote stays valid and the same call resumes it.
    ds = nprt.Dataset(tmp_path / "d")
    report = ds.verify()
    assert not report["corrupt"] and not report["leftovers"], report
    assert not (tmp_path / "report" / "results.json").exists()
