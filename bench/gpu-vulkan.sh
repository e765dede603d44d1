# Sourced by the GPU bench scripts (bench/gpu.sh, bench/kitchen-visit.sh, bench/gpu-ab.sh):
# `use_prepared_vulkan DIR` makes the Vulkan loader that bench/gpu-prepare.sh put in DIR the one
# nprt loads where the machine has none, and the NVIDIA driver's ICD the one the loader reads
# where the loader's own folders list none (a loan's image has the driver but neither).
use_prepared_vulkan() {
  if ! ldconfig -p | grep -q 'libvulkan\.so\.1' && [ -f "$1/libvulkan.so.1" ]; then
    LD_LIBRARY_PATH=$(realpath "$1")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    export LD_LIBRARY_PATH
  fi
  local icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$icd" ] &&
    ! ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json >/dev/null 2>&1; then
    export VK_DRIVER_FILES=$icd
  fi
}
