#!/usr/bin/env bash
# Everything CI checks, from a fresh machine: installs what the tests need (rustup targets,
# qemu-system-arm, qemu-system-misc for riscv32), then host tests, lints, MCU-target builds, the QEMU firmware run compared
# with the host rendering and the board firmware builds.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each step prints the seconds since the start: CI must stay under 30 minutes.
started=$SECONDS
step() { printf '\n==> [%ss] %s\n' "$((SECONDS - started))" "$*"; }
# A step that mostly waits on one core (a single-threaded link, QEMU, libFuzzer) runs beside
# another such: `background CMD...` starts it with its output kept, `finish` waits for it, then
# prints that output and stops the script if it failed.
background() {
  bg_log="$(mktemp)"
  "$@" >"$bg_log" 2>&1 &
  bg_pid=$!
}
finish() {
  local status=0
  wait "$bg_pid" || status=$?
  cat "$bg_log"
  rm -f "$bg_log"
  if [ "$status" -ne 0 ]; then
    echo "background step failed (status $status)" >&2
    exit "$status"
  fi
}

step "toolchain targets"
rustup target add thumbv6m-none-eabi thumbv7em-none-eabihf riscv32imc-unknown-none-elf
rustup component add clippy rustfmt >/dev/null 2>&1 || true

# qemu-system-arm for the firmware, qemu-system-misc (qemu-system-riscv32) for its riscv32imc
# build (scripts/qemu-check.sh, benches/mcu.sh); a C++ compiler for libFuzzer (cargo-fuzz's runtime).
missing=()
command -v qemu-system-arm >/dev/null || missing+=(qemu-system-arm)
command -v qemu-system-riscv32 >/dev/null || missing+=(qemu-system-misc)
command -v c++ >/dev/null || missing+=(g++)
if [ "${#missing[@]}" -gt 0 ]; then
  step "installing ${missing[*]}"
  if [ "$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

step "unsafe only in the span loop (src/pipeline/span/)"
if grep -rn --include='*.rs' -E '\bunsafe\b' src | grep -v '^src/pipeline/span/' | grep -v -E 'unsafe_code|// |//!|/// '; then
  echo "unsafe outside src/pipeline/span/" >&2
  exit 1
fi

step "format and lints"
cargo fmt --all -- --check
(cd fuzz && cargo fmt -- --check)
cargo clippy --all-targets -- -D warnings
cargo clippy --lib --features checked-spans -- -D warnings
# No function of the library or the CLI over 80 lines (clippy.toml), except where a comment
# gives the measurement that splitting it would cost.
cargo clippy --lib --bins --features cli,embedded-graphics -- -D warnings -W clippy::too_many_lines

step "API docs (no broken or private links)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --features convert,embedded-graphics

step "host tests"
# The golden pictures need ../shared/assets: here a missing folder fails instead of skipping.
export SOFT3D_REQUIRE_GOLDEN=1
cargo test

step "the span loop's checked twin draws the same pictures, bit for bit (golden hashes, firmware frames)"
cargo test --features checked-spans --test golden --test qemu_frame --test bands --test fill_rule

step "core library for the MCU targets (no_std, no alloc, default features)"
for t in thumbv6m-none-eabi thumbv7em-none-eabihf riscv32imc-unknown-none-elf; do
  cargo build --release --lib --target "$t"
done

# The demo, headless, with the host tests' build (the test profile is optimized, and
# `cargo test` already built the example): a release build of its own cost CI five minutes.
step "demo, headless"
cargo run --profile test --example simulator -- --headless --frames 4

step "short fuzz of every target (debug assertions on; installs cargo-fuzz)"
# All five built in one cargo run (their binaries link in parallel), then each run reuses it.
scripts/fuzz.sh --build-only
for target in parse babylon texture draw buffers; do
  echo "-- $target"
  # 6 s each: a smoke run (building the targets is most of this step) that keeps CI under 30
  # minutes; the campaigns are longer (scripts/fuzz-campaign.sh).
  scripts/fuzz.sh "$target" 6
done

boards=""
if [ -x scripts/build-boards.sh ]; then
  step "board firmware builds (RP2040, STM32F411), beside the QEMU firmware; their output after it"
  background scripts/build-boards.sh
  boards=1
fi

if [ -x scripts/qemu-check.sh ]; then
  step "QEMU firmware (Cortex-M4F, thumbv6m, riscv32imc) and the host comparison"
  scripts/qemu-check.sh
  # The host tests' (optimized) build: the host renders the same frame in every profile.
  SOFT3D_REQUIRE_QEMU=1 cargo test --test qemu_frame -- --nocapture
fi

if [ -n "$boards" ]; then
  step "board firmware builds: their output"
  finish
fi

# The MCU instruction counts are a benchmark, not a test: `benches/mcu.sh` (about 8 minutes,
# beside which CI would pass 30), run by hand for BENCHMARKS.md.
step "all checks passed"
