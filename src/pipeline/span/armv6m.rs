//! The span loop of the common variant of small targets in Armv6-M assembly
//! (`cfg(span_asm_v6m)`, see the parent module's text): single runs ([`run565`]) of the variant
//! `run565.rs` describes, in Thumb-1, with the Rust loop of the parent module as their checked
//! twin.
//!
//! Thumb-1 computes and addresses with the eight low registers only; the high ones (`r8`-`r12`,
//! `lr`) take moves and additions, and Rust's inline assembly takes none of them as an operand.
//! So the loop keeps the byte offset, both ends, `u` and `v` in low registers, the depth, the
//! light and the four steps in high ones (a step is one `add`), all loaded from a block in
//! memory ([`Thumb565`]); the texture's three values and the rejected count on the stack, and
//! the modulation's two constants in a literal pool (a load each where it is used: two cycles
//! on a Cortex-M0+, as a move from a high register and back would be).

use super::run565::{run_ends, Run565};
use crate::texture::{SPREAD565, SPREAD565_HALF};
use core::ptr::NonNull;

/// What [`run565`] loads: the texels' address and the masks of their byte offsets (`u_mask`
/// and `v_mask` times two), made once a triangle (see `Shader`), then each run's steps and
/// values but for `u` and `v` (in registers), written here by the run, not in a frame of their
/// own: the thumbv6m core stack stays under 2 KiB (a non-null address: an `Option` of this
/// takes no more room).
#[derive(Clone, Copy)]
#[repr(C)]
pub(super) struct Thumb565 {
    texels: NonNull<[u8; 2]>,
    u_mask2: u32,
    v_mask2: u32,
    /// The steps of depth, `u`, `v` and light, then the depth and light at the run's first
    /// pixel.
    run: [i32; 6],
}

impl Thumb565 {
    /// The block for the constants `k`, when its texels are at an even address: Armv6-M faults
    /// on a halfword load from an odd one (Armv7-M does not), and texels at one (`include_bytes!`
    /// data has alignment 1; `include_s3d!` aligns it) are drawn by the Rust loop here.
    #[inline(always)]
    pub(super) fn of(k: Run565) -> Option<Self> {
        debug_assert!([k.spread, k.half] == [SPREAD565, SPREAD565_HALF]);
        let texels = NonNull::new(k.texels.cast_mut()).filter(|t| t.as_ptr() as usize & 1 == 0)?;
        Some(Thumb565 { texels, u_mask2: k.u_mask << 1, v_mask2: k.v_mask << 1, run: [0; 6] })
    }
}

