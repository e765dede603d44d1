#!/usr/bin/env bash
# Side by side: `nprt bench train` and bench/train_pytorch.py (PyTorch 2.15 from PyPI, the
# same layers, batch, maps per batch and loss) on this machine's cores; prints samples/s of
# each design and the ratio. PyTorch goes into target/torch-venv on first use (about 5 GB,
# since PyPI's wheel carries CUDA libraries).
# For `--device gpu` (nprt's GPU kernels) build them in: NPRT_FEATURES=gpu bench/train_vs_pytorch.sh --device gpu
# usage: bench/train_vs_pytorch.sh [nprt bench train options, e.g. --steps 20 --arch prt]
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/torch-venv
if ! "$venv/bin/python" -c 'import torch' 2>/dev/null; then
  echo "bench: installing torch==2.15.0 into $venv" >&2
  python3 -m venv "$venv" >&2
  "$venv/bin/pip" install -q --disable-pip-version-check torch==2.15.0 >&2
fi
cargo build --release -q -p nprt ${NPRT_FEATURES:+--features "$NPRT_FEATURES"}
exec target/release/nprt bench train --python "$venv/bin/python" "$@"
