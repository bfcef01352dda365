//! Painter's algorithm: every triangle of a model sorted back to front by its farthest vertex,
//! then drawn in that order (for boards without RAM for a depth buffer). It does not transform
//! for drawing or rasterize (`primitive` and `raster` do, as for every order).

use super::posed::draw_world;
use super::primitive::{common_cache, draw_triangle, Surface};
use super::{Context, DrawError, DrawSetup, Scratch, SortEntry, Stats, Transforms};
use crate::format::Model;
use crate::math::Mat4;
use crate::target::{Band, DepthBuffer, FrameColor};

/// [`DrawOrder::BackToFront`](super::DrawOrder::BackToFront): sorts every triangle back to
/// front by its farthest vertex in the scratch's sort list, then draws them in that order.
pub(crate) fn draw_back_to_front<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    model: &Model<'_>,
    transform: Mat4,
    ctx: &Context<'_, L>,
    scratch: &mut Scratch<'_>,
) -> Result<Stats, DrawError> {
    let scratch = scratch.sort_entries();
    // Saturating: instances can pass `usize::MAX` on a 32-bit target, which no scratch holds.
    let needed = model.draws().fold(0usize, |n, (m, _)| n.saturating_add(m.triangle_count() as usize));
    if scratch.len() < needed || model.draws().count() > u16::MAX as usize {
        return Err(DrawError::ScratchTooSmall { needed, given: scratch.len() });
    }
    let vp = ctx.frame.vp;
    let mut n = 0;
    for (d, (mesh, world)) in model.placed_draws().enumerate() {
        let world = draw_world(ctx.frame.posed.as_ref(), model, d, world);
        let mvp = vp * transform * world * mesh.dequantize();
        for t in 0..mesh.triangle_count() {
            let w = mesh.triangle(t).map(|i| (mvp * mesh.position_stored(i).extend(1.0)).w);
            let far = w[0].max(w[1]).max(w[2]);
            // Positive floats order like their bits; NaN and negatives sort as nearest.
            let key = if far > 0.0 { far.to_bits() } else { 0 };
            scratch[n] = SortEntry { key, draw: d as u16, triangle: t };
            n += 1;
        }
    }
    let list = &mut scratch[..n];
    list.sort_unstable_by_key(|e| core::cmp::Reverse(e.key));
    let mut stats = Stats::default();
    // One draw's run of triangles at a time, with that draw's transforms.
    for run in list.chunk_by(|a, b| a.draw == b.draw) {
        let Some((d, (mesh, world))) =
            run.first().and_then(|e| Some((e.draw as usize, model.placed_draw(e.draw as usize)?)))
        else {
            continue;
        };
        let place = || transform * draw_world(ctx.frame.posed.as_ref(), model, d, world);
        let Some((placed, flip)) = Transforms::placement(ctx, &mesh, place, false) else {
            continue;
        };
        let deforming = ctx.frame.posed.as_ref().and_then(|p| p.deforming(model, mesh.mesh_index()));
        let transforms = Transforms::new(ctx, &mesh, &placed, deforming.as_ref());
        let mut setup = DrawSetup::new(mesh, &transforms, flip);
        if let Some(deforming) = &deforming {
            setup.arrays = setup.arrays.morphed(deforming);
        }
        let setup = &setup;
        for e in run {
            stats.triangles_submitted = stats.triangles_submitted.saturating_add(1);
            let sub = setup
                .mesh
                .submeshes()
                .find(|s| (s.first_triangle..s.first_triangle + s.triangle_count).contains(&e.triangle));
            let material = sub.and_then(|s| s.material).and_then(|m| model.material(m)).unwrap_or_default();
            let sampler = ctx.sampler(model, &setup.mesh, &material);
            let surface = Surface::new(&material, sampler.as_ref(), ctx, setup);
            let common = common_cache(ctx, setup);
            let _ = draw_triangle(
                band,
                ctx,
                (setup, common),
                (e.triangle, setup.arrays.triangle(e.triangle), None),
                (&surface, None),
                &mut stats,
            );
        }
    }
    Ok(stats)
}
