#!/usr/bin/env bash
# Builds the QEMU firmware (examples/qemu) for the Cortex-M4F (thumbv7em-none-eabihf, run on
# mps2-an386) and for thumbv6m (thumbv6m-none-eabi, run on mps2-an385's Cortex-M3), renders the
# reference Suzanne frame on each, and checks the result:
#   - QEMU exits 0 and the firmware printed its JSON statistics line (shown here);
#   - the frame covers the expected pixels and the frame file is 240x240x2 bytes: 14,457 (the
#     reference coverage) on the M4F; 14,456 on thumbv6m, whose firmware draws with 16-bit
#     positions and the fixed-point vertex path (RenderOptions::fixed_vertices), within 1/16
#     pixel of f32, which moves one edge pixel.
# Then the development (overflow-checked) build of both, on the reference frame and the two
# other benchmark views (features view-far, view-near): no panic, and the same reference frame.
# Frames: out/qemu-frame-m4.rgb565 and out/qemu-frame-m0.rgb565 (little-endian RGB565, 240x240,
# row-major, no header): tests/qemu_frame.rs checks each is bit-identical to the host's
# rendering with the same model and options.
# Then riscv32imc (riscv32imc-unknown-none-elf, release, on qemu-system-riscv32's virt machine with
# -bios none), which draws like thumbv6m (no FPU): its frame must equal out/qemu-frame-m0.rgb565
# byte for byte. Skipped, with a message, without qemu-system-riscv32 (Debian: qemu-system-misc).
# Last, the animated rabbit (feature `rabbit`: ../shared/assets/rabbit/Rabbit.babylon beside the
# repository, posed at frame 50 and drawn with Renderer::draw_posed) on both ARM machines, release:
# QEMU exits 0, the JSON line is printed, the frame file is 240x240x2 bytes. Frames:
# out/qemu-frame-rabbit-m4.rgb565 and out/qemu-frame-rabbit-m0.rgb565, which tests/qemu_frame.rs
# checks are bit-identical to the host's rendering of the same posed frame.
#
# Needs: rustup targets thumbv7em-none-eabihf, thumbv6m-none-eabi and riscv32imc-unknown-none-elf,
# qemu-system-arm (and qemu-system-riscv32 for the riscv32imc check).
# Exit status: 0 when every check passed, 1 otherwise.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
fw="$root/examples/qemu"
out="$root/out"
frame_bytes=$((240 * 240 * 2))

if ! command -v qemu-system-arm >/dev/null; then
    echo "qemu-check: qemu-system-arm not found (apt-get install -y --no-install-recommends qemu-system-arm)" >&2
    exit 1
fi
mkdir -p "$out"

# target  machine  cpu  suffix  covered pixels
configs=(
    "thumbv7em-none-eabihf mps2-an386 cortex-m4 m4 14457"
    "thumbv6m-none-eabi mps2-an385 cortex-m3 m0 14456"
)

# Runs firmware ELF on MACHINE/CPU under QEMU for at most SECONDS, from the repository root (the
# firmware writes out/qemu-frame.rgb565 relative to QEMU's working directory); prints and sets
# JSON (its output) and STATUS (QEMU's exit status: a panic exits non-zero, 124 = timed out).
run_firmware() {
    local elf="$1" machine="$2" cpu="$3" seconds="$4"
    set +e
    JSON="$(cd "$root" && timeout "$seconds" qemu-system-arm -machine "$machine" -cpu "$cpu" -nographic \
        -monitor none -serial none -semihosting-config enable=on,target=native -kernel "$elf")"
    STATUS=$?
    set -e
    echo "$JSON"
}

# Moves the frame the firmware just wrote (out/qemu-frame.rgb565) to FRAME and checks its size;
# a missing or wrong-sized frame sets FAILED, naming WHAT.
keep_frame() {
    local what="$1" frame="$2"
    if [ ! -f "$out/qemu-frame.rgb565" ]; then
        echo "FAIL: $what: no frame written" >&2
        failed=1
        return
    fi
    mv "$out/qemu-frame.rgb565" "$frame"
    local size
    size="$(wc -c <"$frame")"
    if [ "$size" -ne "$frame_bytes" ]; then
        echo "FAIL: $what: $frame has $size bytes, expected $frame_bytes" >&2
        failed=1
    fi
}

# Builds the release firmware for TARGET with FEATURES (may be empty), runs it on MACHINE/CPU
# (run_firmware) with FRAME and the last frame file removed, and sets COVERED to the covered
# pixels of its JSON line. A failed run or a missing line sets FAILED, naming WHAT, and returns 1.
release_run() {
    local what="$1" target="$2" features="$3" machine="$4" cpu="$5" frame="$6"
    # Called as `release_run ... || continue`, where `set -e` does not stop the script: checked.
    if ! (cd "$fw" && cargo build --release --quiet --target "$target" ${features:+--features "$features"}); then
        echo "FAIL: $what: the firmware does not build" >&2
        failed=1
        return 1
    fi
    rm -f "$out/qemu-frame.rgb565" "$frame"
    run_firmware "$fw/target/$target/release/soft3d-qemu" "$machine" "$cpu" 300
    if [ "$STATUS" -ne 0 ]; then
        echo "FAIL: $what: QEMU exited with status $STATUS (124 = timed out)" >&2
        failed=1
        return 1
    fi
    local line
    line="$(grep -m1 '^{"frame"' <<<"$JSON" || true)"
    if [ -z "$line" ]; then
        echo "FAIL: $what: no JSON statistics line" >&2
        failed=1
        return 1
    fi
    COVERED="$(sed -n 's/.*"covered":\([0-9]*\).*/\1/p' <<<"$line")"
}

