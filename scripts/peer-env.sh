# Sourced by scripts/test and bench/*: installs the Mitsuba 3 peer (idempotent) and exports
#   NPRT_PYTHON           a Python with mitsuba 3.9.1
#   NPRT_MITSUBA_VARIANT  llvm_ad_rgb when Debian's libLLVM 19 is available, else scalar_rgb
#   DRJIT_LIBLLVM_PATH    for the llvm variant (Debian's default LLVM 15 does not work)
# Needs only Python 3.11 and, for the faster variant, apt (as root).
peer_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
peer_venv="$peer_root/target/peer-venv"
llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ ! -e "$llvm" ] && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
  echo "peer: installing Debian's libllvm19 for Mitsuba's llvm variant" >&2
  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19) >&2 \
    || echo "peer: libllvm19 unavailable; Mitsuba falls back to scalar_rgb" >&2
fi
if ! "$peer_venv/bin/python" -c 'import mitsuba' 2>/dev/null; then
  echo "peer: installing mitsuba==3.9.1 into $peer_venv" >&2
  python3 -m venv "$peer_venv" >&2
  "$peer_venv/bin/pip" install -q --disable-pip-version-check mitsuba==3.9.1 numpy >&2
fi
export NPRT_PYTHON="$peer_venv/bin/python"
if [ -e "$llvm" ]; then
  export DRJIT_LIBLLVM_PATH="$llvm" NPRT_MITSUBA_VARIANT="${NPRT_MITSUBA_VARIANT:-llvm_ad_rgb}"
else
  export NPRT_MITSUBA_VARIANT="${NPRT_MITSUBA_VARIANT:-scalar_rgb}"
fi
