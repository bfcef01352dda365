//! Drawing a frame: its bands shared among threads, in the pixel format asked for, and the
//! framebuffer's bytes for raw output.

use super::*;

/// A rendered frame: its pixels widened to RGB888 (for PNG and GIF), the framebuffer's own
/// bytes (for raw output, when asked for) and what the draw counted.
pub(crate) struct Frame {
    pub(crate) rgb: Vec<[u8; 3]>,
    pub(crate) raw: Vec<u8>,
    pub(crate) stats: Stats,
}

/// A pixel format the CLI renders into, and how its framebuffer is written to a raw file.
pub(crate) trait RawPixels: FrameColor + Default + Send {
    /// `pixels`, rows of `width`, as the bytes of a raw file.
    fn raw(pixels: &[Self], width: usize) -> Vec<u8>;
}

impl RawPixels for Rgb888 {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        pixels.iter().flat_map(|c| c.to_rgb888()).collect()
    }
}

impl RawPixels for Rgb565 {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        use embedded_graphics_core::prelude::IntoStorage;
        pixels.iter().flat_map(|c| c.into_storage().to_le_bytes()).collect()
    }
}

impl RawPixels for Rgb565Be {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        pixels.iter().flat_map(|c| c.0).collect()
    }
}

impl RawPixels for Gray8 {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        pixels.iter().map(|c| c.to_rgb888()[0]).collect()
    }
}

impl RawPixels for BinaryColor {
    fn raw(pixels: &[Self], width: usize) -> Vec<u8> {
        let mut out = Vec::with_capacity(pixels.len().div_ceil(8));
        for row in pixels.chunks(width) {
            out.extend(
                row.chunks(8)
                    .map(|byte| byte.iter().enumerate().fold(0u8, |b, (i, c)| b | (u8::from(c.is_on()) << (7 - i)))),
            );
        }
        out
    }
}

/// The caller's depth memory for a frame, of the kind `--depth` asks for.
pub(crate) enum Depth {
    U16(Vec<u16>),
    F32(Vec<f32>),
    None,
}

/// One thread's share of a frame: its rows' colour and depth memory.
pub(crate) enum DepthRows<'a> {
    U16(&'a mut [u16]),
    F32(&'a mut [f32]),
    None,
}

impl Depth {
    fn new(kind: DepthKind, pixels: usize) -> Self {
        match kind {
            DepthKind::U16 => Depth::U16(vec![0; pixels]),
            DepthKind::F32 => Depth::F32(vec![0.0; pixels]),
            DepthKind::None => Depth::None,
        }
    }

    /// The depth memory in parts of `part` pixels (the last may be shorter), `parts` of them.
    fn split(&mut self, part: usize, parts: usize) -> Vec<DepthRows<'_>> {
        match self {
            Depth::U16(z) => z.chunks_mut(part).map(DepthRows::U16).collect(),
            Depth::F32(z) => z.chunks_mut(part).map(DepthRows::F32).collect(),
            Depth::None => (0..parts).map(|_| DepthRows::None).collect(),
        }
    }
}

/// One band of a frame: its first row, its colour and depth memory, and its pixels widened.
pub(crate) struct BandRows<'a, C> {
    pub(crate) first_row: u16,
    pub(crate) color: &'a mut [C],
    pub(crate) depth: DepthRows<'a>,
    pub(crate) rgb: &'a mut [[u8; 3]],
}

/// Renders one frame in pixel format `C`, its bands dealt out among the view's threads in turn
/// (band k to thread k mod n: a scene's busy rows are shared), each band drawn whole by one
/// thread, so the picture is the one a single thread draws; the raw bytes only when `raw`.
pub(crate) fn render_frame<C: RawPixels>(
    model: &Model<'_>,
    view: &View,
    spin: f32,
    (depth, raw): (DepthKind, bool),
) -> Result<Frame> {
    // The scene's camera and lights at the frame, once for every band.
    let view = &posed_view(view, model)?;
    let (w, h) = (view.width as usize, view.height as usize);
    let mut color = vec![C::default(); w * h];
    let mut depth = Depth::new(depth, w * h);
    let mut rgb = vec![[0u8; 3]; w * h];
    let band_rows = h.div_ceil(view.bands as usize);
    let band = band_rows * w;
    let depth_parts = depth.split(band, h.div_ceil(band_rows));
    let mut shares: Vec<Vec<BandRows<'_, C>>> = (0..view.threads).map(|_| Vec::new()).collect();
    let bands = color.chunks_mut(band).zip(depth_parts).zip(rgb.chunks_mut(band));
    for (k, ((color, depth), rgb)) in bands.enumerate() {
        let first_row = (k * band_rows) as u16;
        shares[k % view.threads as usize].push(BandRows { first_row, color, depth, rgb });
    }
    let transform = soft3d::testing::math::Mat4::from_rotation_y(spin);
    let results: Vec<Result<Stats>> = std::thread::scope(|scope| {
        let threads: Vec<_> =
            shares.into_iter().map(|share| scope.spawn(move || draw_bands(share, view, (model, transform)))).collect();
        threads.into_iter().map(|t| t.join().unwrap_or_else(|_| Err("a render thread panicked".into()))).collect()
    });
    let mut stats = Stats::default();
    for s in results {
        stats += s?;
    }
    let raw = if raw { C::raw(&color, w) } else { Vec::new() };
    Ok(Frame { rgb, raw, stats })
}

