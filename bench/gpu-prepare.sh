#!/usr/bin/env bash
# Prepares, on a machine without a GPU, everything `bench/gpu.sh --quick` needs on one with an
# NVIDIA GPU, so that a short loan is spent measuring, not building: in the folder .gpu/ (git
# ignores it; about 50 MiB, inside a 64 MiB transfer):
#   nprt        the release binary with the GPU kernels (`--features gpu`), stripped;
#   tests/      the GPU kernels' correctness tests (nprt-net's gpu_training, gpu_unet, gpu_cache,
#               gpu_frame: f32 and the f16/tensor-core paths against the CPU engine; nprt_net
#               and nprt_engine, their libraries' own tests, among them each tensor-core
#               kernel's against the host;
#               nprt-trace's gpu_trace: the path tracer against the CPU's), stripped;
#   cooperative_matrix  nprt-render's bench of the tensor-core products (frame and training
#               shapes), stripped;
#   lib/        the Vulkan loader (libvulkan.so.1) and glvnd's libraries (Debian's), for a GPU
#               machine whose image has the NVIDIA driver's Vulkan ICD but neither;
#   data/       a small dataset of builtin:room (24 training views of 64² at 16 spp, 6 test
#               views, packed) for the f32/f16 training comparison.
# The binaries target x86-64-v3 (.cargo/config.toml) and this machine's glibc: the GPU machine
# must be x86-64 with a glibc at least as new.
#
# usage: bench/gpu-prepare.sh [--out DIR]   (default .gpu)
set -euo pipefail
cd "$(dirname "$0")/.."

out=.gpu
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench/gpu-prepare.sh: unknown argument '$1' (--help lists them)" >&2; exit 2 ;;
  esac
done
log() { echo "bench/gpu-prepare.sh: $*" >&2; }
mkdir -p "$out/tests" "$out/lib"

log "building the release binary with the GPU kernels"
cargo build --release -p nprt --features gpu
strip -o "$out/nprt" target/release/nprt
echo "$(git rev-parse --short HEAD)$(git diff --quiet HEAD || echo ' with uncommitted changes')" >"$out/commit"

# Test and bench executables: cargo prints each one's path as JSON; both profiles optimise.
# Test `lib` is the package's library's own tests, named after the library.
test_binary() {
  local command=$1 package=$2 features=$3 test=$4
  local target=(--"$command" "$test") name=$test
  if [ "$test" = lib ]; then target=(--lib) name=${package//-/_}; fi
  cargo "$command" -p "$package" --features "$features" "${target[@]}" --no-run \
    --message-format=json 2>/dev/null |
    python3 -c 'import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["target"]["name"] == sys.argv[1]:
        print(m["executable"])' "$name"
}
log "building the GPU kernels' tests"
for spec in nprt-net:gpu:gpu_training nprt-net:gpu:gpu_unet nprt-net:gpu:gpu_cache \
  nprt-net:gpu:gpu_frame nprt-net:gpu:lib nprt-engine:gpu:lib \
  nprt-trace:gpu:gpu_trace; do
  IFS=: read -r package features test <<<"$spec"
  exe=$(test_binary test "$package" "$features" "$test")
  [ -x "$exe" ] || { log "no test executable for $spec"; exit 1; }
  # Named as cargo names it, less its hash: gpu_training, nprt_net (a library's tests).
  exe_name=$(basename "$exe")
  strip -o "$out/tests/${exe_name%-*}" "$exe"
done
log "building the cooperative-matrix benchmark"
exe=$(test_binary bench nprt-render gpu cooperative_matrix)
[ -x "$exe" ] || { log "no executable for the cooperative_matrix bench"; exit 1; }
strip -o "$out/cooperative_matrix" "$exe"

# The loader alone is not enough: NVIDIA's Vulkan ICD is libGLX_nvidia, which needs glvnd's
# dispatch libraries (a loan without them found no adapter).
log "fetching the Vulkan loader and glvnd"
debs=$(mktemp -d)
(cd "$debs" && apt-get download libvulkan1 libglvnd0 libgl1 libglx0 libegl1 libopengl0 libgles2 \
  >/dev/null)
for deb in "$debs"/*.deb; do dpkg -x "$deb" "$debs/root"; done
cp -a "$debs"/root/usr/lib/x86_64-linux-gnu/*.so.* "$out/lib/"
rm -rf "$debs"

if [ ! -f "$out/data/manifest.json" ]; then
  log "generating a small dataset of builtin:room"
  "$out/nprt" generate --scene builtin:room --envmaps builtin --train-views 24 --test-views 6 \
    --train-res 64 --test-res 64 --spp 16 --test-spp 64 --seed 1 --out "$out/data"
  # Packed here, so that the loan does not spend its time packing.
  "$out/nprt" dataset pack "$out/data"
fi
du -sh "$out"
log "ready: carry '$out' (and run bench/gpu.sh --quick there)"
