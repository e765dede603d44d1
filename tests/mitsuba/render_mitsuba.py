"""Renders a Mitsuba 3 scene to OpenEXR, for nprt's agreement test and speed benchmark.

usage: render_mitsuba.py SCENE.xml OUT.exr [--variant V] [--spp N] [--seed S] [--warmup]
                         [--set NAME=VALUE ...]
Prints one JSON line: {"variant", "seconds", "spp", "width", "height"}; with --warmup the scene
is rendered once first so the timing excludes the LLVM variant's kernel compilation.
"""
import argparse
import json
import time

import mitsuba as mi


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--spp", type=int)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--warmup", action="store_true")
    ap.add_argument("--set", action="append", default=[])
    a = ap.parse_args()
    mi.set_variant(a.variant)
    # Real maps hold a few tiny negative texels; Mitsuba warns once per sample that meets one.
    mi.set_log_level(mi.LogLevel.Error)
    params = dict(kv.split("=", 1) for kv in a.set)
    scene = mi.load_file(a.scene, **params)
    spp = a.spp or scene.sensors()[0].sampler().sample_count()
    if a.warmup:
        img = mi.render(scene, spp=spp, seed=a.seed + 1000)
        mi.Bitmap(img)  # forces evaluation
    t = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=a.seed)
    bmp = mi.Bitmap(img)
    secs = time.perf_counter() - t
    bmp.write(a.out)
    size = scene.sensors()[0].film().size()
    print(json.dumps({"variant": a.variant, "seconds": secs, "spp": spp, "width": int(size[0]), "height": int(size[1])}))


if __name__ == "__main__":
    main()
