"""Speed of `nprt reference` against Mitsuba 3 on the same scenes; run through
bench/reference_vs_mitsuba.sh, which installs the peer and builds nprt.

Each renderer runs in a fresh process per run; the median of --runs is reported. Mitsuba's
llvm variant is timed twice: "warm" (a first render compiles its kernels, the second is timed)
and "cold" (the first render, compilation included, as a one-off render pays; Dr.Jit caches
kernels on disk, so after one run "cold" is warm too). Ratios are nprt's samples/s over the
peer's: above 1 means nprt is faster.

Equal spp is not equal quality: the table also gives each renderer's mean squared error
against a reference (the mean of both renderers' renders at --ref-spp, from --runs seeds
each) and the efficiency ratio (1 / (MSE · seconds), nprt over peer): above 1 means nprt
reaches a given error sooner. Every map is first clamped to non-negative texels, as nprt
reads it, so both renderers integrate the same light.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
NPRT = os.path.join(ROOT, "target", "release", "nprt")
MITSUBA = os.path.join(ROOT, "tests", "mitsuba", "render_mitsuba.py")


def run_nprt(scene, res, spp, out, params, seed=0):
    cmd = [NPRT, "reference", scene, "--out", out, "--spp", str(spp), "--seed", str(seed), f"--set=res={res}"]
    p = subprocess.run(cmd + [f"--set={kv}" for kv in params], capture_output=True, text=True, check=True)
    return float(re.search(r" in ([0-9.]+) s", p.stdout).group(1))


def run_mitsuba(scene, res, spp, out, variant, warm, params, seed=0):
    cmd = [sys.executable, MITSUBA, scene, out, "--variant", variant, "--spp", str(spp), "--seed", str(seed), f"--set=res={res}"]
    cmd += [f"--set={kv}" for kv in params]
    if warm:
        cmd.append("--warmup")
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])["seconds"]


def load_rgb(path):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    b = mi.Bitmap(path)
    layers = dict(b.split())
    root = layers.get("<root>", b)
    names = [root.struct_()[i].name for i in range(root.channel_count())]
    a = np.array(root, copy=False).astype(np.float64)
    return np.stack([a[..., names.index(c)] for c in "RGB"], -1)


def clamped_map(scene, tmp):
    """The scene's default envmap with negative texels clamped, written beside the output."""
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    found = re.search(r'<default name="envmap" value="([^"]+)"', open(scene).read())
    if not found:
        print(f"note: {scene} has no <default name=\"envmap\">; its map is used as is")
        return None
    rel = found.group(1)
    src = os.path.normpath(os.path.join(os.path.dirname(scene), rel))
    data = np.maximum(np.array(mi.Bitmap(src), copy=False).astype(np.float32)[..., :3], 0.0)
    out = os.path.join(tmp, os.path.basename(scene) + ".map.exr")
    mi.Bitmap(data).write(out)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=[os.path.join(ROOT, "tests", "mitsuba", s) for s in ("diffuse_room.xml", "glossy.xml")])
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=1024)
    a = ap.parse_args()
    out = os.path.join(ROOT, "target", "bench-out.exr")
    peers = [("mitsuba scalar_rgb", "scalar_rgb", False)]
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        peers = [("mitsuba llvm_ad_rgb (warm)", "llvm_ad_rgb", True), ("mitsuba llvm_ad_rgb (cold)", "llvm_ad_rgb", False)] + peers
    else:
        print("note: no libLLVM 19, so Mitsuba's llvm variant is not measured")
    print(f"{a.res}x{a.res}, {a.spp} spp, median of {a.runs} runs, {os.cpu_count()} cores; MSE against a {a.ref_spp}-spp reference")
    print(f"{'scene':<14} {'renderer':<28} {'seconds':>8} {'Msamples/s':>11} {'speed':>7} {'MSE':>10} {'efficiency':>11}")
    tmp = os.path.join(ROOT, "target", "bench")
    os.makedirs(tmp, exist_ok=True)
    for scene in a.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        clean = clamped_map(scene, tmp)
        params = [f"envmap={clean}"] if clean else []
        samples = a.res * a.res * a.spp
        run_nprt(scene, a.res, a.ref_spp, out, params, seed=999)
        ref = load_rgb(out)
        run_mitsuba(scene, a.res, a.ref_spp, out, peers[-1][1], False, params, seed=999)
        ref = (ref + load_rgb(out)) / 2

        def measure(render):
            times, errs = [], []
            for seed in range(a.runs):
                times.append(render(seed))
                errs.append(float(np.mean((load_rgb(out) - ref) ** 2)))
            return statistics.median(times), statistics.mean(errs)

        ours_t, ours_e = measure(lambda seed: run_nprt(scene, a.res, a.spp, out, params, seed))
        print(f"{name:<14} {'nprt reference':<28} {ours_t:8.3f} {samples / ours_t / 1e6:11.3f} {'':>7} {ours_e:10.5f} {'':>11}")
        for label, variant, warm in peers:
            t, e = measure(lambda seed: run_mitsuba(scene, a.res, a.spp, out, variant, warm, params, seed))
            print(f"{name:<14} {label:<28} {t:8.3f} {samples / t / 1e6:11.3f} {t / ours_t:6.2f}x {e:10.5f} {(e * t) / (ours_e * ours_t):10.2f}x")


if __name__ == "__main__":
    main()
