#!/usr/bin/env bash
# The pretrained KITCHEN: one D/S run of a fixed total (60 minutes of f16 training on the GPU
# kernels, its cosine learning rate over the whole 60, on bench/kitchen.sh's `gpu` dataset:
# 1000 training views of 128² at 64 spp, 32 test views at 1024 spp, 3 maps held out) that every
# GPU loan advances from where the last stopped. The run lives in pretrained/kitchen-dsep/
# (committed): model/ (weights, config, loss curves and the resumable checkpoint with Adam's
# moments), dataset.sha256 (the dataset's identity, written by the first visit) and visits.csv
# (a row per visit). docs/kitchen.md keeps the table by GPU-minutes done.
#
#   bench/kitchen-visit.sh prepare [--ab-base REV]
#       here, without a GPU: bench/gpu-prepare.sh's binaries and tests, the KITCHEN scene and
#       the maps packed into .visit/bundle.tar.xz (about 35 MiB, inside a loan's 64 MiB), with
#       nprt built at REV too (default below; `none` for no A/B): the kernels a visit times
#       beside the current ones (bench/gpu-ab.sh).
#   bench/kitchen-visit.sh run [--minutes M] [--skip-tests]
#       on the GPU machine, with .visit carried, in at most M wall minutes (default 8.5): the
#       GPU kernels' correctness tests (where one fails, again with NPRT_TENSOR_CORES=off, and
#       if they pass there the visit goes on on the plain kernels); the dataset path traced on
#       the device from the fixed flags (timed; its manifest checked against dataset.sha256);
#       training resumed until the visit's time is nearly spent (`nprt train --pause-after`);
#       `nprt bench train` and `bench frame` of D/S; the A/B of the prepared base's training
#       kernels against the current ones (`bench/gpu-ab.sh run`, 2 rounds, D/S f16 at both
#       batch sizes and a new viewpoint's frame at 512² and 1920×1080, about 140 s); then in
#       $OUT (default .visit/out): summary.md, visit.log, model.tar.xz and the test views
#       (testviews.tar.part-*, 15 MiB each), 8 files at most.
#   bench/kitchen-visit.sh land DIR [--cpu-model MODEL]
#       here, on what a visit brought back in DIR: checked whole (`nprt model land`: it loads,
#       its checkpoint holds a validation loss, it continues the last visit), the model replaces
#       pretrained/kitchen-dsep/model as one folder, the row joins visits.csv, and `nprt eval` (CPU; OIDN where scripts/oidn.sh put it)
#       scores it on the visit's test views against their references, beside equal-time path
#       tracing with and without OIDN and D/S trained on the CPU: MODEL, by default
#       pretrained/kitchen-dsep/cpu-f32 (15 CPU-minutes in f32 on the visit's flags, traced on
#       the CPU; its summary.md says how).
#
# Scene and maps sit at .visit/kitchen and .visit/envmaps on both machines (links to ../shared
# here), so the dataset's manifest names the same paths wherever it is read.
# Environment, to try the script without a GPU: VISIT_DEVICE (default gpu; wgpu runs on
# lavapipe), VISIT_BUDGET (default gpu; tiny), VISIT_PRETRAINED (default pretrained/kitchen-dsep),
# VISIT_AB_BATCH (the A/B's batch sizes; default 16384,262144), VISIT_AB_FRAMES (its frame
# sizes; default 512,1920x1080).
# The A/B base: the kernels before the latest changes to them that no GPU has timed yet (the
# training step's f16 bias gradients made with their weights', a convolution's weight and bias
# sums added in one pass, both f16 copies of a weight in one dispatch: 172 → 122 dispatches a
# D/S f16 step; a frame's MLPs fused into one dispatch each, `half_mlp`; a training step's MLPs
# fused forward and backward: 122 → 102; an MLP's weight gradients and f16 copies a dispatch
# each, the encoder's sums added once, the backward pass on to the input: 102 → 70). Move it
# on when a visit has timed them and another change follows.
set -euo pipefail
cd "$(dirname "$0")/.."

total_minutes=60
device=${VISIT_DEVICE:-gpu}
budget=${VISIT_BUDGET:-gpu}
pretrained=${VISIT_PRETRAINED:-pretrained/kitchen-dsep}
ab_base=8d12764
log() { echo "bench/kitchen-visit.sh: $*" >&2; }
die() { log "$*"; exit 1; }
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }

