"""Speed of `nprt reference` against Mitsuba 3 on the same scenes; run through
bench/reference_vs_mitsuba.sh, which installs the peer and builds nprt.

Each renderer runs in a fresh process per run; the median of --runs is reported. Mitsuba's
llvm variant is timed twice: "warm" (a first render compiles its kernels, the second is timed)
and "cold" (the first render, compilation included, as a one-off render pays). Ratios are
nprt's samples/s over the peer's: above 1 means nprt is faster.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
NPRT = os.path.join(ROOT, "target", "release", "nprt")
MITSUBA = os.path.join(ROOT, "tests", "mitsuba", "render_mitsuba.py")


def run_nprt(scene, res, spp, out):
    p = subprocess.run([NPRT, "reference", scene, "--out", out, "--spp", str(spp), f"--set=res={res}"],
                       capture_output=True, text=True, check=True)
    return float(re.search(r" in ([0-9.]+) s", p.stdout).group(1))


def run_mitsuba(scene, res, spp, out, variant, warm):
    cmd = [sys.executable, MITSUBA, scene, out, "--variant", variant, "--spp", str(spp), f"--set=res={res}"]
    if warm:
        cmd.append("--warmup")
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])["seconds"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=[os.path.join(ROOT, "tests", "mitsuba", s) for s in ("diffuse_room.xml", "glossy.xml")])
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    out = os.path.join(ROOT, "target", "bench-out.exr")
    peers = [("mitsuba scalar_rgb", "scalar_rgb", False)]
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        peers = [("mitsuba llvm_ad_rgb (warm)", "llvm_ad_rgb", True), ("mitsuba llvm_ad_rgb (cold)", "llvm_ad_rgb", False)] + peers
    else:
        print("note: no libLLVM 19, so Mitsuba's llvm variant is not measured")
    print(f"{a.res}x{a.res}, {a.spp} spp, median of {a.runs} runs, {os.cpu_count()} cores")
    print(f"{'scene':<16} {'renderer':<28} {'seconds':>8} {'Msamples/s':>11} {'nprt / peer':>12}")
    for scene in a.scenes:
        samples = a.res * a.res * a.spp
        ours = statistics.median(run_nprt(scene, a.res, a.spp, out) for _ in range(a.runs))
        name = os.path.splitext(os.path.basename(scene))[0]
        print(f"{name:<16} {'nprt reference':<28} {ours:8.3f} {samples / ours / 1e6:11.3f} {'':>12}")
        for label, variant, warm in peers:
            t = statistics.median(run_mitsuba(scene, a.res, a.spp, out, variant, warm) for _ in range(a.runs))
            print(f"{name:<16} {label:<28} {t:8.3f} {samples / t / 1e6:11.3f} {t / ours:11.2f}x")


if __name__ == "__main__":
    main()
