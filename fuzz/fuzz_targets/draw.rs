//! Drawing a parsed model with anything a caller can choose: cameras (perspective and
//! orthographic, degenerate and extreme), model transforms (huge scales, NaN and infinite
//! entries, projective ones), every `RenderOptions` combination (modes, shadings, filters,
//! dithering, sub-spans, fixed-point vertices, back-to-front order), lights (with specular),
//! band heights from 1 to the frame, every pixel format and depth format, and scratch memory
//! of any size; frames up to 48 x 48 drawn whole, or up to the largest frame (1536 x 1536) of
//! which one band of a few rows is drawn (where slivers' depth planes and the per-pixel
//! perspective bound meet boxes a thousand pixels across). Never panics (built with debug assertions: overflow is a panic) and never
//! hangs.
//!
//! The model is one of the seed scenes (`fuzz/seeds/parse`, chosen by the first byte) or, when
//! that byte says so, the input's tail, if it parses. A model with animation (the logo,
//! morph-cube and shapekey seeds, or a tail that has some) is mostly drawn posed
//! (`Renderer::draw_posed`): its pose evaluated at an arbitrary frame (NaN, infinities and huge
//! ones too) of every group, one group or a group past the last, in pose memory of the right
//! size or too small (the pose then unset: the model at rest).
#![no_main]
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888};
use libfuzzer_sys::arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use soft3d::animation::{pose_memory, Pose, PoseError};
use soft3d::{
    Band, Camera, DepthBuffer, DrawOrder, Filter, Fog, FogMode, FrameColor, Lights, Mat4, Mode, Model, NoDepth,
    RenderOptions, Renderer, Rgb565Be, Scratch, Shading, SortEntry, TransformedVertex, TriangleRows, Vec3, Vec4,
};

const SEEDS: [&[u8]; 8] = [
    include_bytes!("../seeds/parse/suzanne-monkey.s3d"),
    include_bytes!("../seeds/parse/double-sided-DoubleSidedMaterial.s3d"),
    include_bytes!("../seeds/parse/tree-tree.s3d"),
    include_bytes!("../seeds/parse/instances-Instances.s3d"),
    include_bytes!("../seeds/parse/logo-animation-logo.s3d"),
    include_bytes!("../seeds/parse/morph-cube-AnimatedMorphCube.s3d"),
    include_bytes!("../seeds/parse/shapekey-shapekeyAnimation.s3d"),
    include_bytes!("../seeds/parse/rabbit-Rabbit.s3d"),
];

/// A float: usually a plain one in `-range..range`, sometimes any bit pattern (NaN, infinities,
/// huge and tiny values).
fn float(u: &mut Unstructured<'_>, range: f32) -> Result<f32> {
    Ok(match u.int_in_range(0..=7)? {
        0 => f32::from_bits(u.arbitrary()?),
        1 => [0.0, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MAX, f32::MIN_POSITIVE, 1e19]
            [u.int_in_range(0..=7)?],
        _ => (u.arbitrary::<i16>()? as f32 / 32768.0) * range,
    })
}

fn vec3(u: &mut Unstructured<'_>, range: f32) -> Result<Vec3> {
    Ok(Vec3::new(float(u, range)?, float(u, range)?, float(u, range)?))
}

fn camera(u: &mut Unstructured<'_>, aspect: f32) -> Result<Option<Camera>> {
    let (eye, target) = (vec3(u, 20.0)?, vec3(u, 2.0)?);
    let (near, far) = (float(u, 2.0)?, float(u, 200.0)?);
    Ok(if u.arbitrary()? {
        Camera::perspective(eye, target, float(u, 3.0)?, aspect, near, far).ok()
    } else {
        Camera::orthographic(eye, target, float(u, 10.0)?, float(u, 10.0)?, near, far).ok()
    })
}

fn transform(u: &mut Unstructured<'_>) -> Result<Mat4> {
    Ok(match u.int_in_range(0..=4)? {
        0 => Mat4::IDENTITY,
        1 => Mat4::from_rotation_y(float(u, 7.0)?),
        2 => Mat4::from_scale(Vec3::splat(float(u, 70_000.0)?)),
        3 => Mat4::from_scale_rotation_translation(vec3(u, 4.0)?, glam_quat(u)?, vec3(u, 10.0)?),
        _ => {
            let mut c = [0.0; 16];
            for x in &mut c {
                *x = float(u, 4.0)?;
            }
            Mat4::from_cols(
                Vec4::from_slice(&c[0..4]),
                Vec4::from_slice(&c[4..8]),
                Vec4::from_slice(&c[8..12]),
                Vec4::from_slice(&c[12..16]),
            )
        }
    })
}

fn glam_quat(u: &mut Unstructured<'_>) -> Result<glam::Quat> {
    Ok(glam::Quat::from_rotation_x(float(u, 7.0)?) * glam::Quat::from_rotation_z(float(u, 7.0)?))
}

