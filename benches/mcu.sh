#!/usr/bin/env bash
# Microcontroller benchmark: guest instructions executed by QEMU (deterministic, unlike wall-clock
# time) to render the reference Suzanne frame (240x240 RGB565) with the firmware in
# examples/qemu, on the Cortex-M4F (thumbv7em-none-eabihf, mps2-an386), on thumbv6m code
# (thumbv6m-none-eabi, run on mps2-an385's Cortex-M3) and on riscv32imc (riscv32imc-unknown-none-elf,
# run on qemu-system-riscv32's virt machine, -bios none).
#
# Per-frame cost = count(2 frames) - count(1 frame), which subtracts start-up (stack painting,
# .data/.bss set-up, model parsing) and the one-off end (frame file, stack scan, JSON line).
# Both 8 bands of 240x30 (the default) and 1 band of 240x240 (feature `one-band`) are measured.
# Prints a markdown table.
#
# Needs: rustup targets thumbv7em-none-eabihf, thumbv6m-none-eabi and riscv32imc-unknown-none-elf,
# qemu-system-arm 7.2 (plugin API v1; Debian bookworm's), gcc, readelf, and the
# instruction-counting plugin in shared/tools/qemu-insncount beside the repository. Without the
# plugin (or qemu-system-arm/gcc) it prints why and "skipped", and exits 0. Without
# qemu-system-riscv32 (Debian: qemu-system-misc) only the riscv32imc rows are skipped, with a message.
set -euo pipefail

root="$(git -C "$(dirname "${BASH_SOURCE[0]}")" rev-parse --show-toplevel)"
fw="$root/examples/qemu"
plugin_dir="$root/../shared/tools/qemu-insncount"

skip() {
    echo "mcu bench: $1"
    echo "skipped"
    exit 0
}
[ -f "$plugin_dir/build.sh" ] || skip "no instruction-count plugin at $plugin_dir (shared/tools/qemu-insncount beside the repository)"
command -v qemu-system-arm >/dev/null || skip "qemu-system-arm not found (apt-get install -y --no-install-recommends qemu-system-arm)"
command -v gcc >/dev/null || skip "gcc not found (needed to build the plugin)"
command -v readelf >/dev/null || skip "readelf not found (binutils)"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Build the plugin (as its build.sh does) into our own temporary folder: shared/ is read-only.
plugin="$work/libinsncount.so"
gcc -O2 -shared -fPIC -o "$plugin" "$plugin_dir/insncount.c" \
    || { echo "mcu bench: building the plugin failed" >&2; exit 1; }
mkdir -p "$work/out" # the firmware writes out/qemu-frame.rgb565 relative to QEMU's working directory

# Sum of the sizes of the named ELF sections (readelf -S: "[Nr] Name Type Address Off Size ...").
section_bytes() {
    local elf="$1" sum=0 name type addr off size rest
    shift
    while read -r name type addr off size rest; do
        case " $* " in *" $name "*) sum=$((sum + 16#$size)) ;; esac
    done < <(readelf -SW "$elf" | sed -n 's/^ *\[ *[0-9]*\] *//p')
    echo "$sum"
}

# The QEMU system emulator for a target.
qemu_for() {
    case "$1" in
        riscv32*) echo qemu-system-riscv32 ;;
        *) echo qemu-system-arm ;;
    esac
}

# Runs an ELF under QEMU with the plugin; sets INSNS and JSON. riscv32 (virt) runs without
# firmware (-bios none): QEMU jumps straight to the ELF's entry point.
run() {
    local elf="$1" machine="$2" cpu="$3" qemu="${4:-qemu-system-arm}" status=0
    local bios=()
    [ "$qemu" = qemu-system-riscv32 ] && bios=(-bios none)
    rm -f "$work/plugin.log"
    JSON="$(cd "$work" && timeout 120 "$qemu" -machine "$machine" -cpu "$cpu" "${bios[@]}" -nographic -monitor none \
        -serial none -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf" \
        -plugin "$plugin" -d plugin -D "$work/plugin.log")" || status=$?
    if [ "$status" -ne 0 ]; then
        echo "mcu bench: $elf on $machine exited with status $status (124 = timed out)" >&2
        exit 1
    fi
    INSNS="$(sed -n 's/^insns: *\([0-9]*\).*/\1/p' "$work/plugin.log" | tail -n 1)"
    [ -n "$INSNS" ] || { echo "mcu bench: no instruction count in plugin.log" >&2; exit 1; }
}

json_field() { sed -n "s/.*\"$1\":\([0-9]*\).*/\1/p" <<<"$2"; }

