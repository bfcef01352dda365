//! The span loop of the common variant of small targets in Armv7-M assembly (`cfg(span_asm)`,
//! see the parent module's text): the pixel loop's pieces (`asm565!`, also for `rows565`'s row
//! routines) and single runs ([`run565`], [`run565_perspective`]) of the variant `run565.rs`
//! describes, with the Rust loop of the parent module as their checked twin.

use super::run565::{run_ends, Run565};
#[cfg(not(soft_float))]
use crate::fixed::Depth30;

/// The assembly both loops of [`Run565`]'s variant share, as template lines, in the registers
/// both keep: `r0` the byte offset of the pixel from the runs' ends (negative, up to 0), `r1`
/// and `r2` the ends of the colours and depths, `r3` the [`Run565`] constants, `r4` the depth
/// (2.30); `r5`, `r8`, `r9` the pixel's `u`, `v` (scaled) and light (biased); `r6`, `r7`,
/// `r11`, `r12`, `lr` free.
macro_rules! asm565 {
    // The depth test (LEQUAL on the 16-bit depth): to `4f` when it fails, else stores the depth.
    (depth_test) => {
        concat!(
            "ldrh r11, [r2, r0]\n",
            "usat r12, #16, r4, asr #14\n",
            "cmp r12, r11\n",
            "bhi 4f\n",
            "strh r12, [r2, r0]\n",
        )
    };
    // Depth and varyings on by a pixel (the steps at [sp]), then the flags of the next offset
    // (0 after the last pixel).
    (step) => {
        concat!(
            "ldm sp, {{r6, r7, r11, r12}}\n",
            "add r4, r4, r6\n",
            "add r5, r5, r7\n",
            "add r8, r8, r11\n",
            "add r9, r9, r12\n",
            "adds r0, r0, #2\n",
        )
    };
    // The pixels of a run with linear varyings, from `2:` to the last (the step at `5:`).
    (linear_pixels) => {
        concat!("2:\n", asm565!(depth_test), asm565!(shade), "5:\n", asm565!(step), "bne 2b\n",)
    };
    // A pixel the depth test rejected (`4:`): counted, then on to the step at `5:`.
    (reject) => {
        concat!("4:\n", "add r10, r10, #1\n", "b 5b\n")
    };
    // The varyings `(t · (1 / s) + v0) as i32` (`raster::PixelRun`) from `s` in `s0`, the `t`s
    // in `s1`-`s3`, the `v0`s in `s4`-`s6` and 1.0 in `s11`, each operation rounded as the Rust
    // code's f32 operators; `s12`-`s15` free.
    (perspective) => {
        concat!(
            "vdiv.f32 s12, s11, s0\n",
            "vmul.f32 s13, s1, s12\n",
            "vmul.f32 s14, s2, s12\n",
            "vmul.f32 s15, s3, s12\n",
            "vadd.f32 s13, s13, s4\n",
            "vadd.f32 s14, s14, s5\n",
            "vadd.f32 s15, s15, s6\n",
            "vcvt.s32.f32 s13, s13\n",
            "vcvt.s32.f32 s14, s14\n",
            "vcvt.s32.f32 s15, s15\n",
            "vmov r5, r8, s13, s14\n",
            "vmov r9, s15\n",
        )
    };
    // The texel `(u >> 16 & u_mask) | (v >> 16 & v_mask)` lit as `texture::modulate565_white_with`
    // does (level 0..=63, fields spread, multiplied, joined), stored.
    (shade) => {
        concat!(
            "ldm r3, {{r6, r7, r11, r12, lr}}\n",
            "and r6, r6, r5, asr #16\n",
            "and r7, r7, r8, asr #16\n",
            "orr r6, r6, r7\n",
            "ldrh r6, [r11, r6, lsl #1]\n",
            "usat r7, #6, r9, asr #11\n",
            "orr r6, r6, r6, lsl #16\n",
            "and r6, r6, r12\n",
            "mla r6, r6, r7, lr\n",
            "and r6, r12, r6, lsr #5\n",
            "orr r6, r6, r6, lsr #16\n",
            "strh r6, [r1, r0]\n",
        )
    };
}

