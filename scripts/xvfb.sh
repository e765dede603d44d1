#!/usr/bin/env bash
# Installs Xvfb (idempotent), a virtual X server: the test of `nprt view` opens its window there
# and renders through Mesa's software Vulkan. Needs apt as root; without it that test skips
# itself, except where NPRT_REQUIRE_XVFB=1 (scripts/test sets it after this script succeeds).
set -euo pipefail
if command -v Xvfb >/dev/null && ldconfig -p | grep -q 'libX11\.so\.6' && ldconfig -p | grep -q 'libxkbcommon-x11\.so\.0'; then
  exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then
  echo "xvfb: Xvfb is missing and apt (as root) is not available to install it" >&2
  exit 1
fi
echo "xvfb: installing Debian's xvfb, libx11-xcb1 and libxkbcommon-x11-0" >&2
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  xvfb libx11-6 libx11-xcb1 libxcursor1 libxi6 libxrandr2 libxkbcommon-x11-0) >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
