//! The caller's memory for one frame: which rows each triangle touches, every vertex
//! transformed and lit, and the painter's sort list. All of it is optional ([`Scratch::none`]
//! draws the same pictures, only slower); none of it is allocated. Filling it is the stages'
//! job (`vertex`, `primitive`, `sort`), not this module's.

use core::ops::Range;

use super::clip::NEEDS_CLIP;
use super::vertex::{vertex_lit_varyings, Projected, VertexLight};
use crate::fixed::{FDot16, FDot4};
use crate::pipeline::raster::{first_centre, last_centre, ScreenVertex, MAX_EXTENT};

/// Memory the caller lends [`Renderer::draw`](super::Renderer::draw), all of it optional:
/// - rows ([`Scratch::with_rows`], 4 bytes a triangle counting instances): when a frame is drawn
///   in bands, the bands after the first skip the triangles that cannot touch them before any
///   vertex work (and, where a run of neighbouring triangles all miss a band, without looking
///   at each: the scratch keeps the rows of each 64th of the triangles together, 256 bytes);
/// - vertices ([`Scratch::with_vertices`], 28 bytes a vertex counting instances, see
///   [`Model::draw_counts`](crate::Model::draw_counts)): every vertex is transformed, projected
///   and lit once a frame, however many triangles and bands share it (not for Phong shading, nor
///   for meshes whose sub-meshes' textures differ in size: they draw without);
/// - sort entries ([`Scratch::with_sort`], one a triangle): the list
///   [`DrawOrder::BackToFront`](super::DrawOrder::BackToFront) sorts.
///
/// A draw whose rows or vertices do not all fit is drawn without them. Rows and vertices belong
/// to one model drawn with one transform, camera, options and lights: call
/// [`Scratch::new_frame`] (or make a new one) at the start of every frame, then pass the same
/// scratch for each band. A draw of anything else with the same scratch in that frame (another
/// model, or the same one moved) is drawn without the rows and vertices, correctly but without
/// their speed: give each model its own scratch.
pub struct Scratch<'s> {
    rows: &'s mut [TriangleRows],
    /// The rows of each chunk of neighbouring triangles together, once `summarised`.
    chunks: RowChunks,
    /// Whether `chunks` hold the rows learnt this frame (see [`Scratch::summarise_rows`]).
    summarised: bool,
    vertices: &'s mut [TransformedVertex],
    sort: &'s mut [SortEntry],
    /// What the rows and vertices were computed for (the first draw since they were reset).
    owner: Option<Owner>,
    /// Whether the current draw is that owner (see [`Scratch::claim`]).
    owned: bool,
    /// Bit `d`: the vertices of the owner's draw `d` (below 64) are cached and none needs
    /// clipping, so its later bands need no transforms (see `draw_mesh_with`).
    unclipped: u64,
    /// Bit `d`: that draw's transform mirrors (what its first band found; with `unclipped`).
    flipped: u64,
}

/// A digest (64-bit FNV-1a) of everything the cached rows and vertices depend on: the model's
/// bytes (where they are), the transform, the camera's matrix, the options and the lights. A
/// draw with any of them different cannot use them (it draws without them: the same picture,
/// slower).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Owner(pub(crate) u64);

/// Builds an [`Owner`] word by word.
pub(crate) struct Digest(u64);

impl Digest {
    pub(crate) fn new() -> Self {
        Digest(0xcbf2_9ce4_8422_2325)
    }

    /// Goes on from a digest that [`Digest::finish`] gave.
    pub(crate) fn resume(digest: u64) -> Self {
        Digest(digest)
    }

    pub(crate) fn word(&mut self, w: u32) -> &mut Self {
        self.0 = (self.0 ^ u64::from(w)).wrapping_mul(0x0100_0000_01b3);
        self
    }

    /// The floats' bits.
    pub(crate) fn floats(&mut self, v: &[f32]) -> &mut Self {
        v.iter().fold(self, |d, x| d.word(x.to_bits()))
    }

    pub(crate) fn finish(&self) -> u64 {
        self.0
    }
}