failed=0
for config in "${configs[@]}"; do
    read -r target machine cpu suffix expected_covered <<<"$config"
    echo "== $target on $machine ($cpu)"
    frame="$out/qemu-frame-$suffix.rgb565"
    release_run "$target" "$target" "" "$machine" "$cpu" "$frame" || continue
    if [ "$COVERED" != "$expected_covered" ]; then
        echo "FAIL: $target: covered $COVERED pixels, expected $expected_covered" >&2
        failed=1
    fi
    keep_frame "$target" "$frame"
done

# riscv32imc: the same firmware, the same fixed-point path as thumbv6m, so the same frame.
if command -v qemu-system-riscv32 >/dev/null; then
    target=riscv32imc-unknown-none-elf
    echo "== $target on virt (rv32)"
    (cd "$fw" && cargo build --release --quiet --target "$target")
    rm -f "$out/qemu-frame.rgb565"
    set +e
    json="$(cd "$root" && timeout 300 qemu-system-riscv32 -machine virt -bios none -nographic -monitor none \
        -serial none -semihosting-config enable=on,target=native -kernel "$fw/target/$target/release/soft3d-qemu")"
    status=$?
    set -e
    echo "$json"
    if [ "$status" -ne 0 ]; then
        echo "FAIL: $target: QEMU exited with status $status (124 = timed out)" >&2
        failed=1
    elif ! grep -q '^{"frame".*"covered":14456,' <<<"$json"; then
        echo "FAIL: $target: no JSON statistics line with 14456 covered pixels" >&2
        failed=1
    elif ! cmp -s "$out/qemu-frame.rgb565" "$out/qemu-frame-m0.rgb565"; then
        echo "FAIL: $target: its frame differs from thumbv6m's (out/qemu-frame-m0.rgb565)" >&2
        failed=1
    fi
    rm -f "$out/qemu-frame.rgb565"
else
    echo "qemu-check: riscv32imc skipped: qemu-system-riscv32 not found (apt-get install -y --no-install-recommends qemu-system-misc)"
fi

# The development build (examples/qemu's dev profile: overflow checks and debug assertions on,
# as a firmware's everyday build has them) of both targets, on the reference frame and the two
# other benchmark views: it must not panic, and its reference frame must equal the release one.
for config in "${configs[@]}"; do
    read -r target machine cpu suffix expected_covered <<<"$config"
    for view in "" view-far view-near; do
        echo "== dev profile, $target on $machine ($cpu)${view:+, $view}"
        (cd "$fw" && cargo build --quiet --target "$target" ${view:+--features "$view"})
        rm -f "$out/qemu-frame.rgb565"
        run_firmware "$fw/target/$target/debug/soft3d-qemu" "$machine" "$cpu" 600
        status="$STATUS"
        if [ "$status" -ne 0 ]; then
            echo "FAIL: dev profile, $target ${view}: QEMU exited with status $status (a panic exits non-zero)" >&2
            failed=1
        elif [ -z "$view" ] && ! cmp -s "$out/qemu-frame.rgb565" "$out/qemu-frame-$suffix.rgb565"; then
            echo "FAIL: dev profile, $target: its frame differs from the release build's" >&2
            failed=1
        fi
    done
done
rm -f "$out/qemu-frame.rgb565"

# The animated rabbit (feature `rabbit`), release, on both ARM machines.
rabbit_scene="$root/../shared/assets/rabbit/Rabbit.babylon"
rabbit_configs=("${configs[@]}")
if [ ! -f "$rabbit_scene" ]; then
    echo "FAIL: rabbit: $rabbit_scene not found (the firmware converts it at build time)" >&2
    failed=1
    rabbit_configs=()
fi
for config in "${rabbit_configs[@]}"; do
    read -r target machine cpu suffix _ <<<"$config"
    echo "== rabbit (posed, frame 50), $target on $machine ($cpu)"
    frame="$out/qemu-frame-rabbit-$suffix.rgb565"
    release_run "rabbit, $target" "$target" rabbit "$machine" "$cpu" "$frame" || continue
    if [ "${COVERED:-0}" -eq 0 ]; then
        echo "FAIL: rabbit, $target: the frame covers no pixel" >&2
        failed=1
    fi
    keep_frame "rabbit, $target" "$frame"
done

echo "frames: $out/qemu-frame-m4.rgb565 $out/qemu-frame-m0.rgb565"
echo "rabbit frames: $out/qemu-frame-rabbit-m4.rgb565 $out/qemu-frame-rabbit-m0.rgb565"
if [ "$failed" -ne 0 ]; then
    echo "qemu-check: FAILED" >&2
    exit 1
fi
echo "qemu-check: ok"
