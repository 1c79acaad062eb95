#!/usr/bin/env bash
# The Rust house rules: formatting, and clippy with warnings as errors on every target, with
# and without the Python bindings, and for arm64. Run by .ci/run beside the core's build (in a
# target directory of its own, so that neither waits for the other's lock).
set -euo pipefail
cd "$(dirname "$0")/.."

cargo fmt --check
cargo clippy --all-targets -- -D warnings
cargo clippy --features python -- -D warnings
# The core builds for arm64 too (one wheel per platform; the x86-64 instruction-set
# dispatch is behind cfg, and a slip there once went unnoticed): its lints for that target.
rustup target add aarch64-unknown-linux-gnu
cargo clippy --target aarch64-unknown-linux-gnu --all-targets -- -D warnings
echo "rust-lints: fmt and the three clippy runs are clean"
