#!/usr/bin/env bash
# Side by side: `nprt reference` and Mitsuba 3 (llvm_ad_rgb and scalar_rgb) render the same
# scene files at equal spp, resolution and max_depth; prints samples/s and ratios.
# usage: bench/reference_vs_mitsuba.sh [--res N] [--spp N] [--runs N] [SCENE.xml ...]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/peer-env.sh
cargo build --release -q -p nprt
exec "$NPRT_PYTHON" bench/reference_vs_mitsuba.py "$@"
