//! A band's loops over a mesh's triangles: the first band to draw them tests and draws every
//! one and learns the rows it can touch (into the [`Scratch`](super::Scratch)); the later bands
//! draw only those whose rows touch theirs; a draw without a row cache draws them all. It does
//! not test or draw a triangle itself (`primitive` does).

use core::ops::Range;

use super::primitive::{common_cache, draw_triangle, Common, Learnt, Surface};
use super::scratch::DrawChunks;
use super::{fragment, Context, DrawSetup, Stats, TransformedVertex, TriangleRows};
use crate::format::U16Triangles;
use crate::target::{Band, DepthBuffer, FrameColor};

/// Draws triangles `range` of draw `s` in `band`, with `seen` the rows the draw's row cache
/// holds for them (see [`Scratch`](super::Scratch)), when it has them.
#[inline(always)]
pub(super) fn draw_range<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    (range, seen): (Range<u32>, Option<&mut [TriangleRows]>),
    (surface, variant): (&Surface<'_, '_>, Option<fragment::Variant<C, D, L>>),
    stats: &mut Stats,
) {
    match seen {
        // The first band to draw them: every triangle is tested and drawn, learning its rows.
        Some(seen) if seen.first() == Some(&TriangleRows::UNKNOWN) => {
            draw_first_band(band, ctx, s, (seen, range.start), (surface, variant), stats);
        }
        Some(seen) => {
            let band_rows = (ctx.window.row_start, ctx.window.row_end);
            let touched = match Later::new(band, ctx, s, (surface, variant)) {
                Some(mut later) => {
                    draw_touching((seen, &s.chunks), range.start, band_rows, stats, &mut |t, r, stats| {
                        later.draw(t, r, stats)
                    })
                }
                None => {
                    let mut draw =
                        |t, r, stats: &mut Stats| draw_one(band, ctx, s, (t, learnt(r)), (surface, variant), stats);
                    draw_touching((seen, &s.chunks), range.start, band_rows, stats, &mut draw)
                }
            };
            stats.outside_band += range.len() as u32 - touched;
        }
        None => range.for_each(|t| {
            draw_one(band, ctx, s, (t, None), (surface, variant), stats);
        }),
    }
}

/// Draws (with `draw`) the triangles from `first` on whose rows `seen` may touch rows
/// `start..end`, learning their rows, and returns how many. In a band of a frame of many, most
/// triangles are skipped: the triangles drawn are counted, not the ones skipped, so that loop
/// is the test alone. A chunk of triangles whose summary (see
/// [`RowChunks`](super::scratch::RowChunks)) misses the band is skipped whole. Inlined into
/// `draw_submesh`, and [`Later::draw_learnt`] into the per-triangle closure that `draw_range`
/// hands it (which LLVM keeps out of line, 88 bytes): before, the frames of this function and
/// of `draw_learnt` (96 + 88 bytes) lay under every later band's triangle (the deepest stack;
/// the same instructions).
#[inline(always)]
fn draw_touching(
    (seen, chunks): (&mut [TriangleRows], &Option<DrawChunks<'_>>),
    first: u32,
    band_rows: (i32, i32),
    stats: &mut Stats,
    draw: &mut impl FnMut(u32, TriangleRows, &mut Stats) -> TriangleRows,
) -> u32 {
    let Some((chunks, draw_at)) = *chunks else {
        return draw_touching_each(seen, first, band_rows, stats, draw);
    };
    // `seen[0]`'s index among the scratch's rows, which says its chunk.
    let (mut rows, mut t, mut at) = (seen, first, draw_at.wrapping_add(first as usize));
    let mut touched = 0;
    while !rows.is_empty() {
        // To the end of `at`'s chunk, or of the rows.
        let len = chunks.left_in_chunk(at).min(rows.len());
        let (chunk, rest) = rows.split_at_mut(len);
        if chunks.may_touch(at, band_rows.0, band_rows.1) {
            touched += draw_touching_each(chunk, t, band_rows, stats, draw);
        }
        (rows, t, at) = (rest, t.wrapping_add(len as u32), at + len);
    }
    touched
}

/// [`draw_touching`] of rows `seen`, testing every triangle.
#[inline(always)]
fn draw_touching_each(
    seen: &mut [TriangleRows],
    first: u32,
    (start, end): (i32, i32),
    stats: &mut Stats,
    draw: &mut impl FnMut(u32, TriangleRows, &mut Stats) -> TriangleRows,
) -> u32 {
    let mut touched = 0;
    let mut visit = |r: &mut TriangleRows, t: u32, stats: &mut Stats| {
        if r.may_touch(start, end) {
            *r = draw(t, *r, stats);
            touched += 1;
        }
    };
    // Two triangles a step: the loop's own instructions (pointer, count, branch) once for both
    // (Cortex-M4F, 8 bands: -15.5k instructions a frame).
    let (pairs, last) = seen.as_chunks_mut::<2>();
    let mut t = first;
    for [a, b] in pairs {
        visit(a, t, stats);
        visit(b, t.wrapping_add(1), stats);
        t = t.wrapping_add(2);
    }
    for r in last {
        visit(r, t, stats);
    }
    touched
}

/// What a row cache's entry `rows` says of its triangle: its rows when learnt (see [`Learnt`]).
#[inline(always)]
fn learnt(rows: TriangleRows) -> Option<Learnt> {
    (rows != TriangleRows::UNKNOWN).then_some(Learnt(rows))
}

/// [`draw_triangle`] out of line: for [`draw_touching`] (whose loop, skipping the triangles a
/// band does not touch, stays small) where [`Later`] does not draw or the rows are not
/// learnt, draws without a row cache, and the first band's other cases.
#[inline(never)]
fn draw_one<'c, C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    s: &DrawSetup<'c, L>,
    t: (u32, Option<Learnt>),
    surface: (&Surface<'_, '_>, Option<fragment::Variant<C, D, L>>),
    stats: &mut Stats,
) -> TriangleRows {
    let (t, learnt) = t;
    draw_triangle(band, ctx, (s, common_cache(ctx, s)), (t, s.arrays.triangle(t), learnt), surface, stats)
}

