#!/usr/bin/env bash
# The KITCHEN on one device in one call: a dataset path traced on the device (`nprt generate
# --device`), D/S trained there for --minutes (`nprt train`), then `nprt eval` against the
# dataset's converged references beside equal-time path tracing (denoised by Open Image Denoise
# where scripts/oidn.sh installed it) and, with --cpu-model, the same design trained as long on
# the CPU; last, the paper's schedule (3000 views of 256² at 3200 spp, 500 epochs) projected
# from the rates measured here, data generation included. Each stage appends to DIR/summary.md
# as it ends, so a run cut short keeps what it measured.
#
# Budgets (the dataset; training is --minutes either way):
#   gpu  1000 training views of 128² at 64 spp, 32 test views of 128² at 1024 spp: for one GPU
#        loan of at most 8 minutes with the 5 minutes of training (the default with --device
#        gpu or wgpu);
#   cpu  400 training views of 64² at 64 spp, 16 test views of 64² at 256 spp (docs/kitchen.md):
#        about 12 minutes on 2 cores with 5 minutes of training (the default with --device cpu);
#   tiny 8 training views of 32² at 16 spp, 2 test views at 64 spp: to try the script (with
#        --minutes 0.2, a minute on lavapipe).
#
# usage: bench/kitchen.sh --out DIR [--device cpu|gpu|wgpu] [--budget cpu|gpu|tiny] [--minutes M]
#                         [--precision f16|f32] [--cpu-model MODEL] [--scene K/scene.xml]
#                         [--maps DIR] [--nprt BIN] [--no-eval] [--pause-by UNIX_TIME]
#                         [--data-hash FILE]
#   --out        the run's folder: data/, model/, report/ and summary.md (a dataset or model
#                already there is resumed, as nprt resumes them)
#   --device     where the views are traced and D/S trained (default cpu)
#   --precision  the transport networks' products on the GPU (default f16: its validation loss
#                was not worse than f32's, docs/model.md); f32 on the CPU
#   --cpu-model  a D/S model trained --minutes on the CPU on a dataset of the same settings
#                (this script with --device cpu), evaluated beside the device's
#   --scene      the KITCHEN (default ../shared/scenes/kitchen/scene.xml), its camera volume
#                docs/kitchen.camera.json
#   --maps       a folder of HDR maps, 3 held out for the test views (default ../shared/envmaps)
#   --nprt       the nprt binary (default target/release/nprt; build it with `--features gpu`
#                for --device gpu)
#   --no-eval    stop after training (bring the model back and evaluate it where OIDN is)
#   --pause-by   end this call's training by this time (seconds since 1970), saved, the run's
#                --minutes and schedule kept (`nprt train --pause-after`): how
#                bench/kitchen-visit.sh advances one long run a GPU loan at a time
#   --data-hash  the dataset's identity (SHA-256 of manifest.json) kept in FILE: written by the
#                first run; a later run whose dataset differs stops before training
set -euo pipefail
cd "$(dirname "$0")/.."

out=
device=cpu
budget=
minutes=5
precision=
cpu_model=
scene=../shared/scenes/kitchen/scene.xml
maps=../shared/envmaps
nprt=target/release/nprt
evaluate=1
pause_by=
data_hash=
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --device) device=$2; shift 2 ;;
    --budget) budget=$2; shift 2 ;;
    --minutes) minutes=$2; shift 2 ;;
    --precision) precision=$2; shift 2 ;;
    --cpu-model) cpu_model=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    --maps) maps=$2; shift 2 ;;
    --nprt) nprt=$2; shift 2 ;;
    --no-eval) evaluate=; shift ;;
    --pause-by) pause_by=$2; shift 2 ;;
    --data-hash) data_hash=$2; shift 2 ;;
    -h|--help) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench/kitchen.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || { echo "bench/kitchen.sh: give --out DIR (see --help)" >&2; exit 2; }
case "$device" in cpu|gpu|wgpu) ;; *) echo "bench/kitchen.sh: --device cpu, gpu or wgpu" >&2; exit 2 ;; esac
[ -n "$budget" ] || { [ "$device" = cpu ] && budget=cpu || budget=gpu; }
[ -n "$precision" ] || { [ "$device" = cpu ] && precision=f32 || precision=f16; }
case "$budget" in
  gpu) sizes=(--train-views 1000 --test-views 32 --train-res 128 --test-res 128 --spp 64 --test-spp 1024) ;;
  cpu) sizes=(--train-views 400 --test-views 16 --train-res 64 --test-res 64 --spp 64 --test-spp 256) ;;
  tiny) sizes=(--train-views 8 --test-views 2 --train-res 32 --test-res 32 --spp 16 --test-spp 64) ;;
  *) echo "bench/kitchen.sh: --budget cpu, gpu or tiny" >&2; exit 2 ;;
