#!/usr/bin/env bash
# All tests: formatting, lints, and the whole test suite (GPU tests run on lavapipe).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# The viewer's window test drives a real window under a virtual X server.
if ! command -v Xvfb >/dev/null || ! command -v xdotool >/dev/null; then
  echo "test: installing Xvfb and xdotool (the viewer's window test)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq xvfb xdotool >/dev/null
fi

rustup component add rustfmt clippy >/dev/null 2>&1 || true
cargo fmt --all -- --check
cargo clippy --locked --workspace --all-targets -- -D warnings
# API documentation builds without a warning (broken links included); missing_docs is denied
# in every library crate's lib.rs.
RUSTDOCFLAGS="-D warnings" cargo doc --locked --workspace --no-deps
cargo test --locked --workspace

# The Bevy plugin lives in its own workspace with its own lock (integrations/forest-bevy):
# Bevy 0.20 declares Rust 1.97.1 and builds on this toolchain with --ignore-rust-version.
# Its first build is a large share of this script's time (see docs/bevy.md).
(
  cd integrations/forest-bevy
  start=$SECONDS
  cargo fmt -- --check
  cargo clippy --locked --ignore-rust-version --all-targets -- -D warnings
  RUSTDOCFLAGS="-D warnings" cargo doc --locked --ignore-rust-version --no-deps
  cargo test --locked --ignore-rust-version
  echo "test: forest-bevy checked, built and tested in $((SECONDS - start)) s;" \
    "its target: $(du -sh target | cut -f1)"
)
