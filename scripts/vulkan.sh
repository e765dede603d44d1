#!/usr/bin/env bash
# Installs a software Vulkan device (idempotent): Mesa's lavapipe (Debian's mesa-vulkan-drivers)
# and the Vulkan loader, so that `--device wgpu` and the tests of the GPU code path run on a
# machine without a GPU. Needs apt as root; without it the wgpu tests skip themselves, except
# where NPRT_REQUIRE_VULKAN=1 (scripts/test sets it after this script succeeds).
set -euo pipefail
if [ -e /usr/share/vulkan/icd.d/lvp_icd.x86_64.json ] && ldconfig -p | grep -q 'libvulkan\.so\.1'; then
  exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then
  echo "vulkan: lavapipe is missing and apt (as root) is not available to install it" >&2
  exit 1
fi
echo "vulkan: installing Debian's mesa-vulkan-drivers (lavapipe) and libvulkan1" >&2
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  mesa-vulkan-drivers libvulkan1) >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
