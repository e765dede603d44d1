#!/usr/bin/env bash
# Two builds of nprt's GPU kernels timed side by side on one GPU, so that one short loan measures
# a kernel change: A (the kernels before it) and B (after it) run alternately, A then B in even
# rounds and B then A in odd ones, so that a drift in the card's speed (clocks, heat) reaches
# both alike; the medians are compared, and the range of the rounds' B/A shows the noise.
#
#   bench/gpu-ab.sh build REV FILE
#       here: nprt at commit REV (checked out in a temporary git worktree), built in release
#       with the GPU kernels (`--features gpu`) and stripped into FILE, its commit in
#       FILE.commit. bench/kitchen-visit.sh prepare builds the A side of a visit this way
#       (its --ab-base REV, with a default the script names).
#   bench/gpu-ab.sh run A B [--arch LIST] [--precision LIST] [--batch-size LIST]
#                          [--rounds N] [--steps N] [--device D] [--frames LIST] [--profile]
#       on the GPU machine: `nprt bench train` of each design, precision and batch size (comma-
#       separated lists; default dsep, f16 and 16384,262144) by the binaries A and B, one run
#       each per round (default 3 rounds of 10 timed steps, --device gpu); prints a Markdown
#       table of A's and B's median samples/s, B/A and the rounds' B/A. With --frames (frame
#       sizes, e.g. 512,1920x1080), also `nprt bench frame` of each design and precision at each
#       size, alternated the same way: a table of the medians of a new viewpoint left on the
#       device (ms, 10 frames a run). With --profile, one profiled step of each after, A's
#       kernels then B's (`nprt bench train --profile`).
set -euo pipefail
cd "$(dirname "$0")/.."
log() { echo "bench/gpu-ab.sh: $*" >&2; }
die() { log "$*"; exit 1; }
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }

build() {
  [ $# -eq 2 ] || die "build takes REV and FILE (--help explains them)"
  local rev=$1 file=$2
  local commit
  commit=$(git rev-parse --short --verify "$rev^{commit}") || die "'$rev' names no commit"
  local tree
  tree=$(mktemp -d "${TMPDIR:-/tmp}/nprt-ab.XXXXXX")
  trap 'git worktree remove --force "$tree" 2>/dev/null || rm -rf "$tree"; rm -rf "$tree-target"' RETURN
  git worktree add --quiet --detach "$tree" "$commit"
  log "building nprt at $commit"
  # A copy of this tree's release build, so that only the workspace's crates are built again
  # (a build of its own from nothing takes a 2-core machine about ten minutes).
  mkdir -p "$tree-target"
  [ ! -d target/release ] || cp -a target/release "$tree-target/"
  (cd "$tree" && CARGO_TARGET_DIR="$tree-target" cargo build --quiet --release -p nprt --features gpu)
  mkdir -p "$(dirname "$file")"
  strip -o "$file" "$tree-target/release/nprt"
  echo "$commit" >"$file.commit"
  log "A side: $file ($commit)"
}

# The median of the numbers on stdin, one per line (the upper one of an even count).
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int(NR / 2) + 1] }'; }

# `nprt bench train`'s samples/s of binary $1 for design $2, precision $3 and batch size $4.
train_rate() {
  local out rate
  out=$("$1" bench train --arch "$2" --precision "$3" --batch-size "$4" \
    --steps "$steps" --rounds 1 --device "$device" 2>&1) ||
    die "$1 failed on $2 $3 $4: $(tail -n 3 <<<"$out")"
  rate=$(awk -v a="$2" -v p="$3" '$1 == a && $3 == p { print $4 }' <<<"$out")
  [ -n "$rate" ] || die "$1 printed no rate for $2 $3: $(tail -n 3 <<<"$out")"
  echo "$rate"
}

# `nprt bench frame`'s new viewpoint left on the device (ms) of binary $1 for design $2,
# precision $3 and frame size $4.
viewpoint_ms() {
  local out ms
  out=$("$1" bench frame --arch "$2" --precision "$3" --res "$4" --direct-spp 0 --repeats 10 \
    --device "$device" 2>&1) || die "$1 failed on a $4 $2 $3 frame: $(tail -n 3 <<<"$out")"
  ms=$(sed -n 's/.*a new viewpoint \([0-9.]*\) ms.*/\1/p' <<<"$out" | head -n 1)
  [ -n "$ms" ] || die "$1 printed no new viewpoint's time for $2 $3 $4: $(tail -n 3 <<<"$out")"
  echo "$ms"
}

