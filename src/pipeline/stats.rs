//! What a frame's draws count: [`Stats`], summed over draws and bands.

use super::raster;
#[cfg(doc)]
use super::Scratch;

/// What happened during a frame (or band), summed over all draws. Every count saturates at
/// `u32::MAX` (many instances of large meshes can pass it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Triangles handed to the pipeline.
    pub triangles_submitted: u32,
    /// Triangles skipped because their mesh's bounding sphere is outside the view frustum.
    pub culled_frustum_mesh: u32,
    /// Triangles wholly outside a view plane, or with non-finite coordinates.
    pub culled_frustum: u32,
    /// Back faces culled.
    pub culled_back_face: u32,
    /// Triangles of zero area after snapping.
    pub culled_degenerate: u32,
    /// Triangles cut by the near/far/guard planes.
    pub clipped: u32,
    /// Triangles (or clipped pieces) that reached the rasterizer with pixels in this band.
    pub drawn: u32,
    /// Pixels written.
    pub pixels_written: u32,
    /// Steps wireframe lines walked: only those inside the band, so at most the band's width
    /// or rows a line, however far off screen its ends are.
    pub line_steps: u32,
    /// Runs of covered pixels handed to the span loop (each a row, or part of a row, of a
    /// triangle): what the per-row and per-run costs are measured against.
    pub runs: u32,
    /// Fragments rejected by the depth test.
    pub depth_rejected: u32,
    /// Triangles skipped because they cannot touch this band: known from a [`Scratch`]
    /// before any vertex work, or found from their projected rows before lighting.
    pub outside_band: u32,
}

impl Stats {
    /// Counts a triangle the rasterizer refused.
    pub(crate) fn count_reject(&mut self, r: raster::Reject) {
        match r {
            raster::Reject::BackFace => self.culled_back_face += 1,
            raster::Reject::Degenerate => self.culled_degenerate += 1,
            raster::Reject::Empty => {}
            raster::Reject::OutsideGuardBand => self.culled_frustum += 1,
        }
    }
}

/// Saturating: a frame of many instances can count more than 2^32 of something.
impl core::ops::AddAssign for Stats {
    fn add_assign(&mut self, o: Stats) {
        let mut o = o;
        for (count, add) in self.counts().into_iter().zip(o.counts()) {
            *count = count.saturating_add(*add);
        }
    }
}

impl Stats {
    /// Every count, in the order of the fields.
    fn counts(&mut self) -> [&mut u32; 12] {
        [
            &mut self.triangles_submitted,
            &mut self.culled_frustum_mesh,
            &mut self.culled_frustum,
            &mut self.culled_back_face,
            &mut self.culled_degenerate,
            &mut self.clipped,
            &mut self.drawn,
            &mut self.pixels_written,
            &mut self.runs,
            &mut self.line_steps,
            &mut self.depth_rejected,
            &mut self.outside_band,
        ]
    }
}
