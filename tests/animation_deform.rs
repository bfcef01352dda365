//! Issue "Scenes that move": skinning and morphing against a float reference. A hand-made
//! six-vertex strip (`data/skin-morph.babylon`: two bones with known `_matrix` keys, vertices
//! weighted 1, 0.5/0.5, 0.25/0.75 and 0.9/0.1, two morph targets, one with an animated
//! influence) is converted, posed at several frames and its deformed vertices compared with a
//! plain f64 computation written here from the file's numbers: Babylon.js's order, morph
//! targets first (`p + Σ influence · (target - p)`), then linear-blend skinning
//! (`Σ w · p · inverse(absolute bind) · absolute pose`, row vectors), then the mesh's world.
#![cfg(feature = "convert")]

use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};
use serde_json::Value;
use soft3d::animation::{pose_memory, Pose};
use soft3d::convert::{emit, read_babylon, ConvertOptions, EmitOptions};
use soft3d::{Band, Camera, Lights, Mat4, Mode, Model, RenderOptions, Renderer, Scratch, Shading, Vec3, Vec4};

const SCENE: &str = include_str!("data/skin-morph.babylon");

/// Frames posed: the bind pose (0), the bind pose held by the step keys with the animated
/// target a quarter in (5), the second key's pose (15) and the last (20).
const FRAMES: [f32; 4] = [0.0, 5.0, 15.0, 20.0];

type Matrix = [f64; 16];

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn matrix(v: &Value) -> Matrix {
    numbers(v).try_into().unwrap()
}

/// `a · b` of Babylon.js's row-major matrices.
fn mul(a: &Matrix, b: &Matrix) -> Matrix {
    core::array::from_fn(|i| (0..4).map(|k| a[i / 4 * 4 + k] * b[k * 4 + i % 4]).sum())
}

/// `m`'s inverse by Gauss-Jordan elimination with partial pivoting.
fn inverse(m: &Matrix) -> Matrix {
    let mut a: [[f64; 8]; 4] = core::array::from_fn(|r| {
        core::array::from_fn(|c| if c < 4 { m[4 * r + c] } else { f64::from(u8::from(c - 4 == r)) })
    });
    for col in 0..4 {
        let pivot = (col..4).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs())).unwrap();
        a.swap(col, pivot);
        let p = a[col][col];
        assert!(p.abs() > 1e-12, "singular matrix {m:?}");
        a[col].iter_mut().for_each(|v| *v /= p);
        for r in (0..4).filter(|&r| r != col) {
            let f = a[r][col];
            let pivot_row = a[col];
            a[r].iter_mut().zip(pivot_row).for_each(|(v, p)| *v -= f * p);
        }
    }
    core::array::from_fn(|i| a[i / 4][4 + i % 4])
}

/// The point `p · m` (row vector, w = 1).
fn transform(p: [f64; 3], m: &Matrix) -> [f64; 3] {
    core::array::from_fn(|c| p[0] * m[c] + p[1] * m[4 + c] + p[2] * m[8 + c] + m[12 + c])
}

/// A track's value at `frame`: linear between keys, the end keys' values outside them.
fn lerp_keys(keys: &[Value], frame: f64) -> f64 {
    let keys: Vec<(f64, f64)> = keys.iter().map(|k| (k["frame"].as_f64().unwrap(), numbers(&k["values"])[0])).collect();
    let Some(i) = keys.iter().rposition(|k| k.0 <= frame) else { return keys[0].1 };
    match keys.get(i + 1) {
        Some(&(f1, v1)) => {
            let (f0, v0) = keys[i];
            v0 + (v1 - v0) * (frame - f0) / (f1 - f0)
        }
        None => keys[i].1,
    }
}

/// A bone's local matrix at `frame`: the last `_matrix` key at or before it (Babylon.js holds
/// matrix keys: `Animation.AllowMatricesInterpolation` is off).
fn bone_local(bone: &Value, frame: f64) -> Matrix {
    let keys = bone["animation"]["keys"].as_array().unwrap();
    let key = keys.iter().rev().find(|k| k["frame"].as_f64().unwrap() <= frame).unwrap_or(&keys[0]);
    matrix(&key["values"])
}

/// The skin matrix of each bone at `frame`: `inverse(absolute bind) · absolute pose`, where a
/// bone's absolute matrix is its local one times its parent's absolute one.
fn skin_matrices(scene: &Value, frame: f64) -> Vec<Matrix> {
    let bones = scene["skeletons"][0]["bones"].as_array().unwrap();
    let (mut bind, mut posed): (Vec<Matrix>, Vec<Matrix>) = (Vec::new(), Vec::new());
    for bone in bones {
        let (local_bind, local_pose) = (matrix(&bone["matrix"]), bone_local(bone, frame));
        match bone["parentBoneIndex"].as_i64().filter(|&p| p >= 0) {
            Some(p) => {
                bind.push(mul(&local_bind, &bind[p as usize]));
                posed.push(mul(&local_pose, &posed[p as usize]));
            }
            None => {
                bind.push(local_bind);
                posed.push(local_pose);
            }
        }
    }
    bind.iter().zip(&posed).map(|(b, p)| mul(&inverse(b), p)).collect()
}