/// Draws `bands` and widens their pixels: one thread's share of [`render_frame`].
pub(crate) fn draw_bands<C: FrameColor>(
    bands: Vec<BandRows<'_, C>>,
    view: &View,
    scene: (&Model<'_>, soft3d::testing::math::Mat4),
) -> Result<Stats> {
    // The back-to-front list, one entry a triangle, when the order needs it; otherwise each
    // triangle's rows and each transformed vertex, so that the thread's bands after its first
    // skip the triangles that miss them and transform no vertex again.
    let (triangles, vertices) = scene.0.draw_counts();
    let sorted = view.opts.order == DrawOrder::BackToFront;
    let mut sort = vec![SortEntry::default(); if sorted { triangles } else { 0 }];
    let mut rows = vec![soft3d::TriangleRows::default(); if sorted { 0 } else { triangles }];
    let mut cache = vec![soft3d::TransformedVertex::default(); if sorted { 0 } else { vertices }];
    let mut scratch = Scratch::none().with_sort(&mut sort).with_rows(&mut rows).with_vertices(&mut cache);
    // The pose, once a thread: every band draws the same.
    let animation = scene.0.animation().filter(|_| view.pose.is_some());
    let (nodes, weights) =
        animation.map_or((0, 0), |a| pose_memory(a.node_count(), a.palette_count(), a.weight_count()));
    let (mut node_memory, mut weight_memory) = (vec![Mat4::IDENTITY; nodes], vec![0.0f32; weights]);
    let mut pose = Pose::new(&mut node_memory, &mut weight_memory);
    if let (Some(a), Some((frame, group))) = (animation, view.pose) {
        pose.evaluate(&a, frame, group).map_err(|e| format!("--frame: {e}"))?;
    }
    let scene = (scene.0, scene.1, &pose);
    let bg = C::from_rgb888(view.background);
    let mut stats = Stats::default();
    for b in bands {
        let at = b.first_row;
        stats += match b.depth {
            DepthRows::U16(z) => draw_band((&mut *b.color, z), view, at, scene, bg, &mut scratch)?,
            DepthRows::F32(z) => draw_band((&mut *b.color, z), view, at, scene, bg, &mut scratch)?,
            DepthRows::None => draw_band((&mut *b.color, NoDepth), view, at, scene, bg, &mut scratch)?,
        };
        for (out, c) in b.rgb.iter_mut().zip(b.color.iter()) {
            *out = c.to_rgb888();
        }
    }
    Ok(stats)
}

pub(crate) fn draw_band<C: FrameColor, D: DepthBuffer>(
    (color, depth): (&mut [C], D),
    view: &View,
    first_row: u16,
    (model, transform, pose): (&Model<'_>, soft3d::testing::math::Mat4, &Pose<'_>),
    bg: C,
    scratch: &mut Scratch<'_>,
) -> Result<Stats> {
    let mut band = Band::new(color, depth, view.width, view.height, first_row).map_err(|e| e.to_string())?;
    band.clear(bg);
    soft3d::Renderer::new(&view.camera, &view.lights, view.opts)
        .draw_posed(&mut band, model, pose, transform, scratch)
        .map_err(|e| format!("draw: {e}"))
}

pub(crate) fn render_any(model: &Model<'_>, view: &View, spin: f32, args: &RenderArgs, raw: bool) -> Result<Frame> {
    let how = (args.depth, raw);
    match args.format {
        PixelFormat::Rgb888 => render_frame::<Rgb888>(model, view, spin, how),
        PixelFormat::Rgb565 => render_frame::<Rgb565>(model, view, spin, how),
        PixelFormat::Rgb565Be => render_frame::<Rgb565Be>(model, view, spin, how),
        PixelFormat::Gray8 => render_frame::<Gray8>(model, view, spin, how),
        PixelFormat::Mono => render_frame::<BinaryColor>(model, view, spin, how),
    }
}

/// What `-o` writes, by its extension.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum OutputKind {
    Png,
    Raw,
    Gif,
}

pub(crate) fn output_kind(path: &Path) -> Result<OutputKind> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(OutputKind::Png),
        Some("raw" | "bin") => Ok(OutputKind::Raw),
        Some("gif") => Ok(OutputKind::Gif),
        _ => Err(format!(
            "-o: name the output *.png (a PNG picture), *.raw or *.bin (the framebuffer's bytes) or *.gif (the turntable), got {:?}",
            path.display()
        )),
    }
}
