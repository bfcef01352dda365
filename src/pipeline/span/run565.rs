//! The common variant of small targets that the span loop draws in assembly (`cfg(asm_runs)`:
//! Armv7-M in `armv7m.rs`, Armv6-M in `armv6m.rs`): its constants ([`Run565`]) and the hook
//! that hands a run to the assembly ([`Shader::run_in_assembly`]), with the Rust loop of the
//! parent module as the checked twin.

#[cfg(span_asm_v6m)]
use super::armv6m::run565;
#[cfg(span_asm)]
use super::armv7m::run565;
#[cfg(all(span_asm, not(soft_float)))]
use super::armv7m::run565_perspective;
use super::*;

/// The constants of [`run565`], the span loop in assembly for the common variant of small
/// targets: a [`Repeat565`] texture, white light modulating RGB565 (`Lighting::WHITE_RGB565`),
/// an RGB565 frame ([`FrameColor::as_rgb565_values`]), plain `u16` depths, varyings stepping
/// linearly, no dither. In the order the loops load them (Armv7-M: all five with one `ldm`).
#[derive(Clone, Copy)]
#[repr(C)]
pub(super) struct Run565 {
    /// See [`Repeat565::texels_and_masks`].
    pub(super) u_mask: u32,
    pub(super) v_mask: u32,
    /// The texels' address: an index masked by `u_mask | v_mask` lies within them.
    pub(super) texels: *const [u8; 2],
    /// `texture::SPREAD565` and `texture::SPREAD565_HALF`.
    pub(super) spread: u32,
    pub(super) half: u32,
}

impl Run565 {
    /// The constants for a triangle drawn from `base`, when its variant is the one [`run565`]
    /// draws (but for the depth buffer and varyings, which each run checks).
    #[inline(always)]
    pub(super) fn of<C: FrameColor, B: Base, Lt: Lighting, const DITHER: bool>(base: &B) -> Option<Self> {
        let probe: &mut [C] = &mut [];
        if DITHER || Lt::HIGHLIGHT || !Lt::WHITE_RGB565 || C::as_rgb565_values(probe).is_none() {
            return None;
        }
        let (texels, u_mask, v_mask) = base.as_repeat565()?.texels_and_masks();
        debug_assert!((u_mask | v_mask) as usize == texels.len() - 1);
        let (spread, half) = (crate::texture::SPREAD565, crate::texture::SPREAD565_HALF);
        Some(Run565 { u_mask, v_mask, texels: texels.as_ptr(), spread, half })
    }
}

impl<C: FrameColor, D: RunCells, B: Base, Lt: Lighting, const DITHER: bool> Shader<'_, '_, C, D, B, Lt, DITHER> {
    /// The constants of [`run565`] for this triangle, when its variant is the one it draws.
    #[cfg(span_asm)]
    #[inline(always)]
    pub(super) fn run565(&self) -> Option<Run565> {
        Run565::of::<C, B, Lt, DITHER>(self.base)
    }

    /// The run of `len` pixels from band entry `start` (`BandArea::run_start` gave it) by
    /// [`run565`] when this triangle's variant is the one it draws: the pixels the depth test
    /// rejected. `None`, drawing nothing, for any other variant.
    #[inline(always)]
    pub(super) fn run_in_assembly<const V: usize, R: RunVaryings<V>>(
        &mut self,
        start: usize,
        len: usize,
        (z, dz): (Depth30, i32),
        vary: &R,
    ) -> Option<u32> {
        #[cfg(span_asm_v6m)]
        let constants = self.asm.as_mut()?;
        #[cfg(not(span_asm_v6m))]
        let constants = &self.run565()?;
        // SAFETY: `run_start` gave `start` only with `start + len <= rows · width`.
        let depths = unsafe { self.depth.run_u16(start, len) }?;
        let colors = C::as_rgb565_values(colors_of(self.color, start, len)?)?;
        #[cfg(all(span_asm, not(soft_float)))]
        if let Some(f) = vary.perspective() {
            return Some(run565_perspective(colors, depths, (z, dz), &f, constants));
        }
        let (v, dv) = vary.stepped()?;
        let [u, tv, light] = [VertexLit::U, VertexLit::V, VertexLit::LIGHT].map(|k| v.get(k).copied());
        let [du, dtv, dlight] = [VertexLit::U, VertexLit::V, VertexLit::LIGHT].map(|k| dv.get(k).copied());
        let values = [z as i32, u?, tv?, light?];
        Some(run565(colors, depths, values, [dz, du?, dtv?, dlight?], constants))
    }
}

/// The run's pixel count, checked against the depths' (`None` when they differ), and the ends
/// of both: the byte offset of the first pixel from them (`-2n`) and the ends, which the loops
/// of [`Run565`]'s variant index back from.
#[inline(always)]
pub(super) fn run_ends(colors: &mut [u16], depths: &mut [u16]) -> Option<(i32, *mut u16, *mut u16)> {
    let n = colors.len();
    let ends = (colors.as_mut_ptr_range().end, depths.as_mut_ptr_range().end);
    (depths.len() == n).then_some(((n as i32).wrapping_mul(-2), ends.0, ends.1))
}