/// The strip's vertices at `frame` in its local space (before its world matrix), in f64.
fn reference(scene: &Value, frame: f64) -> Vec<[f64; 3]> {
    let mesh = &scene["meshes"][0];
    let base = numbers(&mesh["positions"]);
    let targets = scene["morphTargetManagers"][0]["targets"].as_array().unwrap();
    let influences: Vec<f64> = targets
        .iter()
        .map(|t| {
            t["animations"]
                .get(0)
                .map_or(t["influence"].as_f64().unwrap(), |a| lerp_keys(a["keys"].as_array().unwrap(), frame))
        })
        .collect();
    if mesh.get("skeletonId").is_none() {
        return (0..base.len() / 3).map(|v| morphed(&base, targets, &influences, v)).collect();
    }
    let skins = skin_matrices(scene, frame);
    let (packed, weights) = (numbers(&mesh["matricesIndices"]), numbers(&mesh["matricesWeights"]));
    (0..base.len() / 3)
        .map(|v| {
            let morphed = morphed(&base, targets, &influences, v);
            (0..4).fold([0.0; 3], |sum, k| {
                let bone = (packed[v] as u32 >> (8 * k) & 0xff) as usize;
                let moved = transform(morphed, &skins[bone]);
                core::array::from_fn(|c| sum[c] + weights[4 * v + k] * moved[c])
            })
        })
        .collect()
}

/// Vertex `v` of `base` moved by the morph targets: `p + Σ influence · (target - p)`.
fn morphed(base: &[f64], targets: &[Value], influences: &[f64], v: usize) -> [f64; 3] {
    core::array::from_fn(|c| {
        let p = base[3 * v + c];
        let deltas = targets.iter().zip(influences).map(|(t, w)| w * (numbers(&t["positions"])[3 * v + c] - p));
        p + deltas.sum::<f64>()
    })
}

/// The strip without its skeleton: morphed only (positions then stay in stored units until the
/// draw's dequantization, which `posed_position` applies).
fn morph_only_json() -> Value {
    let mut json = scene_json();
    let mesh = json["meshes"][0].as_object_mut().unwrap();
    for key in ["skeletonId", "matricesIndices", "matricesWeights"] {
        mesh.remove(key);
    }
    json.as_object_mut().unwrap().remove("skeletons");
    json
}

fn scene_json() -> Value {
    serde_json::from_str(SCENE).unwrap()
}

/// `json` converted and written with positions quantized (the default) or as f32.
fn s3d(json: &Value, float_positions: bool) -> Vec<u8> {
    let text = json.to_string();
    let (scene, warnings) =
        read_babylon(text.as_bytes(), None, "skin-morph.babylon", &ConvertOptions::default()).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    emit(&scene, &EmitOptions { float_positions, ..EmitOptions::default() }).unwrap()
}

/// Runs `f` with `model` posed at `frame` (every group).
fn with_pose<R>(model: &Model<'_>, frame: f32, f: impl FnOnce(&Pose<'_>) -> R) -> R {
    let a = model.animation().unwrap();
    let (n, w) = pose_memory(a.node_count(), a.palette_count(), a.weight_count());
    let (mut nodes, mut weights) = (vec![Mat4::ZERO; n], vec![0.0; w]);
    let mut pose = Pose::new(&mut nodes, &mut weights);
    pose.evaluate(&a, frame, None).unwrap();
    f(&pose)
}

/// The largest difference, over the strip's vertices and axes, between soft3d's deformed
/// vertices (`testing::posed_position`: what the vertex stage reads) and the reference.
fn largest_error(model: &Model<'_>, json: &Value, frame: f32) -> f64 {
    let expected = reference(json, frame.into());
    let got: Vec<Vec3> = with_pose(model, frame, |pose| {
        (0..expected.len() as u32).map(|i| soft3d::testing::posed_position(model, pose, 0, i).unwrap()).collect()
    });
    got.iter()
        .zip(&expected)
        .flat_map(|(g, e)| g.to_array().into_iter().zip(e).map(|(g, e)| (f64::from(g) - e).abs()))
        .fold(0.0, f64::max)
}

/// The largest difference the file's quantization allows: half a position step on each axis
/// when positions are quantized (`step`); each morph delta rounded to 1/32767 of its target's
/// largest (0.5 here) for influences summing to at most 1.6; both through bones whose matrices'
/// rows sum to at most 2 here when `skinned`, which adds each of a vertex's two weights rounded
/// to 1/65535 (they then sum to 1 ± 1.5e-5) on points at most 3 units out; and 1e-6 for f32
/// arithmetic.
fn tolerance(step: Option<f64>, skinned: bool) -> f64 {
    let bones = if skinned { 2.0 } else { 1.0 };
    let position = step.map_or(0.0, |s| 0.5 * s);
    let morph = 0.5 * (0.5 / 32767.0) * 1.6;
    let weights = if skinned { 2.0 * (0.5 / 65535.0) * 3.0 } else { 0.0 };
    (position + morph) * bones + weights + 1e-6
}

