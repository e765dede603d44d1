#!/usr/bin/env bash
# Every GPU measurement of nprt's training and frame goals in one go, on a machine with an
# NVIDIA GPU, its Vulkan driver and PyTorch with CUDA. Its parts, as run on one H200
# (2026-11-26): training at 16,384 with the eager peers about 70 s, with the torch.compile ones
# 4 more minutes; at 262,144 with the eager peers about 60 s; frames about 50 s; with --kitchen
# 10 minutes of training and an evaluation more. Writes one summary file (Markdown) with:
#   1. `nprt bench train --device gpu --profile` (nprt's own kernels, and each kernel's GPU
#      time in a step) per design, in f32 and in mixed precision (f16 products on tensor cores),
#      beside PyTorch on CUDA, eager and torch.compile, each in f32 and bf16 autocast (the
#      fastest is the peer), at batch 16,384 and 262,144;
#   2. the paper's schedule (3000 views of 256², 500 epochs) projected from those rates, and its
#      data (3000 views at 3200 spp) from `nprt generate --device` on the GPU and on the CPU
#      (a small builtin:room dataset each, measured after the frames), and the Deep Shading
#      U-Net trained 10 epochs of the GPU's dataset on the kernels and on the CPU;
#   3. `nprt bench frame --profile` (G-buffer, encoder, networks, direct light traced on the GPU,
#      total; each kernel of a lighting change)
#      per design, and D/S with 16 spp of traced direct light, at 512² and 1920×1080
#      on the GPU kernels, in f32 and in f16 (tensor cores where the adapter has them),
#      beside the paper's Table 3;
#   4. with --kitchen: D/S trained 10 minutes on the GPU on that dataset (in --kitchen-precision)
#      and evaluated with `nprt eval` beside --cpu-model (the same design trained 10 minutes on
#      the CPU).
#
# With --quick (one H100 loan of about 15 minutes, start-up included): from what
# bench/gpu-prepare.sh built beforehand on a machine without a GPU (in --prepared, default .gpu,
# carried to the GPU machine): the GPU kernels' correctness tests first (f32 and the
# f16/tensor-core paths against the CPU engine), then 1 at 16,384 and 3 with the eager peers
# only, then 1 at 262,144, 2, the tensor-core products' variants (cooperative_matrix), and D/S
# trained 1 minute in f32 and in f16 on the prepared dataset (validation losses side by side);
# about 6 minutes on an H100. Every section is appended to the
# summary as soon as it is measured, so a run cut short keeps what it measured.
#
# usage: bench/gpu.sh [--quick [--prepared DIR]]
#                     [--nprt BIN] [--python PY] [--kitchen DATASET --cpu-model MODEL]
#                     [--summary FILE] [--work DIR] [--batches "16384 262144"] [--res 512,1920x1080]
#                     [--peer-variants LIST] [--precision LIST] [--kitchen-precision P]
#   --quick      the short run above
#   --prepared   bench/gpu-prepare.sh's folder (default .gpu)
#   --nprt       the nprt binary (default target/release/nprt, built with `--features gpu`
#                when missing; with --quick, the prepared one)
#   --python     Python with PyTorch and CUDA (default python3)
#   --kitchen    a KITCHEN dataset (`nprt generate --scene ../shared/kitchen/... --out DIR`)
#   --cpu-model  D/S trained on it for 10 minutes on the CPU
#                (`nprt train --data DIR --arch dsep --minutes 10 --device cpu --out MODEL`)
#   --summary    the summary file (default bench-gpu-summary.md)
#   --work       where models and reports go (default a temporary folder)
#   --batches    the training batch sizes (default "16384 262144")
#   --res        the frame sizes (default 512,1920x1080); both only to try the script small
#   --peer-variants  the PyTorch variants (default eager-f32,eager-bf16,compile-f32,compile-bf16;
#                eager-f32,eager-bf16 spares torch.compile's minutes on a short loan)
#   --precision  nprt's training precisions, a row each (default f32,f16)
#   --kitchen-precision  the KITCHEN run's (default f32)
#   --device     nprt's --device (default gpu; wgpu runs on any adapter, a software one too,
#                to try the script where there is no GPU)
set -euo pipefail
cd "$(dirname "$0")/.."

nprt=target/release/nprt
python=python3
kitchen=
cpu_model=
summary=bench-gpu-summary.md
work=
batches="16384 262144"
res=512,1920x1080
variants=eager-f32,eager-bf16,compile-f32,compile-bf16
precisions=f32,f16
kitchen_precision=f32
quick=
prepared=.gpu
nprt_given=
device=gpu
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1; shift ;;
    --prepared) prepared=$2; shift 2 ;;
    --nprt) nprt=$2; nprt_given=1; shift 2 ;;
    --python) python=$2; shift 2 ;;
    --kitchen) kitchen=$2; shift 2 ;;
    --cpu-model) cpu_model=$2; shift 2 ;;
    --summary) summary=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --batches) batches=$2; shift 2 ;;
    --res) res=$2; shift 2 ;;
    --peer-variants) variants=$2; shift 2 ;;
    --precision) precisions=$2; shift 2 ;;
    --kitchen-precision) kitchen_precision=$2; shift 2 ;;
    --device) device=$2; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench/gpu.sh: unknown argument '$1' (--help lists them)" >&2; exit 2 ;;
  esac
