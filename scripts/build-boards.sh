#!/usr/bin/env bash
# Builds the real-board firmware in release mode and prints arm-none-eabi-size-like figures:
#   - examples/rp2040     (Raspberry Pi Pico, thumbv6m-none-eabi), then again with `dual-core`;
#   - examples/stm32f411  (STM32F411 Black Pill, thumbv7em-none-eabihf).
# text = read-only allocated sections (vector table, boot2, code, constants: the flashed image
# less .data's initial values); data = initialised RAM (also stored in flash); bss = zeroed RAM
# (.bss, .uninit). Flash = text + data; static RAM = data + bss (stacks come on top: the rest of
# RAM is core 0's stack; core 1's stack, with `dual-core`, is already in .bss).
#
# Needs: rustup targets thumbv6m-none-eabi and thumbv7em-none-eabihf, python3.
# Exit status: 0 when every build succeeded and fits its chip, 1 otherwise.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

# Figures of an ELF: "text data bss" (decimal), from its section headers.
elf_size() {
    python3 - "$1" <<'PY'
import struct, sys

with open(sys.argv[1], "rb") as f:
    elf = f.read()
if elf[:4] != b"\x7fELF" or elf[4] != 1 or elf[5] != 1:
    sys.exit(f"{sys.argv[1]}: not a little-endian ELF32 file")
shoff, = struct.unpack_from("<I", elf, 0x20)
shentsize, shnum = struct.unpack_from("<HH", elf, 0x2E)
SHF_WRITE, SHF_ALLOC, SHT_NOBITS = 0x1, 0x2, 8
text = data = bss = 0
for i in range(shnum):
    _name, kind, flags, _addr, _off, size = struct.unpack_from("<IIIIII", elf, shoff + i * shentsize)
    if not flags & SHF_ALLOC:
        continue
    if kind == SHT_NOBITS:
        bss += size
    elif flags & SHF_WRITE:
        data += size
    else:
        text += size
print(text, data, bss)
PY
}

# name  directory  target  features  flash(KiB)  ram(KiB)
boards=(
    "rp2040 examples/rp2040 thumbv6m-none-eabi - 2048 264"
    "rp2040+dual-core examples/rp2040 thumbv6m-none-eabi dual-core 2048 264"
    "stm32f411 examples/stm32f411 thumbv7em-none-eabihf - 512 128"
)

failed=0
report=()
for board in "${boards[@]}"; do
    read -r name dir target features flash_kib ram_kib <<<"$board"
    echo "== $name ($target)"
    args=(build --release --target "$target")
    [ "$features" != "-" ] && args+=(--features "$features")
    start=$(date +%s)
    if ! (cd "$root/$dir" && cargo "${args[@]}"); then
        echo "FAIL: $name does not build" >&2
        failed=1
        continue
    fi
    seconds=$(($(date +%s) - start))
    package="$(basename "$dir")"
    elf="$root/$dir/target/$target/release/soft3d-$package"
    read -r text data bss <<<"$(elf_size "$elf")"
    flash=$((text + data))
    ram=$((data + bss))
    line=$(printf '%-18s %8d %6d %8d   flash %7d B (%4.1f%% of %d KiB)   static RAM %7d B (%4.1f%% of %d KiB)   built in %ds' \
        "$name" "$text" "$data" "$bss" \
        "$flash" "$(python3 -c "print($flash * 100 / ($flash_kib * 1024))")" "$flash_kib" \
        "$ram" "$(python3 -c "print($ram * 100 / ($ram_kib * 1024))")" "$ram_kib" "$seconds")
    report+=("$line")
    if [ "$flash" -gt $((flash_kib * 1024)) ] || [ "$ram" -gt $((ram_kib * 1024)) ]; then
        echo "FAIL: $name does not fit its chip" >&2
        failed=1
    fi
done

echo
printf '%-18s %8s %6s %8s\n' "image" "text" "data" "bss"
for line in "${report[@]}"; do
    echo "$line"
done
exit "$failed"
