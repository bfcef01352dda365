#!/usr/bin/env bash
# One run of a fuzz campaign (the "no panic" issue's 10 M executions a target):
#
#   scripts/fuzz-campaign.sh TARGET RUNS CORPUS_DIR [LIBFUZZER_ARG...]
#
# Runs fuzz target TARGET (see scripts/fuzz.sh) for RUNS executions, debug assertions on, with
# its corpus in CORPUS_DIR (kept: a later run goes on from it) and the seeds of fuzz/seeds/TARGET,
# then prints the commit, the executions and the time. Extra arguments go to libFuzzer (for
# example `-max_len=256` for a second run of the same target on another core). Exits non-zero on
# a crash, whose input is then in fuzz/artifacts/TARGET/ (make it a regression test).
set -euo pipefail
usage="usage: scripts/fuzz-campaign.sh TARGET RUNS CORPUS_DIR [LIBFUZZER_ARG...]"
target="${1:?$usage}" runs="${2:?$usage}" corpus="${3:?$usage}"
shift 3
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mkdir -p "$corpus"
corpus="$(cd "$corpus" && pwd)"
cd "$root/fuzz"
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "fuzz-campaign: installing cargo-fuzz" >&2
    cargo install --locked cargo-fuzz >&2
fi
seeds=()
[ -d "seeds/$target" ] && seeds=("seeds/$target")
log="$(mktemp)"
start=$(date +%s)
status=0
cargo fuzz run -s none --debug-assertions "$target" "$corpus" ${seeds[@]+"${seeds[@]}"} -- \
    -runs="$runs" "$@" -rss_limit_mb=4096 -timeout=20 -print_final_stats=1 >"$log" 2>&1 || status=$?
executed=$(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}' || true)
echo "fuzz-campaign: $target at $(git -C "$root" rev-parse --short HEAD): ${executed:-?} executions in $(($(date +%s) - start)) s, status $status"
if [ "$status" -ne 0 ]; then
    tail -n 60 "$log"
    echo "fuzz-campaign: $target FAILED: the input is in fuzz/artifacts/$target/" >&2
fi
rm -f "$log"
exit "$status"
