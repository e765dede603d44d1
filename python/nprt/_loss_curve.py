"""A training run's loss curves as numpy arrays."""

import csv
import os

import numpy as np


def loss_curve(model_dir):
    """The loss curves of a training run (its model folder's loss.csv) as a dict of equal-length
    float64 numpy arrays, one entry per row: ``step``, ``epoch``, ``samples``, ``seconds``,
    ``train_loss`` (every row's) and ``val_loss`` (NaN on rows that were not validated: each
    epoch's end is). ``model_dir`` is a ``str`` or a ``pathlib.Path``."""
    path = os.path.join(os.fspath(model_dir), "loss.csv")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    keys = ["step", "epoch", "samples", "seconds", "train_loss", "val_loss"]
    return {
        k: np.array([float(r[k]) if r.get(k) else np.nan for r in rows], dtype=np.float64)
        for k in keys
    }