impl Scratch<'static> {
    /// No scratch memory: every band does all the work, and back-to-front order is refused.
    #[must_use]
    pub fn none() -> Self {
        Scratch {
            rows: &mut [],
            chunks: RowChunks::for_rows(0),
            summarised: false,
            vertices: &mut [],
            sort: &mut [],
            owner: None,
            owned: false,
            unclipped: 0,
            flipped: 0,
        }
    }
}

impl<'s> Scratch<'s> {
    /// Adds a row record of `rows` (reset), one entry a triangle.
    #[must_use]
    pub fn with_rows<'t>(self, rows: &'t mut [TriangleRows]) -> Scratch<'t>
    where
        's: 't,
    {
        rows.fill(TriangleRows::UNKNOWN);
        let chunks = RowChunks::for_rows(rows.len());
        Scratch { rows, chunks, summarised: false, owner: None, owned: false, unclipped: 0, flipped: 0, ..self }
    }

    /// Adds a vertex cache of `vertices` (reset), one entry a vertex.
    #[must_use]
    pub fn with_vertices<'t>(self, vertices: &'t mut [TransformedVertex]) -> Scratch<'t>
    where
        's: 't,
    {
        vertices.fill(TransformedVertex::UNKNOWN);
        Scratch { vertices, summarised: false, owner: None, owned: false, unclipped: 0, flipped: 0, ..self }
    }

    /// Adds the sort list of [`DrawOrder::BackToFront`](super::DrawOrder::BackToFront), one
    /// entry a triangle.
    #[must_use]
    pub fn with_sort<'t>(self, sort: &'t mut [SortEntry]) -> Scratch<'t>
    where
        's: 't,
    {
        Scratch { sort, owned: false, ..self }
    }

    /// Forgets the rows and vertices of the last frame (call at the start of a frame).
    pub fn new_frame(&mut self) {
        self.rows.fill(TriangleRows::UNKNOWN);
        self.vertices.fill(TransformedVertex::UNKNOWN);
        self.owner = None;
        (self.unclipped, self.flipped, self.summarised) = (0, 0, false);
    }

    /// Starts a draw for `owner`: it may use the rows and vertices when it is the first draw
    /// since they were reset (it becomes their owner) or draws what their owner drew; otherwise
    /// [`Scratch::for_draw`] gives it none.
    pub(crate) fn claim(&mut self, owner: Owner) {
        self.owned = *self.owner.get_or_insert(owner) == owner;
    }

    /// The rows and vertices of one draw, each when it fits and the draw owns them.
    #[inline]
    pub(crate) fn for_draw(
        &mut self,
        triangles: Range<usize>,
        vertices: Range<usize>,
    ) -> (Option<&mut [TriangleRows]>, Option<&mut [TransformedVertex]>, Option<DrawChunks<'_>>) {
        if !self.owned {
            return (None, None, None);
        }
        let chunks = self.summarised.then_some((&self.chunks, triangles.start));
        (self.rows.get_mut(triangles), self.vertices.get_mut(vertices), chunks)
    }

    /// Summarises the rows of the first `triangles` triangles chunk by chunk (see
    /// [`RowChunks`]) once they are all learnt, for the later bands of this frame: called at the
    /// end of each draw, it does so once a frame, after the first. A band that is the whole
    /// frame has no later bands to need them.
    pub(crate) fn summarise_rows(&mut self, triangles: usize, whole_frame: bool) {
        if self.summarised || !self.owned || whole_frame {
            return;
        }
        let learnt = &self.rows[..triangles.min(self.rows.len())];
        for (summary, chunk) in self.chunks.summaries.iter_mut().zip(learnt.chunks(1 << self.chunks.shift)) {
            *summary = chunk.iter().fold(TriangleRows::EMPTY, |all, r| all.union(*r));
        }
        self.summarised = true;
    }

    /// When the owner's draw `d` has its vertices cached, none needing clipping (see
    /// [`Scratch::set_unclipped`]): whether its transform mirrors.
    #[inline]
    pub(crate) fn unclipped(&self, d: usize) -> Option<bool> {
        (self.owned && d < 64 && self.unclipped >> d & 1 != 0).then_some(self.flipped >> d & 1 != 0)
    }

    /// Records that draw `d` filled its vertex cache and none of them needs clipping, and
    /// whether its transform mirrors (`flip`).
    #[inline]
    pub(crate) fn set_unclipped(&mut self, d: usize, flip: bool) {
        if self.owned && d < 64 {
            self.unclipped |= 1 << d;
            self.flipped |= u64::from(flip) << d;
        }
    }

    /// The sort list.
    pub(crate) fn sort_entries(&mut self) -> &mut [SortEntry] {
        self.sort
    }
}

