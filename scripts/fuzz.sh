#!/usr/bin/env bash
# Runs one fuzz target for a while: scripts/fuzz.sh TARGET SECONDS [CORPUS_DIR [LIBFUZZER_ARG...]]
# (or builds them all: scripts/fuzz.sh --build-only)
# (SECONDS 0: no time limit, for runs bounded by `-runs=N`, see scripts/fuzz-campaign.sh)
#
# Targets (fuzz/fuzz_targets): parse (.s3d bytes, then every accessor and a small draw),
# texture (every image decoder, on a texture embedded in a .babylon),
# babylon (the .babylon reader and the .s3d writer), draw (a seed model drawn with arbitrary
# cameras, transforms, options, lights, bands, pixel and depth formats and scratch sizes),
# buffers (every entry point given memory of the wrong size). Built with debug assertions
# (overflow is a crash, and the span loop's debug_assert!s check the bounds its unsafe blocks
# skip) and no sanitizer (`-s none`: outside src/pipeline/span/ the crate is safe code),
# which works on the stable toolchain. Seeds come from fuzz/seeds/TARGET when it exists; the corpus grows in
# CORPUS_DIR (default: a temporary folder). A crash leaves its input in fuzz/artifacts/TARGET/
# and exits non-zero: make it a regression test (tests/regressions.rs).
# Installs cargo-fuzz when it is missing.
set -euo pipefail
target="${1:?usage: scripts/fuzz.sh TARGET SECONDS [CORPUS_DIR]}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root/fuzz"

if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "fuzz: installing cargo-fuzz" >&2
    cargo install --locked cargo-fuzz >&2
fi

# --build-only: builds every target with the flags below and stops (CI builds them at once).
if [ "$target" = "--build-only" ]; then
    exec cargo fuzz build -s none --debug-assertions
fi

seconds="${2:?usage: scripts/fuzz.sh TARGET SECONDS [CORPUS_DIR]}"
corpus="${3:-}"
shift $(($# < 3 ? $# : 3))
if [ -z "$corpus" ]; then
    corpus="$(mktemp -d)"
    trap 'rm -rf "$corpus"' EXIT
fi
mkdir -p "$corpus"
seeds=()
[ -d "seeds/$target" ] && seeds=("seeds/$target")

log="$(mktemp)"
status=0
cargo fuzz run -s none --debug-assertions "$target" "$corpus" ${seeds[@]+"${seeds[@]}"} -- \
    -max_total_time="$seconds" "$@" -rss_limit_mb=4096 -timeout=20 -print_final_stats=1 >"$log" 2>&1 || status=$?
grep -E '^(Done|stat::number_of_executed_units)' "$log" || true
if [ "$status" -ne 0 ]; then
    tail -n 60 "$log"
    echo "fuzz: $target FAILED (status $status): the input is in fuzz/artifacts/$target/" >&2
fi
rm -f "$log"
exit "$status"