# .visit/kitchen and .visit/envmaps: links to ../shared here, the unpacked bundle there.
link_shared() {
  mkdir -p .visit
  for pair in kitchen:../shared/scenes/kitchen envmaps:../shared/envmaps; do
    local name=${pair%%:*} target=${pair#*:}
    [ -d "$target" ] || die "'$target' is missing (the KITCHEN and the maps come from ../shared)"
    [ -e ".visit/$name" ] || ln -s "$(realpath "$target")" ".visit/$name"
  done
}

prepare() {
  while [ $# -gt 0 ]; do
    case "$1" in
      --ab-base) ab_base=$2; shift 2 ;;
      *) die "unknown argument '$1' (--help lists them)" ;;
    esac
  done
  bench/gpu-prepare.sh --out .gpu
  local base=()
  rm -f .gpu/nprt-base .gpu/nprt-base.commit
  if [ "$ab_base" != none ]; then
    bench/gpu-ab.sh build "$ab_base" .gpu/nprt-base
    base=(.gpu/nprt-base .gpu/nprt-base.commit)
  fi
  cp .gpu/commit .gpu/nprt.commit
  link_shared
  log "packing .visit/bundle.tar.xz"
  XZ_OPT=-T0 tar -cJhf .visit/bundle.tar.xz --transform 's,^\.gpu,gpu,' --transform 's,^\.visit/,,' \
    .gpu/nprt .gpu/commit .gpu/nprt.commit "${base[@]}" .gpu/lib .gpu/tests/gpu_training \
    .gpu/tests/gpu_frame .gpu/tests/nprt_net .gpu/tests/nprt_engine .visit/kitchen .visit/envmaps
  du -h .visit/bundle.tar.xz
  log "ready: carry '.visit/bundle.tar.xz' and run 'bench/kitchen-visit.sh run' on the GPU machine"
}