# target  board  cpu (rv32: virt's default CPU, given explicitly)
configs=(
    "thumbv7em-none-eabihf mps2-an386 cortex-m4"
    "thumbv6m-none-eabi mps2-an385 cortex-m3"
    "riscv32imc-unknown-none-elf virt rv32"
)

rows=()
ratios=()
lines=()
m4_covered=0 # covered pixels of the M4F 1-band frame, for the stage table
m4_json=""   # its JSON line
skipped=()
for config in "${configs[@]}"; do
    read -r target machine cpu <<<"$config"
    qemu="$(qemu_for "$target")"
    if ! command -v "$qemu" >/dev/null; then
        skipped+=("$target: skipped, $qemu not found (apt-get install -y --no-install-recommends qemu-system-misc)")
        echo "mcu bench: ${skipped[-1]}" >&2
        continue
    fi
    declare -A per_frame=()
    for bands in 8 1; do
        band_feature=""
        [ "$bands" = 1 ] && band_feature="one-band"
        declare -A count=()
        for frames in 1 2; do
            features="$band_feature"
            [ "$frames" = 2 ] && features="${features:+$features,}two-frames"
            echo "building $target, $bands band(s), $frames frame(s)" >&2
            (cd "$fw" && cargo build --release --quiet --target "$target" --features "$features")
            elf="$work/$target-$bands-$frames.elf"
            cp "$fw/target/$target/release/soft3d-qemu" "$elf"
            run "$elf" "$machine" "$cpu" "$qemu"
            count[$frames]="$INSNS"
            if [ "$frames" = 1 ]; then
                json1="$JSON"
                elf1="$elf"
            fi
            lines+=("$target $bands band(s) $frames frame(s): $JSON")
        done
        covered="$(json_field covered "$json1")"
        if [ "$target" = thumbv7em-none-eabihf ] && [ "$bands" = 1 ]; then
            m4_covered="$covered"
            m4_json="$json1"
        fi
        stack="$(json_field stack_bytes "$json1")"
        if [ "$qemu" != qemu-system-riscv32 ]; then
            # The core stack from a build that keeps the draw out of line (see examples/qemu's
            # `stack-probe`): in the counted one, LTO inlines its top levels into the firmware.
            echo "building $target, $bands band(s), stack probe" >&2
            (cd "$fw" && cargo build --release --quiet --target "$target" --features "${band_feature:+$band_feature,}stack-probe")
            cp "$fw/target/$target/release/soft3d-qemu" "$work/$target-$bands-probe.elf"
            run "$work/$target-$bands-probe.elf" "$machine" "$cpu" "$qemu"
            core_stack="$(json_field core_stack_bytes "$JSON")"
            lines+=("$target $bands band(s) stack probe: $JSON")
        fi
        pf=$((count[2] - count[1]))
        per_frame[$bands]="$pf"
        per_px="$(awk -v a="$pf" -v b="$covered" 'BEGIN { printf "%.1f", (b > 0 ? a / b : 0) }')"
        if [ "$qemu" = qemu-system-riscv32 ]; then
            # riscv-rt's link.x: start-up code in .init.rust, and it keeps .eh_frame (in flash).
            # No stack figures: the firmware measures the stack on Cortex-M only (reports 0).
            flash="$(section_bytes "$elf1" .text .init.rust .rodata .eh_frame .data)"
            stack="n/a"
            core_stack="n/a"
        else
            flash="$(section_bytes "$elf1" .vector_table .text .rodata .data)"
        fi
        ram="$(section_bytes "$elf1" .data .bss .uninit)"
        rows+=("| $target | $machine ($cpu) | $bands x 240x$((240 / bands)) | ${count[1]} | ${count[2]} | $pf | $covered | $per_px | $flash | $ram | $stack | $core_stack |")
        unset count
    done
    ratios+=("| $target | ${per_frame[8]} | ${per_frame[1]} | $(awk -v a="${per_frame[8]}" -v b="${per_frame[1]}" 'BEGIN { printf "%.3f", a / b }') |")
    unset per_frame
done