done
if [ -n "$kitchen" ] && [ -z "$cpu_model" ]; then
  echo "bench/gpu.sh: --kitchen needs --cpu-model (the same design trained 10 minutes on the CPU)" >&2
  exit 2
fi

if [ -n "$quick" ]; then
  [ -x "$prepared/nprt" ] || {
    echo "bench/gpu.sh: --quick needs bench/gpu-prepare.sh's folder '$prepared' (no '$prepared/nprt')" >&2
    exit 1
  }
  [ -n "$nprt_given" ] || nprt=$prepared/nprt
  variants=eager-f32,eager-bf16
  source bench/gpu-vulkan.sh
  use_prepared_vulkan "$prepared/lib"
fi

# What the run needs, each missing piece named.
command -v nvidia-smi >/dev/null || { echo "bench/gpu.sh: no nvidia-smi: this needs an NVIDIA GPU" >&2; exit 1; }
{ ldconfig -p | grep -q 'libvulkan\.so\.1' || [ -n "${LD_LIBRARY_PATH:-}" ]; } || {
  echo "bench/gpu.sh: no Vulkan loader (libvulkan.so.1): nprt's GPU kernels run on wgpu over Vulkan; install libvulkan1 and the NVIDIA driver's Vulkan ICD" >&2
  exit 1
}
"$python" -c 'import torch, sys; sys.exit(0 if torch.cuda.is_available() else 1)' || {
  echo "bench/gpu.sh: '$python' has no PyTorch with CUDA (the peer)" >&2
  exit 1
}
if [ ! -x "$nprt" ]; then
  cargo build --release -p nprt --features gpu
fi
if [ -z "$work" ]; then
  work=$(mktemp -d)
fi
mkdir -p "$work"

designs=baseline,prt,albedo,dsep
log() { echo "bench/gpu.sh: $*" >&2; }

{
  echo "# nprt on the GPU: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo
  echo '```'
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
  "$python" -c 'import torch; print("PyTorch", torch.__version__, "CUDA", torch.version.cuda)'
  # A prepared binary names the commit it was built from (a carried copy may have no .git).
  commit=$(cat "$(dirname "$nprt")/commit" 2>/dev/null || git rev-parse --short HEAD 2>/dev/null || echo '(no git)')
  echo "nprt $commit: $nprt"
  echo '```'
} >"$summary"

section() { printf '\n## %s\n\n```\n' "$1" >>"$summary"; }
end_section() { echo '```' >>"$summary"; }

