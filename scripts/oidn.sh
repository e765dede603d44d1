#!/usr/bin/env bash
# Installs Intel Open Image Denoise for the denoised path-tracing baselines (idempotent): the
# `oidn` wheel on PyPI ships OIDN 1.4.3's shared libraries; they are unpacked into
# target/oidn/lib, where nprt looks (or wherever NPRT_OIDN_DIR points). Without them nprt runs
# and reports the denoised baselines as unavailable.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
lib="$root/target/oidn/lib"
if [ -e "$lib/libOpenImageDenoise.so.1.4.3" ] && [ -e "$lib/libtbb.so.12.5" ]; then
  exit 0
fi
wheels="$root/target/oidn/wheel"
mkdir -p "$wheels" "$lib"
echo "oidn: downloading the oidn 0.2.1 wheel (OIDN 1.4.3) into $wheels" >&2
pip=(python3 -m pip)
# The Mitsuba peer's venv has a pip even where the system Python ships none.
[ -x "$root/target/peer-venv/bin/pip" ] && pip=("$root/target/peer-venv/bin/pip")
"${pip[@]}" download -q --disable-pip-version-check --no-deps --only-binary=:all: \
  --platform manylinux1_x86_64 -d "$wheels" oidn==0.2.1 >&2
python3 - "$wheels" "$lib" <<'PY'
import pathlib, sys, zipfile
wheels, lib = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
wheel = next(wheels.glob("oidn-0.2.1-*.whl"))
with zipfile.ZipFile(wheel) as z:
    for name in z.namelist():
        if "/lib.linux.x64/" in name and not name.endswith("/"):
            target = lib / pathlib.Path(name).name
            tmp = target.with_suffix(".part")
            tmp.write_bytes(z.read(name))
            tmp.rename(target)
PY
echo "oidn: installed into $lib" >&2
