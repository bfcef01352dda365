//! Every public entry point given caller memory of the wrong size: colour and depth slices
//! shorter or longer than the band, not a whole number of rows, bands of width or height 0 or
//! outside the frame, scratch rows, vertices and sort entries of any length (back-to-front
//! order with too few entries), and the model bytes truncated anywhere. Each gets a clear error
//! (its `Display` says what and how big) or draws; never a panic, never a write outside.
#![no_main]
use embedded_graphics_core::pixelcolor::Rgb565;
use libfuzzer_sys::arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use soft3d::{
    Band, Camera, DrawError, DrawOrder, Lights, Mat4, Model, NoDepth, RenderOptions, Renderer, Scratch, SortEntry,
    TargetError, TransformedVertex, TriangleRows, Vec3,
};

const SUZANNE: &[u8] = include_bytes!("../seeds/parse/suzanne-monkey.s3d");

/// A length near `n`: 0, `n`, `n ± small`, or anything up to twice it.
fn length(u: &mut Unstructured<'_>, n: usize) -> Result<usize> {
    Ok(match u.int_in_range(0..=4)? {
        0 => 0,
        1 => n,
        2 => n.saturating_sub(u.int_in_range(1..=3)?),
        3 => n + u.int_in_range(1..=3)?,
        _ => u.int_in_range(0..=2 * n + 1)?,
    })
}

fn run(data: &[u8]) -> Result<()> {
    let mut u = Unstructured::new(data);
    // The model, truncated (or not) anywhere: a clear error or a model.
    let cut = length(&mut u, SUZANNE.len())?.min(SUZANNE.len());
    let model = match Model::parse(&SUZANNE[..cut]) {
        Ok(model) => model,
        Err(e) => {
            assert!(!e.to_string().is_empty());
            return Ok(());
        }
    };
    let (width, height): (u16, u16) = (u.int_in_range(0..=40)?, u.int_in_range(0..=40)?);
    let first_row: u16 = u.int_in_range(0..=height.saturating_add(2))?;
    let rows = u.int_in_range(0..=height as usize + 2)?;
    let want = width as usize * rows;
    let mut color = vec![Rgb565::new(1, 2, 3); length(&mut u, want)?];
    let mut depth = vec![0u16; length(&mut u, want)?];
    let (color_len, depth_len) = (color.len(), depth.len());
    let band = if u.arbitrary()? {
        Band::new(&mut color[..], &mut depth[..], width, height, first_row).map(|b| (Some(b), None))
    } else {
        Band::new(&mut color[..], NoDepth, width, height, first_row).map(|b| (None, Some(b)))
    };
    let (with_depth, without) = match band {
        Ok(b) => b,
        Err(e) => {
            // A refusal says why; an acceptance means the lengths were right.
            assert!(!e.to_string().is_empty());
            if let TargetError::DepthLength { depth, color } = e {
                assert!(depth != color);
            }
            return Ok(());
        }
    };
    assert!(color_len % width as usize == 0 && color_len > 0);
    let (triangles, vertices) = model.draw_counts();
    let mut rows_seen = vec![TriangleRows::UNKNOWN; length(&mut u, triangles)?];
    let mut verts = vec![TransformedVertex::UNKNOWN; length(&mut u, vertices)?];
    let mut sort = vec![SortEntry::default(); length(&mut u, triangles)?];
    let sort_len = sort.len();
    let mut scratch = Scratch::none().with_rows(&mut rows_seen).with_vertices(&mut verts).with_sort(&mut sort);
    let camera = Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0).unwrap();
    let lights = Lights::<2>::from_model(&model);
    let order = if u.arbitrary()? { DrawOrder::BackToFront } else { DrawOrder::AsStored };
    let renderer = Renderer::new(&camera, &lights, RenderOptions { order, ..RenderOptions::default() });
    let result = match (with_depth, without) {
        (Some(mut band), _) => renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut scratch),
        (_, Some(mut band)) => renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut scratch),
        _ => unreachable!(),
    };
    match result {
        Ok(_) => assert!(order == DrawOrder::AsStored || sort_len >= triangles),
        Err(DrawError::ScratchTooSmall { needed, given }) => {
            assert_eq!((needed, given), (triangles, sort_len));
            assert!(!DrawError::ScratchTooSmall { needed, given }.to_string().is_empty());
        }
    }
    let _ = depth_len;
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(data);
});
