#!/usr/bin/env bash
# Host speed-up of `soft3d render --threads N` (issue 16): renders each scene REPEAT times per
# thread count and band count and prints the median of the CLI's own frame time (--stats json:
# the render alone, not loading or converting). A benchmark, not a test: wall-clock times move
# with the machine's load.
#
#   benches/threads.sh [REPEAT]   (default 15)
set -euo pipefail
root="$(git -C "$(dirname "${BASH_SOURCE[0]}")" rev-parse --show-toplevel)"
repeat="${1:-15}"
cargo build --release --quiet --features cli --manifest-path "$root/Cargo.toml"
bin="$root/target/release/soft3d"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
assets="$root/../shared/assets"
scenes=(
    "suzanne 1536x1152|$assets/suzanne/monkey.babylon|--uv-origin top --size 1536x1152"
    "teapot Phong 1536x1152|$assets/teapot/teapot.babylon|--shading phong --size 1536x1152"
    "tree 1536x1152|$assets/tree/$(ls "$assets/tree" | grep -m1 '\.babylon$')|--size 1536x1152"
)
echo "machine: $(nproc) CPUs, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| scene | threads | bands | median ms | speed-up |"
echo "| --- | ---: | ---: | ---: | ---: |"
for entry in "${scenes[@]}"; do
    IFS='|' read -r name file args <<<"$entry"
    base=""
    for config in "1 1" "1 8" "2 2" "2 8" "2 16" "4 16"; do
        read -r threads bands <<<"$config"
        times=()
        for _ in $(seq "$repeat"); do
            # shellcheck disable=SC2086
            t="$("$bin" render "$file" -o "$work/out.png" $args --threads "$threads" --bands "$bands" --stats json 2>/dev/null |
                sed -n 's/.*"ms":\([0-9.e+-]*\).*/\1/p')"
            times+=("$t")
        done
        median="$(printf '%s\n' "${times[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')"
        [ -n "$base" ] || base="$median"
        echo "| $name | $threads | $bands | $(printf '%.2f' "$median") | $(awk -v b="$base" -v m="$median" 'BEGIN {printf "%.2f", b / m}') |"
    done
done