/// Draws a run of the variant [`Run565`] describes with varyings stepping linearly: `colors` and
/// `depths` (the same length, checked), the depth (2.30) and the varyings `u`, `v` (scaled by
/// the width, see `Repeat565::scale_v`) and light (biased) at the first pixel in `values`, their
/// steps per pixel in `steps`. The same pixels as `Shader::run`'s loop draws for it, in 24
/// instructions a pixel written (13 a pixel rejected) instead of about 33: every register the
/// loop needs is its own (the constants and steps, each loaded with one `ldm` where they are
/// used), which LLVM's allocation of the Rust loop does not achieve. The pixels the depth test
/// rejected.
#[inline(always)]
pub(super) fn run565(colors: &mut [u16], depths: &mut [u16], values: [i32; 4], steps: [i32; 4], k: &Run565) -> u32 {
    let Some((offset, color_end, depth_end)) = run_ends(colors, depths) else {
        return 0;
    };
    let [z, u, v, light] = values;
    let [dz, du, dv, dlight] = steps;
    let rejected: u32;
    // SAFETY: the loop reads and writes entries `-n..0` of `color_end` and `depth_end` (byte
    // offsets `-2n..0`), so `colors[0..n]` and `depths[0..n]`, both `n` long (`run_ends`); it
    // reads texel `(v >> 16 & v_mask) | (u >> 16 & u_mask)` of `k.texels`, an index of at most
    // `u_mask | v_mask = len - 1` (`Repeat565::texels_and_masks`); it restores `r6`, `r7` and
    // `sp`, and writes no other memory.
    unsafe {
        core::arch::asm!(
            // Steps at [sp] for the `ldm` that adds them; r6, r7 free.
            "push {{r6, r7}}",
            "push {{r10, r11, r12, lr}}",
            "mov r10, #0",
            "cbz r0, 3f",
            asm565!(linear_pixels),
            "3:",
            "add sp, sp, #16",
            "pop {{r6, r7}}",
            "b 6f",
            asm565!(reject),
            "6:",
            inout("r0") offset => _,
            in("r1") color_end,
            in("r2") depth_end,
            in("r3") k as *const Run565,
            inout("r4") z => _,
            inout("r5") u => _,
            inout("r8") v => _,
            inout("r9") light => _,
            inout("r10") dz => rejected,
            inout("r11") du => _,
            inout("r12") dv => _,
            inout("lr") dlight => _,
        );
    }
    rejected
}

/// [`run565`] with perspective-correct varyings (`raster::PixelRun`): at each pixel the three
/// varyings are `(t[k] · (1 / s) + v0[k]) as i32`, then `s` and `t` step by `ds` and `dt`, all
/// in f32 with the rounding of `PixelRun`'s operators; `f` is `[s, t0, t1, t2, v0_0, v0_1, v0_2,
/// ds, dt0, dt1, dt2]` (see `RunVaryings::perspective`). The floats come through memory
/// (`vldm`), and the loop saves and restores `s0`-`s15` itself: Rust's inline assembly takes `s`
/// registers as operands only with the double-precision `vfp2` feature, which the Cortex-M4F
/// lacks.
#[cfg(not(soft_float))]
#[inline(always)]
pub(super) fn run565_perspective(
    colors: &mut [u16],
    depths: &mut [u16],
    (z, dz): (Depth30, i32),
    f: &[f32; 11],
    k: &Run565,
) -> u32 {
    let Some((offset, color_end, depth_end)) = run_ends(colors, depths) else {
        return 0;
    };
    let rejected: u32;
    // SAFETY: as `run565`'s (the same entries, the same texel index), and it reads the 11
    // floats of `f`; it restores `r5`, `r6`, `r7`, `s0`-`s15` and `sp`.
    unsafe {
        core::arch::asm!(
            // The depth step at [sp]; r6, r7 and s0-s15 free.
            "vpush {{s0-s15}}",
            "push {{r5, r6, r7}}",
            "vldm lr, {{s0-s10}}",
            "mov r10, #0",
            "vmov.f32 s11, #1.0",
            // A run of no pixels skips it (`cbz` cannot branch that far).
            "cbnz r0, 2f",
            "b 3f",
            "2:",
            asm565!(depth_test),
            asm565!(perspective),
            asm565!(shade),
            // Step depth and varyings; next pixel.
            "5:",
            "vadd.f32 s0, s0, s7",
            "vadd.f32 s1, s1, s8",
            "vadd.f32 s2, s2, s9",
            "vadd.f32 s3, s3, s10",
            "ldr r6, [sp]",
            "add r4, r4, r6",
            "adds r0, r0, #2",
            "bne 2b",
            "3:",
            "pop {{r5, r6, r7}}",
            "vpop {{s0-s15}}",
            "b 6f",
            asm565!(reject),
            "6:",
            inout("r0") offset => _,
            in("r1") color_end,
            in("r2") depth_end,
            in("r3") k as *const Run565,
            inout("r4") z => _,
            inout("r5") dz => _,
            out("r8") _,
            out("r9") _,
            out("r10") rejected,
            out("r11") _,
            out("r12") _,
            inout("lr") f.as_ptr() => _,
        );
    }
    rejected
}