failed=
# 0. With --quick: the kernels' correctness on this adapter before any of their timings.
if [ -n "$quick" ]; then
  section "The GPU kernels' correctness tests (NPRT_REQUIRE_VULKAN=1)"
  for t in "$prepared"/tests/*; do
    [ -x "$t" ] || continue
    log "correctness: $(basename "$t")"
    if ! NPRT_REQUIRE_VULKAN=1 "$t" 2>&1 | tee "$work/$(basename "$t").txt" |
      grep -E '^test |^test result|panicked|skipped' >>"$summary"; then
      failed=1
    fi
    grep -q '^test result: ok' "$work/$(basename "$t").txt" || failed=1
  done
  end_section
fi

# 1. Training throughput beside PyTorch. One round: each variant's process compiles anew, and
# torch.compile's compile falls in its warm-up steps.
train_rates() {
  local batch=$1 steps
  steps=$([ "$batch" -le 16384 ] && echo 20 || echo 5)
  log "training throughput at batch $batch"
  section "Training samples/s at batch $batch (nprt's kernels on wgpu; PyTorch on CUDA)"
  "$nprt" bench train --device "$device" --python "$python" --peer-variants "$variants" \
    --precision "$precisions" --arch "$designs" --batch-size "$batch" --steps "$steps" \
    --warmup 3 --rounds 1 --profile \
    | tee "$work/train-$batch.txt" >>"$summary"
  end_section
}

# 3. The frame, stage by stage.
frames() {
  log "frame timings"
  section "Frame ms (nprt bench frame --device $device); the paper's Table 3 (RTX 3090, 512²): encoder 0.34 ms, networks 9.7-16 ms"
  "$nprt" bench frame --device "$device" --arch "$designs" --res "$res" --repeats 10 --precision f32,f16 \
    --profile >>"$summary"
  end_section
}

# Data generation: the same small builtin:room dataset path traced on the GPU and on every CPU
# core (`nprt generate --device`), each run's samples/s line.
generation() {
  log "data generation on $device and on the CPU"
  section "Data generation (nprt generate, builtin:room, 20 views of 128² at 64 spp): GPU, then CPU ($(nproc) threads)"
  for d in "$device" cpu; do
    rm -rf "$work/generate-$d"
    "$nprt" generate --scene builtin:room --envmaps builtin --out "$work/generate-$d" \
      --train-views 16 --test-views 4 --spp 64 --test-spp 64 --device "$d" 2>&1 \
      | tail -n 1 | sed "s/^/$d: /" | tee -a "$work/generate.txt" >>"$summary" || failed=1
  done
  end_section
}

# The Deep Shading U-Net on the kernels and on every CPU core, 10 epochs of the dataset the
# GPU just generated (16 views of 128², 4 a step), each run's summary line.
deep_shading() {
  [ -f "$work/generate-$device/manifest.json" ] || return 0
  log "Deep Shading on $device and on the CPU"
  section "Deep Shading (nprt train-deep-shading, 10 epochs of 16 views of 128²): GPU, then CPU ($(nproc) threads)"
  for d in "$device" cpu; do
    "$nprt" train-deep-shading --data "$work/generate-$device" --out "$work/deep-shading-$d" \
      --epochs 10 --device "$d" 2>&1 | grep -E '^(trained|time)' | sed "s/^/$d: /" >>"$summary" || failed=1
  done
  end_section
}

# The smallest batch first, then the frames and data generation, then the larger batches: a
# short loan measures the most-asked figures first.
first=${batches%% *}
train_rates "$first"
frames
generation
deep_shading
for batch in $batches; do
  [ "$batch" = "$first" ] || train_rates "$batch"
done

# 2. The paper's schedule from the measured rates: 3000 views × 256² pixels × 500 epochs (every
# pixel counted, as if all were foreground).
section "The paper's schedule (3000 views of 256², 500 epochs) projected from the rates above"
for batch in $batches; do
  awk -v batch="$batch" '$1 ~ /^(baseline|prt|albedo|dsep)$/ {
      samples = 3000 * 256 * 256 * 500
      printf "batch %6d  %-9s %s nprt %6.1f min   PyTorch %6s min\n", batch, $1, $3,
        samples / $4 / 60, ($5 == "-" ? "-" : sprintf("%.1f", samples / $5 / 60))
    }' "$work/train-$batch.txt" >>"$summary"
done
# Its data: 3000 views of 256² at 3200 spp (the paper's references), at the rates measured.
if [ -f "$work/generate.txt" ]; then
  sed -nE 's/^([a-z]+): .* ([0-9.]+) Msamples\/s.*/\1 \2/p' "$work/generate.txt" \
    | awk '$2 > 0 { printf "data on %-4s 3000 views of 256² at 3200 spp: %8.1f h\n", $1, 3000 * 65536 * 3200 / ($2 * 1e6) / 3600 }' >>"$summary"
fi
end_section

# With --quick: the tensor-core products at the frame's and training's shapes, per variant.
if [ -n "$quick" ] && [ -x "$prepared/cooperative_matrix" ]; then
  log "cooperative-matrix products"
  section "Cooperative-matrix products (crates/nprt-render/benches/cooperative_matrix.rs)"
  timeout 120 "$prepared/cooperative_matrix" >>"$summary" 2>&1 || failed=1
  end_section
fi

# With --quick: does f16 train D/S as well as f32 (its validation loss within 1%)?
if [ -n "$quick" ] && [ -f "$prepared/data/manifest.json" ]; then
  section "D/S trained 1 minute on the prepared dataset, f32 then f16: the last epochs' losses"
  for p in f32 f16; do
    log "training D/S 1 minute in $p"
    "$nprt" train --data "$prepared/data" --arch dsep --minutes 1 --device "$device" --precision "$p" \
      --out "$work/precision-$p" 2>&1 | tail -n 4 >>"$summary" || failed=1
  done
  end_section
fi

# 4. KITCHEN: 10 minutes of training on the GPU against 10 on the CPU.
if [ -n "$kitchen" ]; then
  log "training D/S on '$kitchen' for 10 minutes ($kitchen_precision)"
  section "KITCHEN: D/S trained 10 minutes on the GPU ($kitchen_precision)"
  "$nprt" train --data "$kitchen" --arch dsep --minutes 10 --device "$device" --out "$work/kitchen-gpu" \
    --precision "$kitchen_precision" >>"$summary"
  end_section
  log "evaluating"
  "$nprt" eval --model "$work/kitchen-gpu","$cpu_model" --data "$kitchen" --out "$work/kitchen-eval" \
    --device "$device" >/dev/null
  printf '\n## KITCHEN: nprt eval of the GPU model, then the CPU model\n\n' >>"$summary"
  cat "$work/kitchen-eval/report.md" >>"$summary"
fi
log "summary in '$summary'"
if [ -n "$failed" ]; then
  log "a correctness test or a run failed (see the summary)"
  exit 1
fi
