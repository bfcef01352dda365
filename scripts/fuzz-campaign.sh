#!/usr/bin/env bash
# One run of a fuzz campaign (the "no panic" issue's 10 M executions a target):
#
#   scripts/fuzz-campaign.sh TARGET RUNS CORPUS_DIR [LIBFUZZER_ARG...]
#
# scripts/fuzz.sh with no time limit and RUNS executions, its corpus kept in CORPUS_DIR (a later
# run goes on from it), extra arguments passed to libFuzzer (for example `-max_len=256` for a
# second run of the same target on another core); prints the commit and the time. A crash
# leaves its input in fuzz/artifacts/TARGET/ and exits non-zero.
set -euo pipefail
usage="usage: scripts/fuzz-campaign.sh TARGET RUNS CORPUS_DIR [LIBFUZZER_ARG...]"
target="${1:?$usage}" runs="${2:?$usage}" corpus="${3:?$usage}"
shift 3
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mkdir -p "$corpus"
corpus="$(cd "$corpus" && pwd)"
start=$(date +%s)
status=0
"$root/scripts/fuzz.sh" "$target" 0 "$corpus" -runs="$runs" "$@" || status=$?
echo "fuzz-campaign: $target at $(git -C "$root" rev-parse --short HEAD), $(($(date +%s) - start)) s, status $status"
exit "$status"
