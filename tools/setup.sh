#!/usr/bin/env bash
# Installs what dermis needs on Debian 12 that a fresh machine lacks: the GLSL
# compiler, the Vulkan loader, lavapipe (the CPU Vulkan driver the tests run
# on), the Khronos validation layer and g++ (meshoptimizer, the levels of
# detail's simplifier, is C++ built by its crate). Idempotent: installed packages are skipped.
set -euo pipefail
packages=(glslang-tools mesa-vulkan-drivers libvulkan1 vulkan-validationlayers fonts-dejavu-core g++)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" >/dev/null
fi
if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: cargo not found; install a Rust toolchain (stable, 1.85 or newer) with rustup" >&2
  exit 1
fi
# The test command lints with clippy: rustup's default profile ships it.
if ! cargo clippy --version >/dev/null 2>&1; then
  echo "setup: clippy not found; adding it (rustup component add clippy)"
  rustup component add clippy
fi
