#!/usr/bin/env bash
# Two builds of nprt's GPU kernels timed side by side on one GPU, so that one short loan measures
# a kernel change: A (the kernels before it) and B (after it) run alternately, A then B in even
# rounds and B then A in odd ones, so that a drift in the card's speed (clocks, heat) reaches
# both alike; the medians are compared, and the range of the rounds' B/A shows the noise.
#
#   bench/gpu-ab.sh build REV FILE
#       here: nprt at commit REV (checked out in a temporary git worktree), built in release
#       with the GPU kernels (`--features gpu`) and stripped into FILE, its commit in
#       FILE.commit. bench/kitchen-visit.sh prepare builds the A side of a visit this way from
#       pretrained/kitchen-dsep/ab-base.
#   bench/gpu-ab.sh run A B [--arch LIST] [--precision LIST] [--batch-size LIST]
#                          [--rounds N] [--steps N] [--device D] [--profile]
#       on the GPU machine: `nprt bench train` of each design, precision and batch size (comma-
#       separated lists; default dsep, f16 and 16384,262144) by the binaries A and B, one run
#       each per round (default 3 rounds of 10 timed steps, --device gpu); prints a Markdown
#       table of A's and B's median samples/s, B/A and the rounds' B/A. With --profile, one
#       profiled step of each after, A's kernels then B's (`nprt bench train --profile`).
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

run_ab() {
  [ $# -ge 2 ] || die "run takes the binaries A and B (--help explains them)"
  local a=$1 b=$2
  shift 2
  local archs=dsep precisions=f16 batches=16384,262144 rounds=3 steps=10 device=gpu profile=
  while [ $# -gt 0 ]; do
    case "$1" in
      --arch) archs=$2; shift 2 ;;
      --precision) precisions=$2; shift 2 ;;
      --batch-size) batches=$2; shift 2 ;;
      --rounds) rounds=$2; shift 2 ;;
      --steps) steps=$2; shift 2 ;;
      --device) device=$2; shift 2 ;;
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
  echo "| design | precision | batch | A samples/s | B samples/s | B/A | rounds' B/A |"
  echo "|---|---|---|---:|---:|---:|---|"
  local arch precision batch
  for arch in ${archs//,/ }; do
    for precision in ${precisions//,/ }; do
      for batch in ${batches//,/ }; do
        local rates_a=() rates_b=() r side
        for ((r = 0; r < rounds; r++)); do
          for side in $([ $((r % 2)) -eq 0 ] && echo "A B" || echo "B A"); do
            local bin=$a
            [ "$side" = B ] && bin=$b
            local out rate
            out=$("$bin" bench train --arch "$arch" --precision "$precision" --batch-size "$batch" \
              --steps "$steps" --rounds 1 --device "$device" 2>&1) ||
              die "$side ($bin) failed on $arch $precision $batch: $(tail -n 3 <<<"$out")"
            rate=$(awk -v a="$arch" -v p="$precision" '$1 == a && $3 == p { print $4 }' <<<"$out")
            [ -n "$rate" ] || die "$side ($bin) printed no rate for $arch $precision: $(tail -n 3 <<<"$out")"
            if [ "$side" = A ]; then rates_a+=("$rate"); else rates_b+=("$rate"); fi
          done
        done
        local med_a med_b ratios
        med_a=$(printf '%s\n' "${rates_a[@]}" | median)
        med_b=$(printf '%s\n' "${rates_b[@]}" | median)
        ratios=$(paste <(printf '%s\n' "${rates_a[@]}") <(printf '%s\n' "${rates_b[@]}") |
          awk '{ r = $2 / $1; lo = (NR == 1 || r < lo) ? r : lo; hi = (NR == 1 || r > hi) ? r : hi }
               END { printf "%.2f–%.2f×", lo, hi }')
        awk -v arch="$arch" -v p="$precision" -v n="$batch" -v a="$med_a" -v b="$med_b" -v rr="$ratios" \
          'BEGIN { printf "| %s | %s | %d | %.0f | %.0f | %.2f× | %s |\n", arch, p, n, a, b, b / a, rr }'
      done
    done
  done
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
