#!/usr/bin/env bash
# One firmware configuration's profile, quicker than benches/mcu.sh (which measures every target
# and view): builds examples/qemu for 1 and 2 frames, counts the instructions executed at each
# address (benches/qemu-pcprof) and prints the frame's count, the stage table of
# benches/mcu-profile.py and the firmware's JSON line.
#
#   benches/profile.sh [--target TRIPLE] [--bands 1|8] [--features F,...] [--keep DIR]
#                      [--by-function STAGE [DEPTH]] [--instructions FUNCTION MIN MAX]
#
# --target: thumbv7em-none-eabihf (default, mps2-an386's Cortex-M4F) or thumbv6m-none-eabi
# (run on mps2-an385's Cortex-M3); --bands: 1 (default) or 8; --features: the firmware's other
# features (view-far, view-near, checked-spans); --keep: leave the ELFs and per-address counts
# in DIR (to read with llvm-objdump beside them); --by-function: also where the stages whose
# name contains STAGE go, by function at inlining depth DEPTH (default -1, the outermost: see
# benches/mcu-profile.py); --instructions: also every instruction of the functions whose name
# contains FUNCTION run MIN..MAX-1 times a frame, with its source line (for example `fragments
# 600 700` around Suzanne's 634 drawn triangles: what runs once a triangle). Needs what
# benches/mcu.sh needs, with python3, llvm-objdump and llvm-addr2line.
set -euo pipefail
root="$(git -C "$(dirname "${BASH_SOURCE[0]}")" rev-parse --show-toplevel)"
target=thumbv7em-none-eabihf bands=1 features="" keep="" split="" depth=-1 listing=()
while [ $# -gt 0 ]; do
    case "$1" in
        --target) target="$2"; shift 2 ;;
        --bands) bands="$2"; shift 2 ;;
        --features) features="$2"; shift 2 ;;
        --keep) keep="$2"; shift 2 ;;
        --by-function)
            split="$2"; shift 2
            if [ $# -gt 0 ] && [[ "$1" =~ ^-?[0-9]+$ ]]; then depth="$1"; shift; fi ;;
        --instructions) listing=("$2" "$3" "$4"); shift 4 ;;
        *) echo "profile: unknown argument $1" >&2; exit 2 ;;
    esac
done
case "$target" in
    thumbv7em-none-eabihf) machine=mps2-an386 cpu=cortex-m4 ;;
    thumbv6m-none-eabi) machine=mps2-an385 cpu=cortex-m3 ;;
    *) echo "profile: targets are thumbv7em-none-eabihf and thumbv6m-none-eabi" >&2; exit 2 ;;
esac
work="${keep:-$(mktemp -d)}"
[ -n "$keep" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work/out"
gcc -O2 -shared -fPIC -o "$work/libinsncount.so" "$root/../shared/tools/qemu-insncount/insncount.c"
gcc -O2 -shared -fPIC -o "$work/libpcprof.so" "$root/benches/qemu-pcprof/pcprof.c"
base=""
[ "$bands" = 1 ] && base="one-band"
[ -n "$features" ] && base="${base:+$base,}$features"
for frames in 1 2; do
    f="$base"
    [ "$frames" = 2 ] && f="${f:+$f,}two-frames"
    (cd "$root/examples/qemu" && cargo build --release --quiet --target "$target" ${f:+--features "$f"})
    cp "$root/examples/qemu/target/$target/release/soft3d-qemu" "$work/fw-$frames.elf"
    (cd "$work" && PCPROF_OUT="$work/pc-$frames.txt" timeout 300 qemu-system-arm -machine "$machine" -cpu "$cpu" \
        -nographic -monitor none -serial none -semihosting-config enable=on,target=native -icount shift=0 \
        -kernel "$work/fw-$frames.elf" -plugin "$work/libinsncount.so" -plugin "$work/libpcprof.so" -d plugin \
        -D "$work/log-$frames.txt" >"$work/json-$frames.txt")
done
insns() { sed -n 's/^insns: *\([0-9]*\).*/\1/p' "$1" | tail -n 1; }
json="$(cat "$work/json-1.txt")"
field() { sed -n "s/.*\"$1\":\([0-9]*\).*/\1/p" <<<"$json"; }
echo "$target, $bands band(s)${features:+, $features}: $(($(insns "$work/log-2.txt") - $(insns "$work/log-1.txt"))) instructions a frame"
echo
python3 "$root/benches/mcu-profile.py" "$work/fw-1.elf" "$work/pc-1.txt" "$work/fw-2.elf" "$work/pc-2.txt" \
    "$(field covered)" "$(field pixels_written)" "$(field runs)" "$(field drawn)"
if [ -n "$split" ]; then
    echo
    python3 "$root/benches/mcu-profile.py" --by-function "$split" "$depth" \
        "$work/fw-1.elf" "$work/pc-1.txt" "$work/fw-2.elf" "$work/pc-2.txt"
fi
if [ ${#listing[@]} -gt 0 ]; then
    echo
    python3 "$root/benches/mcu-profile.py" --instructions "${listing[@]}" \
        "$work/fw-1.elf" "$work/pc-1.txt" "$work/fw-2.elf" "$work/pc-2.txt"
fi
echo
echo "$json"