# Runs MEASURE ARGS... ROUNDS times by A and by B, A first in even rounds and B first in odd
# ones; prints A's median, B's median and the range of the rounds' B/A.
alternate() {
  local rounds=$1 a=$2 b=$3 measure=$4
  shift 4
  local values_a=() values_b=() r side
  for ((r = 0; r < rounds; r++)); do
    for side in $([ $((r % 2)) -eq 0 ] && echo "A B" || echo "B A"); do
      if [ "$side" = A ]; then
        values_a+=("$("$measure" "$a" "$@")")
      else
        values_b+=("$("$measure" "$b" "$@")")
      fi
    done
  done
  local ratios
  ratios=$(paste <(printf '%s\n' "${values_a[@]}") <(printf '%s\n' "${values_b[@]}") |
    awk '{ r = $2 / $1; lo = (NR == 1 || r < lo) ? r : lo; hi = (NR == 1 || r > hi) ? r : hi }
         END { printf "%.2f–%.2f×", lo, hi }')
  echo "$(printf '%s\n' "${values_a[@]}" | median) $(printf '%s\n' "${values_b[@]}" | median) $ratios"
}

# A Markdown table of MEASURE by A and B for each design, precision and size in SIZES (a
# comma-separated list): the size's column is SIZE_NAME, the values' VALUE_NAME, each printed
# with FORMAT. Reads run_ab's a, b, rounds, archs and precisions.
ab_table() {
  local measure=$1 sizes=$2 size_name=$3 value_name=$4 format=$5
  echo "| design | precision | $size_name | A $value_name | B $value_name | B/A | rounds' B/A |"
  echo "|---|---|---|---:|---:|---:|---|"
  local arch precision size
  for arch in ${archs//,/ }; do
    for precision in ${precisions//,/ }; do
      for size in ${sizes//,/ }; do
        alternate "$rounds" "$a" "$b" "$measure" "$arch" "$precision" "$size" |
          awk -v arch="$arch" -v p="$precision" -v n="$size" -v f="$format" \
            '{ printf "| %s | %s | %s | " f " | " f " | %.2f× | %s |\n", arch, p, n, $1, $2, $2 / $1, $3 }'
      done
    done
  done
}

run_ab() {
  [ $# -ge 2 ] || die "run takes the binaries A and B (--help explains them)"
  local a=$1 b=$2
  shift 2
  local archs=dsep precisions=f16 batches=16384,262144 rounds=3 steps=10 device=gpu profile=
  local frames=
  while [ $# -gt 0 ]; do
    case "$1" in
      --arch) archs=$2; shift 2 ;;
      --precision) precisions=$2; shift 2 ;;
      --batch-size) batches=$2; shift 2 ;;
      --rounds) rounds=$2; shift 2 ;;
      --steps) steps=$2; shift 2 ;;
      --device) device=$2; shift 2 ;;
      --frames) frames=$2; shift 2 ;;
      --profile) profile=1; shift ;;
      *) die "unknown argument '$1' (--help lists them)" ;;
    esac
  done
  [ -x "$a" ] || die "A, '$a', is not an executable nprt"
  [ -x "$b" ] || die "B, '$b', is not an executable nprt"
  [[ $rounds =~ ^[1-9][0-9]*$ ]] || die "--rounds must be a positive count, not '$rounds'"
  source bench/gpu-vulkan.sh
  use_prepared_vulkan "$(dirname "$b")/lib"
  local name_a name_b
  name_a=$(cat "$a.commit" 2>/dev/null || echo "$a")
  name_b=$(cat "$b.commit" 2>/dev/null || echo "$b")
  echo "A: nprt $name_a; B: nprt $name_b; $rounds rounds of $steps steps, --device $device"
  echo
  ab_table train_rate "$batches" batch samples/s %.0f
  if [ -n "$frames" ]; then
    echo
    ab_table viewpoint_ms "$frames" size "new viewpoint ms" %.2f
  fi
  if [ -n "$profile" ]; then
    for side in A B; do
      local bin=$a
      [ "$side" = B ] && bin=$b
      printf '\n%s, one profiled step of each:\n\n```\n' "$side"
      for arch in ${archs//,/ }; do
        "$bin" bench train --arch "$arch" --precision "$precisions" \
          --batch-size "${batches%%,*}" --steps 2 --rounds 1 --device "$device" --profile 2>&1 |
          sed -n '/^design/,$p'
      done
      echo '```'
    done
  fi
}

case "${1:-}" in
  build) shift; build "$@" ;;
  run) shift; run_ab "$@" ;;
  -h | --help) usage ;;
  *) usage >&2; exit 2 ;;
esac
