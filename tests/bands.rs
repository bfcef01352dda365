//! Rendering a frame in bands of any height gives exactly the pixels of the whole frame.
use embedded_graphics_core::pixelcolor::Rgb888;
use soft3d::convert::{emit, EmitOptions};
use soft3d::testing::math::Mat4;
use soft3d::Model;
use soft3d::{Band, Camera, Lights, Mode, NoDepth, RenderOptions, Shading, TransformedVertex, TriangleRows, Vec3};
use soft3d::{DrawError, DrawOrder, Renderer, Scratch, SortEntry};

mod common;
use common::{scene, ASSETS};
const W: u16 = 240;
const H: u16 = 240;

fn model_bytes(rel: &str) -> Vec<u8> {
    emit(&scene(rel), &EmitOptions::default()).unwrap()
}

fn camera(model: &Model<'_>) -> Camera {
    let aspect = W as f32 / H as f32;
    match model.camera() {
        Some(c) => Camera::from_scene(&c, aspect).unwrap(),
        None => Camera::framing(model, 0.8, aspect).unwrap(),
    }
}

/// Renders the frame in bands of `rows` rows (the last may be shorter): colour and u16 depth.
/// Bands use a [`Scratch`]: with every vertex cached for 1-row bands, without a vertex cache
/// for 7 rows, and with a vertex cache one entry short (the last draw goes uncached) for others.
fn render(model: &Model<'_>, opts: &RenderOptions, rows: u16) -> (Vec<Rgb888>, Vec<u16>) {
    render_with(model, &camera(model), opts, rows)
}

/// [`render`] with the camera `cam`.
fn render_with(model: &Model<'_>, cam: &Camera, opts: &RenderOptions, rows: u16) -> (Vec<Rgb888>, Vec<u16>) {
    let (w, h) = (W as usize, H as usize);
    let mut color = vec![Rgb888::new(0, 0, 0); w * h];
    let mut depth = vec![0u16; w * h];
    let lights = Lights::<4>::from_model(model);
    let spin = Mat4::from_rotation_y(0.3);
    let (triangles, vertices) =
        model.draws().fold((0, 0), |(t, v), (m, _)| (t + m.triangle_count() as usize, v + m.vertex_count() as usize));
    assert_eq!(model.draw_counts(), (triangles, vertices));
    let mut seen = vec![TriangleRows::default(); triangles];
    let mut transformed = vec![TransformedVertex::default(); vertices];
    let mut cache = match rows {
        1 => Scratch::none().with_rows(&mut seen).with_vertices(&mut transformed),
        7 => Scratch::none().with_rows(&mut seen),
        _ => Scratch::none().with_rows(&mut seen).with_vertices(&mut transformed[1..]),
    };
    for (k, (c, z)) in color.chunks_mut(rows as usize * w).zip(depth.chunks_mut(rows as usize * w)).enumerate() {
        let mut band = Band::new(c, z, W, H, k as u16 * rows).unwrap();
        band.clear(Rgb888::new(10, 20, 30));
        // The whole frame uses no scratch, bands the row cache: both must agree.
        if rows == H {
            soft3d::Renderer::new(cam, &lights, *opts)
                .draw(&mut band, model, spin, &mut soft3d::Scratch::none())
                .unwrap();
        } else {
            soft3d::Renderer::new(cam, &lights, *opts).draw(&mut band, model, spin, &mut cache).unwrap();
        }
    }
    (color, depth)
}

#[test]
fn bands_equal_the_whole_frame_for_every_asset() {
    // The binary Opaque has the same geometry as Opaque (tests/format.rs): skip the duplicate.
    for rel in ASSETS.iter().filter(|r| !r.contains(".binary.")) {
        let bytes = model_bytes(rel);
        let model = Model::parse(&bytes).unwrap();
        let opts = RenderOptions::default();
        let whole = render(&model, &opts, H);
        let drawn = whole.1.iter().filter(|&&d| d != u16::MAX).count();
        assert!(drawn > 100, "{rel}: only {drawn} pixels drawn: the test would prove nothing");
        for rows in [1, 7, 16] {
            assert!(render(&model, &opts, rows) == whole, "{rel}: bands of {rows} rows differ");
        }
    }
}

#[test]
fn bands_equal_the_whole_frame_in_every_mode() {
    let bytes = model_bytes("suzanne/monkey.babylon");
    let model = Model::parse(&bytes).unwrap();
    for shading in [Shading::Unlit, Shading::Flat, Shading::Gouraud, Shading::Phong] {
        for mode in [Mode::Solid, Mode::Wireframe, Mode::Points, Mode::SolidWireframe] {
            for subspan in [1, 8] {
                let opts = RenderOptions { shading, mode, subspan, dither: true, ..Default::default() };
                let whole = render(&model, &opts, H);
                for rows in [1, 7, 16] {
                    assert!(render(&model, &opts, rows) == whole, "{shading:?} {mode:?} {subspan}: bands of {rows}");
                }
            }
        }
    }
}