esac
for f in "$scene" "$nprt"; do
  [ -e "$f" ] || { echo "bench/kitchen.sh: '$f' is missing (see --help)" >&2; exit 2; }
done
[ -d "$maps" ] || { echo "bench/kitchen.sh: no maps folder '$maps'" >&2; exit 2; }
[ -z "$cpu_model" ] || [ -f "$cpu_model/model.json" ] ||
  { echo "bench/kitchen.sh: '$cpu_model' holds no model" >&2; exit 2; }

mkdir -p "$out"
summary=$out/summary.md
log() { echo "bench/kitchen.sh: $*" >&2; }
stage() { printf '\n## %s\n\n```\n' "$1" >>"$summary"; }
end_stage() { echo '```' >>"$summary"; }
{
  echo "# The KITCHEN on $device: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo
  echo "nprt $(git rev-parse --short HEAD 2>/dev/null || echo unknown); budget $budget (${sizes[*]});"
  echo "D/S trained $minutes minutes in $precision; $(nproc) CPU threads"
} >"$summary"

log "generating the dataset on $device"
stage "Data: nprt generate --device $device ${sizes[*]}"
t0=$SECONDS
"$nprt" generate --scene "$scene" --camera-volume docs/kitchen.camera.json --envmaps "$maps" \
  --test-maps 3 --out "$out/data" "${sizes[@]}" --device "$device" 2>&1 | tee "$out/generate.txt" |
  grep -E '^(dataset|rendered|warning)' >>"$summary"
echo "wall $((SECONDS - t0)) s" >>"$summary"
end_stage

if [ -n "$data_hash" ]; then
  hash=$(sha256sum "$out/data/manifest.json" | cut -d' ' -f1)
  if [ ! -s "$data_hash" ]; then
    echo "$hash" >"$data_hash"
  elif [ "$(cat "$data_hash")" != "$hash" ]; then
    echo "dataset manifest $hash differs from the $(cat "$data_hash") of '$data_hash': not trained" >>"$summary"
    log "the dataset is not the one '$data_hash' names; not training on it"
    exit 1
  fi
  echo "dataset manifest SHA-256 $hash" >>"$summary"
fi

# A pause leaves 40 s for the last validation and save before the time asked.
pause=()
if [ -n "$pause_by" ]; then
  left=$((pause_by - $(date +%s) - 40))
  [ "$left" -ge 30 ] || { log "no time left to train before --pause-by"; echo "no time left to train" >>"$summary"; exit 0; }
  pause=(--pause-after "$(awk -v s="$left" 'BEGIN { printf "%.2f", s / 60 }')")
fi
log "training D/S for $minutes minutes on $device ${pause[*]}"
stage "D/S: nprt train --minutes $minutes --device $device --precision $precision ${pause[*]}"
"$nprt" train --data "$out/data" --arch dsep --minutes "$minutes" --device "$device" \
  --precision "$precision" --checkpoint-minutes 1 "${pause[@]}" --out "$out/model" 2>&1 |
  tee "$out/train.txt" | grep -E '^(trained|time:|dataset|resumed|paused)' >>"$summary"
end_stage

# The paper's schedule from the rates above: its data (3000 views of 256² at 3200 spp) and its
# training (500 epochs over 3000 views of 256², every pixel counted as if in the foreground).
stage "The paper's schedule projected from these rates"
msps=$(sed -nE 's/.* ([0-9.]+) Msamples\/s.*/\1/p' "$out/generate.txt" | tail -n 1)
ksps=$(sed -nE 's/^trained .*\(([0-9.]+) K samples\/s\).*/\1/p' "$out/train.txt" | tail -n 1)
awk -v m="${msps:-0}" -v k="${ksps:-0}" 'BEGIN {
  if (m > 0) printf "data:     3000 views of 256² at 3200 spp at %s Msamples/s: %.1f h\n", m, 3000 * 65536 * 3200 / (m * 1e6) / 3600
  if (k > 0) printf "training: 500 epochs of 3000 views of 256² at %s K samples/s: %.1f h\n", k, 500 * 3000 * 65536 / (k * 1e3) / 3600
}' >>"$summary"
end_stage

if [ -n "$evaluate" ]; then
  models=$out/model
  [ -z "$cpu_model" ] || models=$models,$cpu_model
  log "evaluating"
  "$nprt" eval --data "$out/data" --model "$models" --device "$device" --out "$out/report" \
    >"$out/eval.txt" 2>&1 || { tail -n 20 "$out/eval.txt" >&2; exit 1; }
  printf '\n## nprt eval (the model trained on %s first)\n\n' "$device" >>"$summary"
  cat "$out/report/report.md" >>"$summary"
fi
log "summary in '$summary'"