/// How many chunks of neighbouring triangles' rows a [`Scratch`] summarises: chunks of 8
/// triangles up to 512 triangles, of 16 up to 1,024, and so on (256 bytes).
pub(crate) const ROW_CHUNKS: usize = 64;

/// A draw's [`RowChunks`] (once summarised), and where its triangles' rows start among the
/// scratch's (the index that says a triangle's chunk).
pub(crate) type DrawChunks<'s> = (&'s RowChunks, usize);

/// The rows that each chunk of `1 << shift` neighbouring triangles together may touch (the
/// union of theirs): a band tests a chunk whole and skips it when it cannot touch it. A mesh's
/// neighbouring triangles tend to be near each other (exporters keep faces in modelling order):
/// in the reference frame's eighth bands, 3,014 triangle tests and 366 chunk tests instead of
/// 6,762 triangle tests.
pub(crate) struct RowChunks {
    summaries: [TriangleRows; ROW_CHUNKS],
    shift: u8,
}

impl RowChunks {
    /// No summaries yet, for `rows` triangles: the smallest chunks that `ROW_CHUNKS` of cover
    /// them all, of at least 8 triangles.
    fn for_rows(rows: usize) -> Self {
        let shift = (3..usize::BITS - 1).find(|&s| rows >> s < ROW_CHUNKS).unwrap_or(usize::BITS - 1);
        RowChunks { summaries: [TriangleRows::UNKNOWN; ROW_CHUNKS], shift: shift as u8 }
    }

    /// How many triangles from `at` on (an index into the scratch's rows) are in its chunk.
    #[inline(always)]
    pub(crate) fn left_in_chunk(&self, at: usize) -> usize {
        let size = 1 << self.shift;
        size - (at & (size - 1))
    }

    /// Whether the chunk of triangle `at` (an index into the scratch's rows) may touch rows
    /// `row_start..row_end`.
    #[inline(always)]
    pub(crate) fn may_touch(&self, at: usize, row_start: i32, row_end: i32) -> bool {
        self.summaries.get(at >> self.shift).is_none_or(|r| r.may_touch(row_start, row_end))
    }
}

/// One entry of the back-to-front sort list: a triangle and its sort key.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SortEntry {
    pub(crate) key: u32,
    pub(crate) draw: u16,
    pub(crate) triangle: u32,
}

/// The rows a triangle can touch, learnt in the first band that processes it (see
/// [`Scratch`]). `UNKNOWN` until then; `EMPTY` for triangles that draw nothing anywhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriangleRows {
    first: u16,
    last: u16,
}

impl Default for TriangleRows {
    fn default() -> Self {
        Self::UNKNOWN
    }
}

impl TriangleRows {
    /// Not yet seen this frame.
    pub const UNKNOWN: TriangleRows = TriangleRows { first: 0, last: u16::MAX };
    /// Culled: draws nothing in any band.
    pub const EMPTY: TriangleRows = TriangleRows { first: u16::MAX, last: 0 };

    /// Whether the triangle may touch rows `row_start..row_end`: the one band-bounds test of a
    /// triangle's rows.
    #[inline(always)]
    pub(crate) fn may_touch(&self, row_start: i32, row_end: i32) -> bool {
        (self.first as i32) < row_end && (self.last as i32) >= row_start
    }

    /// The rows either may touch.
    #[inline(always)]
    fn union(self, other: TriangleRows) -> TriangleRows {
        TriangleRows { first: self.first.min(other.first), last: self.last.max(other.last) }
    }

    /// Rows `floor(min_y)..=floor(max_y)` of the snapped polygon: a superset of the rows whose
    /// pixel centres it covers and of the rows its wireframe lines and points touch.
    pub(crate) fn of(screen: &[ScreenVertex], height: u16) -> Self {
        let ys = || screen.iter().map(|v| v.y);
        Self::of_ys(ys().min().unwrap_or(0), ys().max().unwrap_or(-1), height)
    }