echo
echo "Reference Suzanne frame, 240x240 RGB565, textured (nearest), Gouraud, perspective-correct (within 1/16 texel),"
echo "drawn with a RowCache of triangle rows and transformed vertices. The thumbv6m build (no FPU) uses 16-bit"
echo "positions and the fixed-point vertex path (RenderOptions::fixed_vertices), and so does riscv32imc (no FPU either:"
echo "the same frame, byte for byte); the M4F build f32 positions and vertices."
echo "Instruction counts from QEMU (-icount shift=0, qemu-insncount plugin); per frame = 2 frames - 1 frame."
echo "Flash = .vector_table + .text + .rodata + .data (includes the 32 KiB 128x128 RGB565 texture);"
echo "static RAM = .data + .bss (includes the colour and depth band buffers); stack = high-water mark of the"
echo "whole firmware (semihosting included); core stack = what the draw calls alone use, all of the renderer's frames (the stack-probe build, see examples/qemu)."
echo "riscv32imc (QEMU virt, -bios none): flash = .text + .init.rust + .rodata + .eh_frame + .data; its stack is not"
echo "measured (n/a)."
echo
echo "| target | board | bands | insns 1 frame | insns 2 frames | insns per frame | covered px | insns per covered px | flash bytes | static RAM bytes | stack bytes | core stack bytes |"
echo "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
printf '%s\n' "${rows[@]}"
echo
echo "| target | per frame, 8 bands of 240x30 | per frame, 1 band of 240x240 | 8 bands / 1 band |"
echo "| --- | ---: | ---: | ---: |"
printf '%s\n' "${ratios[@]}"
[ "${#skipped[@]}" -eq 0 ] || { echo; printf '%s\n' "${skipped[@]}"; }
# Other views of the same model, M4F, 1 band (examples/qemu `view`): far away (vertex-bound)
# and a close-up (pixel-bound, clipped at the guard band).
views=()
for view in view-far view-near; do
    declare -A count=()
    for frames in 1 2; do
        features="one-band,$view"
        [ "$frames" = 2 ] && features="$features,two-frames"
        echo "building thumbv7em-none-eabihf, $view, $frames frame(s)" >&2
        (cd "$fw" && cargo build --release --quiet --target thumbv7em-none-eabihf --features "$features")
        elf="$work/$view-$frames.elf"
        cp "$fw/target/thumbv7em-none-eabihf/release/soft3d-qemu" "$elf"
        run "$elf" mps2-an386 cortex-m4
        count[$frames]="$INSNS"
        [ "$frames" = 1 ] && json1="$JSON"
        lines+=("thumbv7em-none-eabihf $view $frames frame(s): $JSON")
    done
    pf=$((count[2] - count[1]))
    views+=("| $view | $pf | $(json_field covered "$json1") | $(json_field pixels_written "$json1") | $(json_field runs "$json1") | $(json_field drawn "$json1") |")
    unset count
done

echo
echo "Other views, Cortex-M4F, 1 band of 240x240 (view-far: camera (0, 0, -12), model turned -0.7 rad;"
echo "view-near: camera (0.3, 0.2, -1.6), model turned 0.5 rad; both FOV 0.8):"
echo
echo "| view | insns per frame | covered px | pixels written | runs | triangles drawn |"
echo "| --- | ---: | ---: | ---: | ---: | ---: |"
printf '%s\n' "${views[@]}"
echo
echo "JSON lines:"
printf '%s\n' "${lines[@]}"

# Where the M4F's instructions go (1 band), by pipeline stage: a second plugin counts executed
# instructions per address, and benches/mcu-profile.py attributes them through the inlining
# chain. Optional: needs python3 and llvm-addr2line.
echo
if command -v python3 >/dev/null && command -v llvm-addr2line >/dev/null; then
    gcc -O2 -shared -fPIC -o "$work/libpcprof.so" "$root/benches/qemu-pcprof/pcprof.c" \
        || { echo "mcu bench: building the profiling plugin failed" >&2; exit 1; }
    m4="thumbv7em-none-eabihf"
    for frames in 1 2; do
        elf="$work/$m4-1-$frames.elf"
        (cd "$work" && PCPROF_OUT="$work/pc-$frames.txt" timeout 300 qemu-system-arm -machine mps2-an386 \
            -cpu cortex-m4 -nographic -monitor none -serial none -semihosting-config enable=on,target=native \
            -icount shift=0 -kernel "$elf" -plugin "$work/libpcprof.so" -d plugin -D "$work/pcprof.log" >/dev/null) \
            || { echo "mcu bench: profiling run failed" >&2; exit 1; }
    done
    echo "Cortex-M4F, 1 band of 240x240, instructions per frame by stage:"
    echo
    python3 "$root/benches/mcu-profile.py" "$work/$m4-1-1.elf" "$work/pc-1.txt" "$work/$m4-1-2.elf" "$work/pc-2.txt" \
        "$m4_covered" "$(json_field pixels_written "$m4_json")" "$(json_field runs "$m4_json")" \
        "$(json_field drawn "$m4_json")"
else
    echo "(stage profile skipped: needs python3 and llvm-addr2line)"
fi
