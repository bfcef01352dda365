#!/usr/bin/env bash
# The peer comparison: TGX (github.com/vindar/tgx at $commit) drawing soft3d's reference
# Suzanne frame as bare-metal firmware on QEMU mps2-an386 (Cortex-M4F); prints the instructions
# a frame (2-frame run minus 1-frame run) and the profile by stage. See README.md here.
#
#   benches/tgx/run.sh [-O2|-O3]        (default -O2)
#
# TGX: $TGX_SRC if set (a checkout of that commit: src/, tools/), else cloned into
# benches/tgx/work/tgx. Everything it writes is under benches/tgx/work/ (git-ignored);
# the results of one level in work/O2/ (or work/O3/).
set -euo pipefail
commit=d43f88906ab87f877ea249af2232896b097f15a7
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$here/work"
opt="${1:--O2}"
case "$opt" in -O2|-O3) ;; *) echo "tgx: usage: $0 [-O2|-O3]" >&2; exit 2 ;; esac
arm="apt-get install -y --no-install-recommends gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib"
need() { command -v "$1" >/dev/null || { echo "tgx: $1 not found (install: $2)" >&2; exit 1; }; }
need arm-none-eabi-g++ "$arm"
need arm-none-eabi-objdump "$arm"
need qemu-system-arm "apt-get install -y --no-install-recommends qemu-system-arm"
need llvm-addr2line "apt-get install -y --no-install-recommends llvm"
need gcc "apt-get install -y gcc"
need python3 "apt-get install -y python3"
need cargo "rustup, https://rustup.rs"
if ! arm-none-eabi-g++ -mcpu=cortex-m4 -mthumb -x c++ -fsyntax-only - <<<'#include <cmath>' 2>/dev/null; then
    echo "tgx: arm-none-eabi-g++ has no C++ library headers (install: $arm)" >&2
    exit 1
fi
mkdir -p "$work"

# TGX's source, at the pinned commit.
if [ -n "${TGX_SRC:-}" ]; then
    tgx="$(cd "$TGX_SRC" && pwd)"
else
    tgx="$work/tgx"
    if [ ! -d "$tgx/.git" ]; then
        rm -rf "$tgx.part"
        if ! git clone --quiet --no-checkout --filter=blob:none https://github.com/vindar/tgx "$tgx.part"; then
            rm -rf "$tgx.part"
            echo "tgx: cannot clone https://github.com/vindar/tgx; set TGX_SRC to a copy of its commit $commit" >&2
            exit 1
        fi
        mv "$tgx.part" "$tgx"
    fi
    [ "$(git -C "$tgx" rev-parse HEAD 2>/dev/null)" = "$commit" ] || git -C "$tgx" checkout --quiet "$commit"
fi
for f in src/tgx.h src/Color.cpp tools/legacy_tools/obj_to_h.py; do
    [ -f "$tgx/$f" ] || { echo "tgx: $tgx/$f not found (TGX_SRC must hold TGX's src/ and tools/)" >&2; exit 1; }
done
# The sources profile.py's stage attribution (line numbers) was written for.
sum="$(cd "$tgx/src" && LC_ALL=C cat ./*.h ./*.inl ./*.cpp | sha256sum | cut -c1-16)"
[ "$sum" = e6c08bb7a44088b1 ] ||
    echo "tgx: note: $tgx/src differs from commit ${commit:0:7} (sha256 $sum): the stages may be misattributed" >&2

# Inputs: Suzanne's texels from soft3d's converter, with examples/qemu/build.rs's options; the
# model, texture and strips as TGX headers (gen.py); the two QEMU plugins.
(cd "$root" && nice -n 10 cargo run --release --quiet --features cli --bin soft3d -- convert \
    --uv-origin top --max-texture 128 --float-positions -o "$work/suzanne.s3d" assets/suzanne/monkey.babylon) >/dev/null
python3 "$here/gen.py" "$root/assets/suzanne/monkey.babylon" "$work/suzanne.s3d" "$tgx" "$work/gen" >/dev/null
mkdir -p "$work/tools"
gcc -O2 -shared -fPIC -o "$work/tools/libinsncount.so" "$root/../shared/tools/qemu-insncount/insncount.c"
gcc -O2 -shared -fPIC -o "$work/tools/libpcprof.so" "$root/benches/qemu-pcprof/pcprof.c"

# Firmware for 1 and 2 frames; each run in QEMU with both plugins (the firmware writes
# out/tgx-frame.rgb565 through semihosting, and its JSON line on QEMU's stderr).
build="$work/build${opt}" out="$work/${opt#-}"
nice -n 10 make -s -C "$here/fw" TGX="$tgx" GEN="$work/gen" BUILD="$build" OPT="$opt"
rm -rf "$out"
mkdir -p "$out/out"
for n in 1 2; do
    if ! (cd "$out" && PCPROF_OUT=pc-$n.txt timeout 300 nice -n 10 qemu-system-arm -machine mps2-an386 \
        -cpu cortex-m4 -nographic -monitor none -serial none -semihosting-config enable=on,target=native \
        -icount shift=0 -kernel "$build/fw-$n.elf" -plugin "$work/tools/libinsncount.so" \
        -plugin "$work/tools/libpcprof.so" -d plugin -D log-$n.txt 2>json-$n.txt); then
        echo "tgx: QEMU failed on fw-$n.elf (status 124: timed out):" >&2
        cat "$out/json-$n.txt" >&2
        exit 1
    fi
done
insns() { sed -n 's/^insns: *\([0-9]*\).*/\1/p' "$1" | tail -n 1; }
i1="$(insns "$out/log-1.txt")" i2="$(insns "$out/log-2.txt")"
echo "TGX ${commit:0:7}, $(arm-none-eabi-g++ -dumpversion) $opt, mps2-an386: 1 frame $i1, 2 frames $i2," \
    "per frame $((i2 - i1)) instructions"
cat "$out/json-1.txt"

python3 "$here/topng.py" "$out/out/tgx-frame.rgb565" "$out/tgx-frame.png" >/dev/null
frame="$root/out/qemu-frame-m4.rgb565"
if [ -f "$frame" ]; then
    python3 "$here/topng.py" "$out/out/tgx-frame.rgb565" "$out/tgx-frame.png" "$frame" "$out/compare.png"
else
    echo "(no $frame, written by scripts/qemu-check.sh: no side-by-side picture)"
fi
python3 "$here/profile.py" "$build/fw-2.elf" "$out/pc-1.txt" "$out/pc-2.txt" >"$out/profile.md"
echo
sed -n '1,4p;/| stage/,$p' "$out/profile.md"
echo "picture: $out/tgx-frame.png; full profile: $out/profile.md"