/// Draws a run of [`Run565`]'s variant with varyings stepping linearly, as the Armv7-M
/// `run565` does (the same arguments, the same pixels bit for bit, the pixels the depth test
/// rejected returned), from the block `k`: 39 instructions a pixel written, 17 a pixel
/// rejected, where LLVM's allocation of the Rust loop keeps the varyings on the stack.
#[inline(always)]
pub(super) fn run565(
    colors: &mut [u16],
    depths: &mut [u16],
    values: [i32; 4],
    steps: [i32; 4],
    k: &mut Thumb565,
) -> u32 {
    let Some((offset, color_end, depth_end)) = run_ends(colors, depths) else {
        return 0;
    };
    let [z, u, v, light] = values;
    let [dz, du, dv, dlight] = steps;
    k.run = [dz, du, dv, dlight, z, light];
    let rejected: u32;
    // SAFETY: the loop reads and writes entries `-n..0` of `color_end` and `depth_end` (byte
    // offsets `-2n..0`), so `colors[0..n]` and `depths[0..n]`, both `n` long (`run_ends`); it
    // reads texel `(v >> 16 & v_mask) | (u >> 16 & u_mask)` of `k.texels`, an index of at most
    // `u_mask | v_mask = len - 1` (`Repeat565::texels_and_masks`), at an even address
    // (`Thumb565::of`), the nine words of `k` and its own literal pool; it writes its own
    // stack slots only, and restores `r6`, `r7` and `sp`.
    unsafe {
        core::arch::asm!(
            // The stack, from `sp` up: the rejected count, the texels' address, the two masks,
            // then the saved `r6` and `r7`. The steps in r10, r11, r12, lr, the depth in r8,
            // the light in r9; `u` and `v` stay in r4 and r5 (through r12 and lr meanwhile).
            "push {{r6, r7}}",
            "mov r12, r4",
            "mov lr, r5",
            "ldm r3!, {{r5, r6, r7}}",
            "movs r4, #0",
            "push {{r4, r5, r6, r7}}",
            "mov r4, r12",
            "mov r5, lr",
            "ldm r3!, {{r6, r7}}",
            "mov r10, r6",
            "mov r11, r7",
            "ldm r3!, {{r6, r7}}",
            "mov r12, r6",
            "mov lr, r7",
            "ldm r3!, {{r6, r7}}",
            "mov r8, r6",
            "mov r9, r7",
            "cmp r0, #0",
            "beq 3f",
            // The depth test (LEQUAL on the 16-bit depth `(z >> 14) - (z >> 30)`, as
            // `target::z_to_u16_by_shifts`): to `4f` when it fails, else stores the depth.
            "2:",
            "mov r7, r8",
            "lsrs r7, r7, #14",
            "lsrs r6, r7, #16",
            "subs r7, r7, r6",
            "ldrh r6, [r2, r0]",
            "cmp r7, r6",
            "bhi 4f",
            "strh r7, [r2, r0]",
            // The texel `(v >> 16 & v_mask) | (u >> 16 & u_mask)`, as a byte offset:
            // `(v >> 15 & 2 v_mask) | (u >> 15 & 2 u_mask)`.
            "asrs r6, r5, #15",
            "ldr r7, [sp, #12]",
            "ands r6, r7",
            "asrs r3, r4, #15",
            "ldr r7, [sp, #8]",
            "ands r3, r7",
            "orrs r3, r6",
            "ldr r7, [sp, #4]",
            "ldrh r3, [r7, r3]",
            // The light level `(light >> 11).clamp(0, 63)`: out of line (`7:`) when outside.
            "mov r6, r9",
            "asrs r6, r6, #11",
            "cmp r6, #63",
            "bhi 7f",
            "1:",
            // `texture::modulate565_white_with`: fields spread, multiplied, rounded, joined.
            "lsls r7, r3, #16",
            "adds r3, r3, r7",
            "ldr r7, 8f",
            "ands r3, r7",
            "muls r3, r6, r3",
            "ldr r6, 9f",
            "adds r3, r3, r6",
            "lsrs r3, r3, #5",
            "ands r3, r7",
            "lsrs r6, r3, #16",
            "orrs r3, r6",
            "strh r3, [r1, r0]",
            // Depth and varyings on by a pixel; the next offset (0 after the last pixel).
            "5:",
            "add r8, r10",
            "add r4, r11",
            "add r5, r12",
            "add r9, lr",
            "adds r0, r0, #2",
            "bne 2b",
            "3:",
            "pop {{r3}}",
            "add sp, #12",
            "pop {{r6, r7}}",
            "b 6f",
            // A pixel the depth test rejected: counted, then on to the step.
            "4:",
            "ldr r6, [sp]",
            "adds r6, r6, #1",
            "str r6, [sp]",
            "b 5b",
            // A light level outside 0..=63: 0 below, 63 above.
            "7:",
            "asrs r7, r6, #31",
            "mvns r7, r7",
            "movs r6, #63",
            "ands r6, r7",
            "b 1b",
            // `SPREAD565` and `SPREAD565_HALF`.
            ".p2align 2",
            "8:",
            ".word {spread}",
            "9:",
            ".word {half}",
            "6:",
            spread = const SPREAD565,
            half = const SPREAD565_HALF,
            inout("r0") offset => _,
            in("r1") color_end,
            in("r2") depth_end,
            inout("r3") k as *mut Thumb565 => rejected,
            inout("r4") u => _,
            inout("r5") v => _,
            out("r8") _,
            out("r9") _,
            out("r10") _,
            out("r11") _,
            out("r12") _,
            out("lr") _,
        );
    }
    rejected
}