fn options(u: &mut Unstructured<'_>) -> Result<RenderOptions> {
    Ok(RenderOptions {
        shading: [Shading::Unlit, Shading::Flat, Shading::Gouraud, Shading::Phong][u.int_in_range(0..=3)?],
        mode: [Mode::Solid, Mode::Wireframe, Mode::Points, Mode::SolidWireframe][u.int_in_range(0..=3)?],
        filter: if u.arbitrary()? { Filter::Nearest } else { Filter::Bilinear },
        subspan: if u.arbitrary()? { 1 } else { u.arbitrary()? },
        textures: u.arbitrary()?,
        dither: u.arbitrary()?,
        fixed_vertices: u.arbitrary()?,
        order: if u.int_in_range(0..=3)? == 0 { DrawOrder::BackToFront } else { DrawOrder::AsStored },
        wire_color: if u.arbitrary()? { Some(u.arbitrary()?) } else { None },
        fog: if u.arbitrary()? { Some(fog(u)?) } else { None },
    })
}

/// Any fog: every mode, odd densities and ranges (negative, reversed, huge, NaN-free).
fn fog(u: &mut Unstructured<'_>) -> Result<Fog> {
    let mode = [FogMode::Exp, FogMode::Exp2, FogMode::Linear][u.int_in_range(0..=2)?];
    Ok(Fog {
        density: float(u, 10.0)?,
        start: float(u, 100.0)?,
        end: float(u, 100.0)?,
        ..Fog::new(mode, vec3(u, 2.0)?)
    })
}

fn lights(u: &mut Unstructured<'_>, model: &Model<'_>) -> Result<Lights<4>> {
    let mut lights = Lights::<4>::from_model(model);
    if u.arbitrary()? {
        lights = Lights::new(vec3(u, 1.0)?);
        for _ in 0..u.int_in_range(0..=4)? {
            let light = match u.int_in_range(0..=2)? {
                0 => Lights::<4>::directional(vec3(u, 1.0)?, float(u, 2.0)?),
                1 => Lights::<4>::point(vec3(u, 10.0)?, float(u, 2.0)?),
                _ => soft3d::Light {
                    kind: soft3d::LightKind::Hemispheric,
                    vector: vec3(u, 1.0)?,
                    diffuse: vec3(u, 1.0)?,
                    intensity: float(u, 2.0)?,
                },
            };
            let _ = lights.push(light);
        }
    }
    if u.arbitrary()? {
        lights.specular = vec3(u, 1.0)?;
        lights.shininess = float(u, 128.0)?;
    }
    Ok(lights)
}

/// Draws the frame in bands of `rows` (or only the band from row `only`) into colour format
/// `C`, with depth kind `depth` (u16, f32 or none), and scratch memory of full, half or no
/// size.
fn draw_frame<C: FrameColor + Default>(
    u: &mut Unstructured<'_>,
    renderer: &Renderer<'_, 4>,
    model: &Model<'_>,
    pose: Option<&Pose<'_>>,
    transform: Mat4,
    (width, height, rows, only): (u16, u16, u16, Option<u16>),
    depth: u8,
) -> Result<()> {
    let (triangles, vertices) = model.draw_counts();
    let mut cut = |n: usize| -> Result<usize> {
        Ok(match u.int_in_range(0..=3)? {
            0 => 0,
            1 => n / 2,
            _ => n,
        })
    };
    let mut rows_seen = vec![TriangleRows::UNKNOWN; cut(triangles)?];
    let mut verts = vec![TransformedVertex::UNKNOWN; cut(vertices)?];
    let mut sort = vec![SortEntry::default(); cut(triangles)?];
    let mut scratch = Scratch::none().with_rows(&mut rows_seen).with_vertices(&mut verts).with_sort(&mut sort);
    let n = width as usize * rows as usize;
    let mut color = vec![C::default(); n];
    let (mut z16, mut zf) = (vec![0u16; n], vec![0f32; n]);
    let firsts = match only {
        Some(first) => first..first + 1,
        None => 0..height,
    };
    for first_row in firsts.step_by(rows as usize) {
        let take = (rows.min(height - first_row)) as usize * width as usize;
        let color = &mut color[..take];
        let at = (width, height, first_row);
        match depth {
            0 => draw_band(
                renderer,
                (model, pose),
                transform,
                Band::new(color, &mut z16[..take], at.0, at.1, at.2),
                &mut scratch,
            ),
            1 => draw_band(
                renderer,
                (model, pose),
                transform,
                Band::new(color, &mut zf[..take], at.0, at.1, at.2),
                &mut scratch,
            ),
            _ => {
                draw_band(renderer, (model, pose), transform, Band::new(color, NoDepth, at.0, at.1, at.2), &mut scratch)
            }
        }
    }
    Ok(())
}