    /// [`TriangleRows::of`] the lowest and highest y (28.4).
    #[inline(always)]
    pub(crate) fn of_ys(min: FDot4, max: FDot4, height: u16) -> Self {
        Self::of_rows(min >> 4, max >> 4, height)
    }

    /// The rows whose pixel centres lie within the lowest and highest y (28.4): all that a
    /// filled triangle covers (the rasterizer's own rows, see `raster::CoveredBox`), fewer than
    /// [`TriangleRows::of_ys`] (a band that its rows but none of its centres reach skips it).
    #[inline(always)]
    pub(crate) fn of_centres(min: FDot4, max: FDot4, height: u16) -> Self {
        Self::of_rows(first_centre(min), last_centre(max), height)
    }

    /// Rows `first..=last` of a frame `height` rows high, empty when none is in it.
    #[inline(always)]
    fn of_rows(first: i32, last: i32, height: u16) -> Self {
        if last < first.max(0) || first >= height as i32 {
            return Self::EMPTY;
        }
        TriangleRows { first: first.max(0) as u16, last: last.min(height as i32 - 1) as u16 }
    }
}

/// A vertex projected and lit, computed once a frame (see [`Scratch`]): everything an unclipped
/// triangle needs of its corner, in the form the rasterizer takes it, in 28 bytes.
#[derive(Clone, Copy, Debug)]
pub struct TransformedVertex {
    /// Snapped screen position (28.4), when [`Self::outcode`] has no `NEEDS_CLIP`.
    pub(crate) xy: [i16; 2],
    pub(crate) z: f32,
    pub(crate) inv_w: f32,
    /// Texel coordinates (16.16 texels, see `vertex::texel`), when the outcode has no
    /// `NEEDS_CLIP`.
    pub(crate) texel: [FDot16; 2],
    /// Light varyings: red, green and blue light times the vertex colour (see
    /// `vertex::coloured_light`).
    pub(crate) light: [u16; 3],
    /// [`VertexLight`]'s specular / 257.
    specular: u8,
    /// The position's [`outcode`](super::clip::outcode), plus `NEEDS_CLIP` where the position
    /// or texel coordinates do not fit the fields above: a triangle with such a corner takes
    /// the full path (which clips when it must).
    pub(crate) outcode: u8,
}

const _: () = assert!(core::mem::size_of::<TransformedVertex>() == 28);

impl Default for TransformedVertex {
    fn default() -> Self {
        Self::UNKNOWN
    }
}

/// The bound on cached snapped coordinates (28.4): below half the rasterizer's extent, so that
/// any two are less than [`MAX_EXTENT`] apart.
const CACHED_COORD: u32 = (MAX_EXTENT / 2) as u32;

/// The `1/w` of a vertex not transformed yet this frame: +0, so that the empty cache is all zero
/// bytes (`.bss`, not flash).
pub(crate) const UNKNOWN_INV_W: u32 = 0;

impl TransformedVertex {
    /// Not yet transformed this frame.
    pub const UNKNOWN: TransformedVertex = TransformedVertex {
        xy: [0; 2],
        z: 0.0,
        inv_w: f32::from_bits(UNKNOWN_INV_W),
        texel: [0; 2],
        light: [0; 3],
        specular: 0,
        outcode: 0,
    };

    /// The entry of a vertex projected to `p` with texel coordinates `texel` (16.16, and
    /// whether they were finite: see `vertex::cached_texel`), not lit yet ([`Self::set_light`]).
    /// Without `NEEDS_CLIP`, the entry vouches for what the front end would otherwise test per
    /// triangle: any three such corners are [`in_guard_band`](super::raster::in_guard_band)
    /// (each within half its extent of 0) and have positive finite `1/w`s.
    #[inline(always)]
    pub(crate) fn new(p: Projected, (texel, texel_finite): ([FDot16; 2], bool)) -> Self {
        let near = |c: FDot4| c.unsigned_abs() < CACHED_COORD;
        // `&`, not `&&`: no branches.
        let fits = near(p.x) & near(p.y) & crate::math::is_positive_finite(p.inv_w) & texel_finite;
        TransformedVertex {
            // Within `CACHED_COORD` < 2^15 when `fits` (else unused): the casts are exact.
            xy: [p.x as i16, p.y as i16],
            z: p.z,
            inv_w: p.inv_w,
            texel,
            light: [0; 3],
            specular: 0,
            outcode: p.outcode | if fits { 0 } else { NEEDS_CLIP },
        }
    }