# Runs each of the bundle's correctness tests (all of them, so that the log has every
# failure), its results into the summary $1, its output into $2 and the log; fails if any did.
correctness() {
  local failed=0 t
  for t in .visit/gpu/tests/*; do
    log "correctness: $(basename "$t")${NPRT_TENSOR_CORES:+ (NPRT_TENSOR_CORES=$NPRT_TENSOR_CORES)}"
    NPRT_REQUIRE_VULKAN=1 timeout 150 "$t" 2>&1 | tee "$2/$(basename "$t").txt" |
      grep -E '^test result|panicked|FAILED' >>"$1" || true
    grep -q '^test result: ok' "$2/$(basename "$t").txt" || failed=1
  done
  return "$failed"
}

run_visit() {
  local minutes=8.5 tests=1
  while [ $# -gt 0 ]; do
    case "$1" in
      --minutes) minutes=$2; shift 2 ;;
      --skip-tests) tests=; shift ;;
      *) die "unknown argument '$1' (--help lists them)" ;;
    esac
  done
  local deadline=$(($(date +%s) + $(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')))
  local out=${OUT:-.visit/out} work=.visit/work
  mkdir -p "$out" "$work"
  exec > >(tee -a "$out/visit.log") 2>&1
  if [ -f .visit/bundle.tar.xz ] && [ ! -x .visit/gpu/nprt ]; then
    log "unpacking the bundle"
    python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])' \
      .visit/bundle.tar.xz .visit
  fi
  local nprt=${VISIT_NPRT:-.visit/gpu/nprt}
  [ -x "$nprt" ] || die "no '$nprt': run 'bench/kitchen-visit.sh prepare' where the code builds"
  [ -f .visit/kitchen/scene.xml ] || link_shared
  source bench/gpu-vulkan.sh
  use_prepared_vulkan .visit/gpu/lib
  local summary=$out/summary.md
  {
    echo "# A visit to the pretrained KITCHEN: $(date -u +%Y-%m-%dT%H:%MZ)"
    echo
    echo "nprt $(cat .visit/gpu/commit 2>/dev/null || git rev-parse --short HEAD 2>/dev/null || echo unknown)"
    nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo "device $device"
  } >"$summary"

  if [ -n "$tests" ]; then
    printf '\n## The GPU kernels'"'"' correctness tests\n\n```\n' >>"$summary"
    if ! correctness "$summary" "$work"; then
      # The plain kernels compute the same sums: a tensor-core kernel that fails here need not
      # cost the visit its training.
      [ -z "${NPRT_TENSOR_CORES:-}" ] ||
        die "a test failed with NPRT_TENSOR_CORES=$NPRT_TENSOR_CORES: not training on kernels that disagree with the CPU engine"
      log "a test failed: again on the plain kernels (NPRT_TENSOR_CORES=off)"
      echo "(again with NPRT_TENSOR_CORES=off, the plain kernels:)" >>"$summary"
      export NPRT_TENSOR_CORES=off
      correctness "$summary" "$work" ||
        die "a test failed on the plain kernels too: not training on kernels that disagree with the CPU engine"
    fi
    echo '```' >>"$summary"
    [ -z "${NPRT_TENSOR_CORES:-}" ] ||
      printf '\n**This visit ran on the plain kernels (NPRT_TENSOR_CORES=off)**: the tensor-core ones failed a test above (visit.log has its output); its training, benches and A/B are the plain kernels'"'"'.\n' >>"$summary"
  fi

  # The model as the last visit left it (a first visit starts the run).
  if [ -f "$pretrained/model/checkpoint/state.json" ] && [ ! -e "$work/model" ]; then
    cp -a "$pretrained/model" "$work/model"
  fi
  mkdir -p "$pretrained"
  # Benches and packing take about 90 s after training, the A/B about 140 s more.
  local after=90 base=.visit/gpu/nprt-base
  [ ! -x "$base" ] || after=230
  bench/kitchen.sh --out "$work" --device "$device" --budget "$budget" --precision f16 \
    --minutes "$total_minutes" --pause-by $((deadline - after)) --data-hash "$pretrained/dataset.sha256" \
    --scene .visit/kitchen/scene.xml --maps .visit/envmaps --nprt "$nprt" --no-eval
  sed -n '2,$p' "$work/summary.md" >>"$summary"

  if [ $(($(date +%s) + 60)) -lt "$deadline" ]; then
    printf '\n## nprt bench train and bench frame (D/S)\n\n```\n' >>"$summary"
    # Beside PyTorch on CUDA where the machine's python3 has it.
    timeout 60 "$nprt" bench train --arch dsep --device "$device" --precision f32,f16 \
      --rounds 1 --python python3 --peer-variants eager-f32,eager-bf16 2>&1 |
      tail -n 8 >>"$summary" || true
    timeout 40 "$nprt" bench frame --arch dsep --device "$device" --res 512 \
      --precision f32,f16 2>&1 | tail -n 10 >>"$summary" || true
    echo '```' >>"$summary"
  fi
  if [ -x "$base" ] && [ $(($(date +%s) + 60)) -lt "$deadline" ]; then
    printf '\n## The training and frame kernels, A/B (bench/gpu-ab.sh)\n\n' >>"$summary"
    timeout $((deadline - $(date +%s) - 45)) bench/gpu-ab.sh run "$base" "$nprt" --rounds 2 \
      --device "$device" --batch-size "${VISIT_AB_BATCH:-16384,262144}" \
      --frames "${VISIT_AB_FRAMES:-512,1920x1080}" >>"$summary" ||
      echo "(the A/B did not finish: $?)" >>"$summary"
  fi

  log "packing what comes back"
  [ -f "$work/model/checkpoint/state.json" ] || die "no model was trained in this visit"
  tar -cJf "$out/model.tar.xz" -C "$work" --exclude snapshots model
  (cd "$work" && tar -cf - data/manifest.json data/views/test_*) |
    split -b 15M -d - "$out/testviews.tar.part-"
  log "done: $(ls "$out" | tr '\n' ' ')"
}

land() {
  local from=${1:-} cpu_model=
  [ -n "$from" ] && [ -d "$from" ] || die "give the folder a visit's files came back to"
  shift
  while [ $# -gt 0 ]; do
    case "$1" in
      --cpu-model) cpu_model=$2; shift 2 ;;
      *) die "unknown argument '$1' (--help lists them)" ;;
    esac
  done
  # The model asked for must be one; the committed one is compared where it is present.
  if [ -n "$cpu_model" ]; then
    [ -f "$cpu_model/model.json" ] || die "--cpu-model: '$cpu_model' holds no model.json"
  elif [ -f "$pretrained/cpu-f32/model.json" ]; then
    cpu_model=$pretrained/cpu-f32
  fi
  [ -f "$from/model.tar.xz" ] || die "'$from' holds no model.tar.xz (did the visit train?)"
  local nprt=${VISIT_NPRT:-target/release/nprt} work=target/kitchen-visit
  # Built whenever it is not given: an older binary lacks `nprt model land`.
  [ -n "${VISIT_NPRT:-}" ] || cargo build -q --release -p nprt
  link_shared
  rm -rf "$work" && mkdir -p "$work"
  tar -xJf "$from/model.tar.xz" -C "$work"
  cat "$from"/testviews.tar.part-* | tar -xf - -C "$work"
  local hash
  hash=$(sha256sum "$work/data/manifest.json" | cut -d' ' -f1)
  mkdir -p "$pretrained"
  if [ -s "$pretrained/dataset.sha256" ] && [ "$(cat "$pretrained/dataset.sha256")" != "$hash" ]; then
    die "the visit's dataset ($hash) is not the run's ($(cat "$pretrained/dataset.sha256"))"
  fi
  # Checked whole before anything of the run changes (nprt model land: the model loads, its
  # checkpoint holds a validation loss, it continues the last visit), then landed as one folder.
  local row
  row=$("$nprt" model land "$work/model" --into "$pretrained" --landed "$(date -u +%Y-%m-%dT%H:%MZ)") ||
    die "the visit's model was not landed; $pretrained is as it was"
  echo "$hash" >"$pretrained/dataset.sha256.new" && mv "$pretrained/dataset.sha256.new" "$pretrained/dataset.sha256"
  log "model landed in $pretrained/model ($row); evaluating on the CPU"
  local models=$pretrained/model
  [ -z "$cpu_model" ] || models=$models,$cpu_model
  [ -d target/oidn/lib ] && export NPRT_OIDN_DIR=${NPRT_OIDN_DIR:-$PWD/target/oidn/lib}
  "$nprt" eval --data "$work/data" --model "$models" --device cpu --out "$work/report"
  log "report in $work/report/report.md; add the row to docs/kitchen.md's table and commit $pretrained"
}

case "${1:-}" in
  prepare) shift; prepare "$@" ;;
  run) shift; run_visit "$@" ;;
  land) shift; land "$@" ;;
  -h | --help) usage ;;
  *) usage >&2; exit 2 ;;
esac