#[test]
fn skinned_and_morphed_vertices_match_a_float_reference() {
    for (json, skinned) in [(scene_json(), true), (morph_only_json(), false)] {
        for float_positions in [false, true] {
            let bytes = s3d(&json, float_positions);
            let model = Model::parse(&bytes).unwrap();
            let step = f64::from(model.mesh(0).unwrap().dequantization().0.max_element());
            let allowed = tolerance((!float_positions).then_some(step), skinned);
            for frame in FRAMES {
                let error = largest_error(&model, &json, frame);
                let what = format!("skinned {skinned}, f32 positions {float_positions}, frame {frame}");
                println!("{what}: error {error:.2e}, allowed {allowed:.2e}");
                assert!(error <= allowed, "{what}: {error:e} > {allowed:e}");
            }
            // The pose's weights: "bulge" at its 0.6, "lean" linear from 0 at frame 0 to 1 at 20.
            let weights = with_pose(&model, 15.0, |pose| pose.weights().to_vec());
            assert_eq!(weights, [0.6, 0.75]);
        }
    }
}

/// The strip drawn posed as points (unlit, white on black) by an orthographic camera: one pixel
/// a vertex, each the pixel holding the reference vertex placed by the mesh's world matrix (a
/// move of 0.5 along x), so that the draw itself deforms as `posed_position` says.
#[test]
fn a_posed_draw_puts_each_vertex_where_the_reference_does() {
    const SIZE: u16 = 480;
    let json = scene_json();
    let bytes = s3d(&json, false);
    let model = Model::parse(&bytes).unwrap();
    // 6 x 6 units around (1, 1): 80 pixels a unit.
    let camera =
        Camera::orthographic(Vec3::new(1.0, 1.0, -10.0), Vec3::new(1.0, 1.0, 0.0), 6.0, 6.0, 1.0, 20.0).unwrap();
    let world = numbers(&json["meshes"][0]["position"]);
    let lights = Lights::<1>::new(Vec3::ONE);
    let opts = RenderOptions {
        mode: Mode::Points,
        shading: Shading::Unlit,
        wire_color: Some([255; 3]),
        ..RenderOptions::default()
    };
    let pixel = |p: [f64; 3]| {
        let clip = camera.view_projection() * Vec4::new(p[0] as f32, p[1] as f32, p[2] as f32, 1.0);
        let half = f64::from(SIZE) / 2.0;
        ((f64::from(clip.x / clip.w) + 1.0) * half, (1.0 - f64::from(clip.y / clip.w)) * half)
    };
    let rest: Vec<_> =
        reference(&json, 0.0).into_iter().map(|p| pixel(core::array::from_fn(|c| p[c] + world[c]))).collect();
    for frame in FRAMES {
        let n = usize::from(SIZE) * usize::from(SIZE);
        let (mut color, mut depth) = (vec![Rgb888::BLACK; n], vec![u16::MAX; n]);
        let mut band = Band::new(&mut color[..], &mut depth[..], SIZE, SIZE, 0).unwrap();
        band.clear(Rgb888::BLACK);
        with_pose(&model, frame, |pose| {
            let renderer = Renderer::new(&camera, &lights, opts);
            renderer.draw_posed(&mut band, &model, pose, Mat4::IDENTITY, &mut Scratch::none()).unwrap();
        });
        let drawn: Vec<(f64, f64)> = (0..n)
            .filter(|&i| color[i] != Rgb888::BLACK)
            .map(|i| ((i % usize::from(SIZE)) as f64 + 0.5, (i / usize::from(SIZE)) as f64 + 0.5))
            .collect();
        assert_eq!(drawn.len(), 6, "frame {frame}: {drawn:?}");
        let mut moved = 0.0f64;
        for (v, p) in reference(&json, frame.into()).into_iter().enumerate() {
            let (x, y) = pixel(core::array::from_fn(|c| p[c] + world[c]));
            // The pixel holding the point (snapped to 1/16 pixel): its centre within 0.5 + 1/16.
            let near = drawn.iter().any(|&(px, py)| (px - x).abs() <= 0.57 && (py - y).abs() <= 0.57);
            assert!(near, "frame {frame}: vertex {v} at ({x:.2}, {y:.2}) not drawn: {drawn:?}");
            moved = moved.max((x - rest[v].0).abs().max((y - rest[v].1).abs()));
        }
        println!("frame {frame}: the pose moves a vertex {moved:.1} pixels from rest");
        // Where the bones move, a draw at rest would miss the reference by far more than a pixel.
        assert!(frame < 15.0 || moved > 20.0, "frame {frame}: the test would prove nothing");
    }
}