/// With the near plane through the model, later bands draw clipped triangles from the same
/// vertex cache: they must still work the draw's transforms out (bands skip them only for
/// draws whose cached vertices need no clipping), in every shading and with the fixed-point
/// vertices too.
#[test]
fn bands_equal_the_whole_frame_with_the_near_plane_through_the_model() {
    let bytes = model_bytes("suzanne/monkey.babylon");
    let model = Model::parse(&bytes).unwrap();
    let (centre, radius) = model.bounds().unwrap();
    let eye = centre + Vec3::new(0.3, 0.2, 2.0 * radius);
    let cam =
        Camera::perspective(eye, centre, 0.8, W as f32 / H as f32, 2.0 * radius - 0.3 * radius, 10.0 * radius).unwrap();
    let lights = Lights::<4>::from_model(&model);
    for shading in [Shading::Flat, Shading::Gouraud] {
        for fixed_vertices in [false, true] {
            let opts = RenderOptions { shading, fixed_vertices, ..Default::default() };
            let mut color = vec![Rgb888::new(0, 0, 0); W as usize * H as usize];
            let mut band = Band::new(&mut color[..], NoDepth, W, H, 0).unwrap();
            let stats = Renderer::new(&cam, &lights, opts)
                .draw(&mut band, &model, Mat4::from_rotation_y(0.3), &mut Scratch::none())
                .unwrap();
            assert!(stats.clipped > 10 && stats.drawn > 100, "{shading:?}: nothing to prove: {stats:?}");
            let whole = render_with(&model, &cam, &opts, H);
            for rows in [1, 16] {
                assert!(
                    render_with(&model, &cam, &opts, rows) == whole,
                    "{shading:?} {fixed_vertices}: bands of {rows}"
                );
            }
        }
    }
}

#[test]
fn painters_mode_bands_match_and_cover_like_the_depth_buffer() {
    let bytes = model_bytes("suzanne/monkey.babylon");
    let model = Model::parse(&bytes).unwrap();
    let cam = camera(&model);
    let lights = Lights::<4>::from_model(&model);
    let opts = RenderOptions::default();
    let painter = Renderer::new(&cam, &lights, RenderOptions { order: DrawOrder::BackToFront, ..opts });
    let mut entries = vec![SortEntry::default(); 966];
    let mut scratch = Scratch::none().with_sort(&mut entries);
    let mut paint = |rows: u16| {
        let mut color = vec![Rgb888::new(0, 0, 0); W as usize * H as usize];
        for (k, c) in color.chunks_mut(rows as usize * W as usize).enumerate() {
            let mut band = Band::new(c, NoDepth, W, H, k as u16 * rows).unwrap();
            band.clear(Rgb888::new(10, 20, 30));
            painter.draw(&mut band, &model, Mat4::IDENTITY, &mut scratch).unwrap();
        }
        color
    };
    let whole = paint(H);
    assert!(paint(16) == whole);
    // Same silhouette as the z-buffered frame, and most pixels agree (painter's errors are local).
    let mut zcolor = vec![Rgb888::new(0, 0, 0); W as usize * H as usize];
    let mut depth = vec![0u16; W as usize * H as usize];
    let mut band = Band::new(&mut zcolor[..], &mut depth[..], W, H, 0).unwrap();
    band.clear(Rgb888::new(10, 20, 30));
    soft3d::Renderer::new(&cam, &lights, opts)
        .draw(&mut band, &model, Mat4::IDENTITY, &mut soft3d::Scratch::none())
        .unwrap();
    let bg = Rgb888::new(10, 20, 30);
    let silhouette = whole.iter().zip(&zcolor).filter(|(a, b)| (**a == bg) != (**b == bg)).count();
    let same = whole.iter().zip(&zcolor).filter(|(a, b)| a == b && **a != bg).count();
    let covered = zcolor.iter().filter(|c| **c != bg).count();
    assert_eq!(silhouette, 0);
    assert!(same * 100 >= covered * 95, "{same} of {covered} agree");
    // Too small a scratch slice is an error, not a partial frame.
    let mut small = vec![SortEntry::default(); 10];
    let mut color = vec![Rgb888::new(0, 0, 0); W as usize * H as usize];
    let mut band = Band::new(&mut color[..], NoDepth, W, H, 0).unwrap();
    let result = painter.draw(&mut band, &model, Mat4::IDENTITY, &mut Scratch::none().with_sort(&mut small));
    assert_eq!(result, Err(DrawError::ScratchTooSmall { needed: 966, given: 10 }));
}

