#!/usr/bin/env bash
# One-time set-up of a fresh Debian/Ubuntu machine for this project: the software Vulkan driver
# (Mesa's lavapipe, so wgpu finds an adapter without a GPU) and a Rust toolchain. Idempotent.
set -euo pipefail

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    echo "setup: need root (or sudo) to run: $*" >&2; exit 1; fi
}

if ! ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; then
  echo "setup: installing the software Vulkan driver (mesa-vulkan-drivers)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
fi

if ! command -v cargo >/dev/null; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    export PATH="$HOME/.cargo/bin:$PATH"
  else
    echo "setup: installing Rust (rustup, from the distribution's packages)"
    if ! { as_root apt-get update -qq \
        && as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq rustup >/dev/null \
        && rustup default stable; }; then
      echo "setup: could not install Rust; install Rust 1.87 or newer with rustup (https://rustup.rs) and run again" >&2
      exit 1
    fi
  fi
fi

# wgpu prints a harmless warning without it.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
  export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/forest-xdg-$(id -u)"
  mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
fi