    /// Sets its light varyings.
    #[inline(always)]
    pub(crate) fn set_light(&mut self, [r, g, b, specular]: VertexLight) {
        (self.light, self.specular) = ([r, g, b], (specular / 257) as u8);
    }

    /// This vertex on the screen with its texel coordinates and the light varyings `light`.
    #[inline(always)]
    pub(crate) fn screen_vertex(&self, light: VertexLight) -> ScreenVertex {
        let (x, y) = (i32::from(self.xy[0]), i32::from(self.xy[1]));
        ScreenVertex { x, y, z: self.z, inv_w: self.inv_w, varyings: vertex_lit_varyings(self.texel, light) }
    }

    /// Its light varyings, with the specular intensity (a multiple of 257).
    #[inline(always)]
    pub(crate) fn light(&self) -> VertexLight {
        let [r, g, b] = self.light;
        [r, g, b, self.specular as u16 * 257]
    }

    /// The light of the triangle corner `k` that this vertex is: flat shading's for that
    /// corner when given, else the vertex's own.
    #[inline(always)]
    pub(crate) fn corner_light(&self, flat: Option<&[VertexLight; 3]>, k: usize) -> VertexLight {
        flat.map_or_else(|| self.light(), |l| l[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(first: u16, last: u16) -> TriangleRows {
        TriangleRows { first, last }
    }

    /// Chunks of 8 rows (the least), each summarised as the union of its triangles' rows (an
    /// empty triangle adds nothing), and a draw's part of them tested chunk by chunk.
    #[test]
    fn chunks_summarise_the_rows_of_their_triangles() {
        let mut learnt = [TriangleRows::UNKNOWN; 20];
        let mut scratch = Scratch::none().with_rows(&mut learnt[..]);
        scratch.claim(Owner(1));
        // What a first band learns.
        let draw = scratch.for_draw(0..20, 0..0).0.unwrap();
        draw.fill(TriangleRows::EMPTY);
        for (t, r) in [(2, rows(10, 12)), (5, rows(40, 41)), (9, rows(100, 120)), (19, rows(0, 3))] {
            draw[t] = r;
        }
        // Not until a band that is not the whole frame has drawn.
        scratch.summarise_rows(20, true);
        assert!(scratch.for_draw(0..20, 0..0).2.is_none());
        scratch.summarise_rows(20, false);
        assert_eq!(scratch.chunks.shift, 3);
        assert_eq!(scratch.chunks.summaries[..3], [rows(10, 41), rows(100, 120), rows(0, 3)]);
        assert_eq!(scratch.chunks.summaries[3], TriangleRows::UNKNOWN);
        let (chunks, at) = scratch.for_draw(4..20, 0..0).2.unwrap();
        assert_eq!(at, 4);
        // Triangle 8's chunk (8..16) touches rows 100..=120 only.
        assert!(!chunks.may_touch(8, 0, 100) && chunks.may_touch(8, 120, 121) && !chunks.may_touch(8, 121, 200));
        assert!(chunks.may_touch(19, 3, 4) && !chunks.may_touch(19, 4, 200));
        // Beyond the summaries (a scratch larger than they cover): never skipped.
        assert!(chunks.may_touch(usize::MAX, 0, 1));
    }

    /// Another owner's draw gets no rows, and so no chunks.
    #[test]
    fn chunks_are_the_owners_alone() {
        let mut learnt = [TriangleRows::EMPTY; 8];
        let mut scratch = Scratch::none().with_rows(&mut learnt[..]);
        scratch.claim(Owner(1));
        scratch.summarise_rows(8, false);
        scratch.claim(Owner(2));
        assert!(scratch.for_draw(0..8, 0..0).0.is_none() && scratch.for_draw(0..8, 0..0).2.is_none());
        scratch.new_frame();
        scratch.claim(Owner(2));
        assert!(scratch.for_draw(0..8, 0..0).0.is_some() && scratch.for_draw(0..8, 0..0).2.is_none());
    }
}
