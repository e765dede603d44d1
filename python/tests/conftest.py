"""What the tests of the Python package share: the built-in room, and a tiny dataset and D/S
model made once per session through the package itself."""

import pathlib

import numpy as np
import pytest

import nprt

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def room():
    return nprt.load_scene("builtin:room")


@pytest.fixture(scope="session")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("data")
    done = nprt.generate(
        "builtin:room", "builtin", out, train_views=6, test_views=2, train_res=(24, 24),
        test_res=(32, 24), spp=4, test_spp=8, seed=3, progress=False,
    )
    assert done["rendered"] == 8 and done["skipped"] == 0 and done["msamples_per_s"] > 0
    return out


@pytest.fixture(scope="session")
def model(dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("model")
    run = nprt.train(dataset, "dsep", out, epochs=2, progress=False)
    assert run["epochs"] == pytest.approx(2.0) and np.isfinite(run["val_loss"])
    return out