fn draw_band<C: FrameColor + Default, D: DepthBuffer>(
    renderer: &Renderer<'_, 4>,
    (model, pose): (&Model<'_>, Option<&Pose<'_>>),
    transform: Mat4,
    band: Result<Band<'_, C, D>, soft3d::TargetError>,
    scratch: &mut Scratch<'_>,
) {
    let mut band = band.expect("the band fits its frame");
    band.clear(C::default());
    let _ = match pose {
        Some(pose) => renderer.draw_posed(&mut band, model, pose, transform, scratch),
        None => renderer.draw(&mut band, model, transform, scratch),
    };
}

/// Evaluates `pose` for `model` (when it has animation) at an arbitrary frame and group; whether
/// to draw it posed (mostly, when there is animation; an unset pose draws the model at rest).
fn evaluate_pose(u: &mut Unstructured<'_>, model: &Model<'_>, pose: &mut Pose<'_>) -> Result<bool> {
    let Some(animation) = model.animation() else { return u.ratio(1, 8) };
    let groups = animation.group_count();
    let frame = match u.int_in_range(0..=3)? {
        0 => float(u, 1e4)?,
        _ => {
            // Around a group's range (before it, inside, past its end).
            let (from, to) =
                u.choose_index(groups.max(1)).ok().and_then(|g| animation.group(g)).map_or((0.0, 100.0), |g| g.range());
            from + (to - from) * (u.arbitrary::<i16>()? as f32 / 8192.0)
        }
    };
    let group = match u.int_in_range(0..=4)? {
        0 | 1 => None,
        2 | 3 => Some(u.int_in_range(0..=groups)?),
        _ => Some(u.arbitrary()?),
    };
    let (matrices, weights) = pose_memory(animation.node_count(), animation.palette_count(), animation.weight_count());
    match pose.evaluate(&animation, frame, group) {
        Ok(()) => {
            assert!(group.is_none_or(|g| g < groups) && pose.weights().len() == weights);
            assert_eq!(pose.palette().len(), animation.palette_count());
        }
        Err(PoseError::NoSuchGroup(g)) => assert!(Some(g) == group && g >= groups),
        Err(PoseError::TooSmall { nodes: n, weights: w }) => assert_eq!((n, w), (matrices, weights)),
    }
    Ok(!u.ratio(1, 8)?)
}

fn run(data: &[u8]) -> Result<()> {
    let mut u = Unstructured::new(data);
    let pick: u8 = u.arbitrary()?;
    let tail_model;
    let model = match SEEDS.get(pick as usize % (SEEDS.len() + 1)) {
        Some(seed) => Model::parse(seed).expect("seed parses"),
        None => {
            tail_model = u.peek_bytes(u.len()).unwrap_or(&[]).to_vec();
            match Model::parse(&tail_model) {
                Ok(m) => m,
                Err(_) => return Ok(()),
            }
        }
    };
    // Mostly small frames drawn whole; sometimes one band of a few rows of a large frame.
    let (width, height, rows, only) = if u.ratio(1, 4)? {
        let (width, height) = (u.int_in_range(1..=1536)?, u.int_in_range(1..=1536)?);
        let rows = u.int_in_range(1..=height.min(8))?;
        (width, height, rows, Some(u.int_in_range(0..=height - rows)?))
    } else {
        let (width, height) = (u.int_in_range(1..=48)?, u.int_in_range(1..=48)?);
        (width, height, u.int_in_range(1..=height)?, None)
    };
    let Some(camera) = camera(&mut u, width as f32 / height as f32)? else { return Ok(()) };
    let transform = transform(&mut u)?;
    let lights = lights(&mut u, &model)?;
    let renderer = Renderer::new(&camera, &lights, options(&mut u)?);
    let size = (width, height, rows, only);
    let depth = u.int_in_range(0..=2)?;
    let format = u.int_in_range(0..=4)?;
    // Pose memory of `pose_memory`'s size, or sometimes too small (one short: `TooSmall`).
    let (n, w) = model.animation().map_or((0, 0), |a| pose_memory(a.node_count(), a.palette_count(), a.weight_count()));
    let short = usize::from(u.ratio(1, 8)?);
    let (mut nodes, mut weights) = (vec![Mat4::IDENTITY; n.saturating_sub(short)], vec![0.0; w.saturating_sub(short)]);
    let mut posed = Pose::new(&mut nodes, &mut weights);
    let pose = if evaluate_pose(&mut u, &model, &mut posed)? { Some(&posed) } else { None };
    match format {
        0 => draw_frame::<Rgb565>(&mut u, &renderer, &model, pose, transform, size, depth),
        1 => draw_frame::<Rgb888>(&mut u, &renderer, &model, pose, transform, size, depth),
        2 => draw_frame::<Gray8>(&mut u, &renderer, &model, pose, transform, size, depth),
        3 => draw_frame::<BinaryColor>(&mut u, &renderer, &model, pose, transform, size, depth),
        _ => draw_frame::<Rgb565Be>(&mut u, &renderer, &model, pose, transform, size, depth),
    }
}

fuzz_target!(|data: &[u8]| {
    let _ = run(data);
});
