#!/usr/bin/env bash
# Installs Debian's Chromium (idempotent), which runs WebGPU headless on its bundled SwiftShader:
# the test of the WebGPU example that `nprt export` writes loads it there. Needs apt as root;
# without it that test skips itself, except where NPRT_REQUIRE_CHROMIUM=1 (scripts/test sets it
# after this script succeeds).
set -euo pipefail
if command -v chromium >/dev/null; then
  exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then
  echo "chromium: Chromium is missing and apt (as root) is not available to install it" >&2
  exit 1
fi
echo "chromium: installing Debian's chromium" >&2
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  chromium) >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