/// Draws the triangles from `first` on in the first band that draws them, every one of them
/// (their rows `seen` not known yet), and learns their rows. Out of line: the loop's values in
/// a frame of its own, not among its caller's.
#[inline(never)]
fn draw_first_band<'c, C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    s: &DrawSetup<'c, L>,
    (seen, first): (&mut [TriangleRows], u32),
    surface: (&Surface<'_, '_>, Option<fragment::Variant<C, D, L>>),
    stats: &mut Stats,
) {
    // The common case inlined, so that a culled triangle costs no call (Cortex-M4F reference
    // frame -23k instructions against `draw_one`), its tests of the vertex cache and of the
    // index width made once, not in the loop (-23k more; thumbv6m -74k, where the inlined loop
    // with those tests in it cost 17k more than `draw_one`).
    let common = common_cache(ctx, s).filter(|_| s.arrays.u16_triangles().is_some());
    if let Some(cache) = common {
        for (t, r) in (first..).zip(seen) {
            let idx = s.arrays.triangle(t);
            *r = draw_triangle(band, ctx, (s, Some(cache)), (t, idx, None), surface, stats);
        }
    } else {
        for (t, r) in (first..).zip(seen) {
            *r = draw_one(band, ctx, s, (t, None), surface, stats);
        }
    }
}

/// The later bands' common case: a draw whose triangles fill from the vertex cache with 16-bit
/// indices, not flat shaded, with the surface's variant. What a triangle's draw needs, tested
/// once a band instead of once a triangle, behind one reference: [`Later::draw`] takes it and
/// a triangle, not a dozen arguments (Cortex-M4F, 8 bands: -15.5k instructions a frame against
/// [`draw_one`]).
struct Later<'b, 'a, 'c, C: FrameColor, D: DepthBuffer, const L: usize> {
    band: &'b mut Band<'a, C, D>,
    ctx: &'b Context<'b, L>,
    s: &'b DrawSetup<'c, L>,
    cache: &'c [TransformedVertex],
    indices: U16Triangles<'c>,
    surface: &'b Surface<'b, 'b>,
    variant: fragment::Variant<C, D, L>,
}

impl<'b, 'a, 'c, C: FrameColor, D: DepthBuffer, const L: usize> Later<'b, 'a, 'c, C, D, L> {
    /// The common case of draw `s` in `band`, when it is one.
    #[inline(always)]
    fn new(
        band: &'b mut Band<'a, C, D>,
        ctx: &'b Context<'b, L>,
        s: &'b DrawSetup<'c, L>,
        (surface, variant): (&'b Surface<'b, 'b>, Option<fragment::Variant<C, D, L>>),
    ) -> Option<Self> {
        let cache = common_cache(ctx, s).filter(|c| !c.flat)?.cache;
        Some(Later { band, ctx, s, cache, indices: s.arrays.u16_triangles()?, surface, variant: variant? })
    }

    /// [`draw_triangle`] of triangle `t`, whose row cache entry is `rows`, in the common case:
    /// [`Later::draw_learnt`] when an earlier band learnt its rows, else [`draw_one`] (which
    /// tests it all).
    #[inline(always)]
    fn draw(&mut self, t: u32, rows: TriangleRows, stats: &mut Stats) -> TriangleRows {
        match learnt(rows) {
            Some(learnt) => self.draw_learnt(t, learnt, stats),
            None => draw_one(self.band, self.ctx, self.s, (t, None), (self.surface, Some(self.variant)), stats),
        }
    }

    /// [`draw_triangle`] of triangle `t`, whose rows an earlier band `learnt` (inlined into
    /// [`Later::draw`]: see [`draw_touching`]).
    #[inline(always)]
    fn draw_learnt(&mut self, t: u32, learnt: Learnt, stats: &mut Stats) -> TriangleRows {
        let surface = (self.surface, Some(self.variant));
        let idx = self.indices.triangle(t).unwrap_or_else(|| self.s.arrays.triangle(t));
        // Not flat shaded (as `new` found): the fill without that test (-3.7k).
        let common = Common { cache: self.cache, flat: false };
        draw_triangle(self.band, self.ctx, (self.s, Some(common)), (t, idx, Some(learnt)), surface, stats)
    }
}