/// A scratch's rows and vertices belong to one model drawn one way: a second draw with the same
/// scratch in a frame (the same model moved, another model, other options or lights) draws what
/// it draws with a fresh scratch, not the first draw's cached vertices.
#[test]
fn a_scratch_reused_for_another_draw_in_the_frame_changes_nothing() {
    let suzanne = model_bytes("suzanne/monkey.babylon");
    let teapot = model_bytes("teapot/teapot.babylon");
    let (suzanne, teapot) = (Model::parse(&suzanne).unwrap(), Model::parse(&teapot).unwrap());
    let cam = camera(&suzanne);
    let lights = Lights::<4>::from_model(&suzanne);
    let dim = Lights::<4>::new(Vec3::splat(0.3));
    let opts = RenderOptions::default();
    let flat = RenderOptions { shading: Shading::Flat, ..opts };
    let turned = Mat4::from_rotation_y(1.0);
    let draw = |scratch: &mut Scratch<'_>, model: &Model<'_>, lights: &Lights<4>, opts, t| {
        let mut color = vec![Rgb888::new(0, 0, 0); W as usize * H as usize];
        let mut depth = vec![0u16; W as usize * H as usize];
        for (k, (c, z)) in color.chunks_mut(W as usize * 16).zip(depth.chunks_mut(W as usize * 16)).enumerate() {
            let mut band = Band::new(c, z, W, H, k as u16 * 16).unwrap();
            band.clear(Rgb888::new(10, 20, 30));
            Renderer::new(&cam, lights, opts).draw(&mut band, model, t, scratch).unwrap();
        }
        color
    };
    let (mut rows, mut verts) = (vec![TriangleRows::UNKNOWN; 5000], vec![TransformedVertex::UNKNOWN; 5000]);
    let mut shared = Scratch::none().with_rows(&mut rows).with_vertices(&mut verts);
    let first = draw(&mut shared, &suzanne, &lights, opts, Mat4::IDENTITY);
    assert!(first == draw(&mut Scratch::none(), &suzanne, &lights, opts, Mat4::IDENTITY));
    for (model, lights, opts, t) in [
        (&suzanne, &lights, opts, turned),
        (&teapot, &lights, opts, Mat4::IDENTITY),
        (&suzanne, &dim, opts, Mat4::IDENTITY),
        (&suzanne, &lights, flat, Mat4::IDENTITY),
    ] {
        let fresh = draw(&mut Scratch::none(), model, lights, opts, t);
        assert!(draw(&mut shared, model, lights, opts, t) == fresh, "{opts:?} {t:?}");
    }
    // A new frame forgets the owner: the next draw may use the memory again.
    shared.new_frame();
    assert!(
        draw(&mut shared, &suzanne, &lights, opts, turned)
            == draw(&mut Scratch::none(), &suzanne, &lights, opts, turned)
    );
}

/// A depth buffer that says it has the band's length but hands the span loop fewer plain
/// values (`DepthBuffer::as_u16`): nothing is drawn through them (no panic, and no unchecked
/// index beyond them); the same buffer handing all of them draws the frame.
#[test]
fn a_depth_buffer_with_too_few_plain_values_draws_nothing() {
    use soft3d::DepthBuffer;
    struct Short<'a>(&'a mut [u16], usize);
    impl DepthBuffer for Short<'_> {
        type Cells<'b>
            = core::slice::IterMut<'b, u16>
        where
            Self: 'b;
        fn depth_len(&self) -> Option<usize> {
            Some(self.0.len())
        }
        fn cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>> {
            self.0.get_mut(start..start.checked_add(len)?).map(|c| c.iter_mut())
        }
        fn clear_depth(&mut self) {
            self.0.fill(u16::MAX);
        }
        fn as_u16(&mut self) -> Option<&mut [u16]> {
            let n = self.1;
            self.0.get_mut(..n)
        }
    }
    let bytes = model_bytes("suzanne/monkey.babylon");
    let model = Model::parse(&bytes).unwrap();
    let (cam, lights) = (camera(&model), Lights::<4>::from_model(&model));
    let pixels = W as usize * H as usize;
    for (given, drawn) in [(pixels - 1, false), (pixels, true)] {
        let (mut color, mut depth) = (vec![Rgb888::new(0, 0, 0); pixels], vec![u16::MAX; pixels]);
        let mut band = Band::new(&mut color[..], Short(&mut depth[..], given), W, H, 0).unwrap();
        let stats = Renderer::new(&cam, &lights, RenderOptions::default())
            .draw(&mut band, &model, Mat4::IDENTITY, &mut Scratch::none())
            .unwrap();
        assert_eq!(stats.pixels_written > 1000, drawn, "{given} values: {stats:?}");
        assert_eq!(color.iter().any(|&c| c != Rgb888::new(0, 0, 0)), drawn);
        assert_eq!(depth.iter().any(|&d| d != u16::MAX), drawn);
    }
}
