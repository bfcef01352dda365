//! Issue "Scenes that move": keys interpolated as Babylon.js's `Animation._interpolate` does,
//! through the public path (a hand-made `.babylon` converted by `soft3d::convert`, emitted,
//! parsed and evaluated by `Pose`), each against a value worked out by hand or by the formula
//! Babylon.js uses: linear vectors and floats, quaternion slerp (the shorter way), step keys,
//! Hermite tangents (vector, float and normalised quaternion), group loops, and `_matrix` keys
//! decomposed as `Matrix.decompose` does (non-uniform and negative scales among them).
#![cfg(feature = "convert")]

use serde_json::json;
use soft3d::animation::{pose_memory, Pose};
use soft3d::convert::scene::{NodeProperty, TrackTarget};
use soft3d::convert::{emit, read_babylon, ConvertOptions, EmitOptions};
use soft3d::{Mat4, Model, Vec3};

const KEYS: &str = include_str!("data/keys.babylon");

/// `json` converted and written as `.s3d` bytes.
fn s3d(json: &str) -> Vec<u8> {
    let (scene, warnings) = read_babylon(json.as_bytes(), None, "test.babylon", &ConvertOptions::default()).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    emit(&scene, &EmitOptions::default()).unwrap()
}

/// Every animated node's world matrix at `frame` of `group` (every group when `None`).
fn worlds(model: &Model<'_>, frame: f32, group: Option<usize>) -> Vec<Mat4> {
    let a = model.animation().expect("an animated model");
    let (n, w) = pose_memory(a.node_count(), a.palette_count(), a.weight_count());
    let (mut nodes, mut weights) = (vec![Mat4::ZERO; n], vec![0.0; w]);
    let mut pose = Pose::new(&mut nodes, &mut weights);
    pose.evaluate(&a, frame, group).unwrap();
    (0..a.node_count()).map(|i| pose.node_world(i).unwrap()).collect()
}

/// The animated node that carries mesh `name`.
fn node_of(model: &Model<'_>, name: &str) -> usize {
    let mesh = model.meshes().position(|m| m.name() == name).unwrap_or_else(|| panic!("no mesh {name}"));
    model.animation().and_then(|a| a.link_of(mesh)).unwrap_or_else(|| panic!("{name} is not animated")).0
}

/// The world matrix of the node carrying mesh `name` at `frame` (every group).
fn world_of(model: &Model<'_>, name: &str, frame: f32) -> Mat4 {
    worlds(model, frame, None)[node_of(model, name)]
}

fn assert_near(got: Vec3, expected: [f64; 3], tolerance: f64, what: &str) {
    let close = got.to_array().iter().zip(expected).all(|(&g, e)| (f64::from(g) - e).abs() <= tolerance);
    assert!(close, "{what}: {got} vs {expected:?} (tolerance {tolerance})");
}

/// `Scalar.Hermite` / `Vector3.Hermite` of Babylon.js, on one component, in f64: the cubic
/// through `v0` and `v1` with tangents `m0` and `m1` (already scaled by the frames between the
/// keys, as `_interpolate` does).
fn hermite(v0: f64, m0: f64, v1: f64, m1: f64, t: f64) -> f64 {
    let (t2, t3) = (t * t, t * t * t);
    v0 * (2.0 * t3 - 3.0 * t2 + 1.0) + v1 * (-2.0 * t3 + 3.0 * t2) + m0 * (t3 - 2.0 * t2 + t) + m1 * (t3 - t2)
}

#[test]
fn linear_keys_move_vectors_and_floats_in_proportion() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    // position (0,0,0) at 0 to (10,-20,5) at 10; scaling.x 1 at 0 to 3 at 20.
    for (frame, position, scale) in
        [(2.5, [2.5, -5.0, 1.25], 1.25), (7.5, [7.5, -15.0, 3.75], 1.75), (15.0, [10.0, -20.0, 5.0], 2.5)]
    {
        let m = world_of(&model, "linear", frame);
        assert_near(m.w_axis.truncate(), position, 1e-5, &format!("position at {frame}"));
        assert_near(m.x_axis.truncate(), [scale, 0.0, 0.0], 1e-6, &format!("scaling.x at {frame}"));
        // scaling.x alone moves: y and z keep their rest scaling.
        assert_near(m.y_axis.truncate(), [0.0, 1.0, 0.0], 1e-6, "y axis");
    }
}

/// A rotation of `degrees` about y, as Babylon.js's `RotationY` puts it in a matrix's first
/// column (glam's `x_axis`): (cos, 0, -sin).
fn turned_x_axis(degrees: f64) -> [f64; 3] {
    let r = degrees.to_radians();
    [r.cos(), 0.0, -r.sin()]
}

#[test]
fn quaternion_keys_slerp_the_shorter_way() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    // Identity at 0, 90° about y at 10: half way is 45°; a quarter of the way 22.5° (a
    // normalised lerp would give 21.6° there, 0.006 off in cos).
    for (frame, degrees) in [(5.0, 45.0), (2.5, 22.5), (10.0, 90.0)] {
        let m = world_of(&model, "slerp", frame);
        assert_near(m.x_axis.truncate(), turned_x_axis(degrees), 1e-5, &format!("frame {frame}"));
    }
    // 90° at 10 to (0,-1,0,0) at 20, which is 180° written with the other sign: the shorter way
    // passes 135° half way (the longer, through 0°, would give -45°).
    let m = world_of(&model, "slerp", 15.0);
    assert_near(m.x_axis.truncate(), turned_x_axis(135.0), 1e-5, "frame 15");
    assert_near(m.y_axis.truncate(), [0.0, 1.0, 0.0], 1e-6, "y stays up");
}

#[test]
fn a_step_key_holds_its_value_until_the_next_key() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    // 1 (step) at 0, 5 at 10, 7 at 20: held until 10, linear after.
    for (frame, y) in [(0.0, 1.0), (5.0, 1.0), (9.99, 1.0), (10.0, 5.0), (15.0, 6.0), (20.0, 7.0)] {
        let got = world_of(&model, "step", frame).w_axis.y;
        assert!((f64::from(got) - y).abs() < 1e-6, "frame {frame}: {got} vs {y}");
    }
}

#[test]
fn hermite_keys_follow_babylons_cubic_with_tangents_scaled_by_the_key_gap() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    // Keys 20 frames apart: the tangents are scaled by 20. At frame 15 (t = 0.25) the four
    // weights are 0.84375, 0.15625, 0.140625 and -0.046875, so position x is
    // 1·0.84375 + 3·0.15625 + (0.5·20)·0.140625 + (-0.25·20)·(-0.046875) = 2.953125.
    assert_near(world_of(&model, "hermite", 15.0).w_axis.truncate(), [2.953_125, -1.593_75, 7.0625], 1e-5, "t=0.25");
    let (v0, out0, v1, in1) = ([1.0, 2.0, 3.0], [0.5, -1.0, 2.0], [3.0, 0.0, -1.0], [-0.25, 0.5, 1.0]);
    for frame in [10.0, 12.5, 20.0, 27.0, 30.0] {
        let t = (frame - 10.0) / 20.0;
        let expected: [f64; 3] = core::array::from_fn(|c| hermite(v0[c], out0[c] * 20.0, v1[c], in1[c] * 20.0, t));
        let m = world_of(&model, "hermite", frame as f32);
        assert_near(m.w_axis.truncate(), expected, 1e-4, &format!("position at {frame}"));
        // scaling.y: 1 (out 0.2) to 2 (in -0.1); the rotation keeps the axis' length.
        let scale = hermite(1.0, 0.2 * 20.0, 2.0, -0.1 * 20.0, t);
        assert!((f64::from(m.y_axis.length()) - scale).abs() < 1e-5, "scaling.y at {frame}: {}", m.y_axis.length());
        assert_near(m.x_axis.truncate(), turned_x_axis(hermite_turn(t)), 1e-5, &format!("rotation at {frame}"));
    }
    // Frame 15 by hand: y = 0.7071·0.15625 + 1·0.140625 + 0.4·(-0.046875) = 0.232360,
    // w = 0.84375 + 0.7071·0.15625 + (-0.4)·(-0.046875) = 0.972985: 26.86° about y.
    let degrees = 2.0 * 0.232_360_f64.atan2(0.972_985).to_degrees();
    assert_near(world_of(&model, "hermite", 15.0).x_axis.truncate(), turned_x_axis(degrees), 1e-4, "rotation at 15");
}

/// The "hermite" node's turn about y, in degrees, at `t` between its quaternion keys: their
/// cubic, normalised (`Quaternion.Hermite(...).normalize()`), is a turn of 2·atan2(y, w).
fn hermite_turn(t: f64) -> f64 {
    use core::f64::consts::FRAC_1_SQRT_2;
    let (q0, out0) = ([0.0, 0.0, 0.0, 1.0], [0.0, 0.05, 0.0, 0.0]);
    let (q1, in1) = ([0.0, FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2], [0.0, 0.02, 0.0, -0.02]);
    let h = |c: usize| hermite(q0[c], out0[c] * 20.0, q1[c], in1[c] * 20.0, t);
    2.0 * h(1).atan2(h(3)).to_degrees()
}

#[test]
fn a_looping_group_starts_again_and_another_stays_at_its_end() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    let a = model.animation().unwrap();
    let group = |name: &str| a.group_named(name).unwrap_or_else(|| panic!("no group {name}"));
    // Both tracks go from 0 at frame 0 to 10 at frame 10; frame 13 is 3 frames past the end.
    for (name, expected) in [("cycle", 3.0), ("once", 10.0)] {
        let node = node_of(&model, name);
        let x = |frame: f32| worlds(&model, frame, Some(group(name)))[node].w_axis.x;
        assert!((x(4.0) - 4.0).abs() < 1e-5, "{name} at 4: {}", x(4.0));
        assert!((x(13.0) - expected).abs() < 1e-5, "{name} at 13: {} vs {expected}", x(13.0));
        assert!((x(-2.0)).abs() < 1e-6, "{name} before the start: the first key");
    }
}

/// Babylon.js plays a track whose `loopBehavior` is 2 (constant) in a looping group at its last
/// value once the group has gone round (`_interpolate` returns `highLimitValue` when
/// `repeatCount > 0`); `Pose` plays it so.
#[test]
fn a_constant_track_of_a_looping_group_stays_at_its_end() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    let a = model.animation().unwrap();
    let node = node_of(&model, "constant");
    let x = worlds(&model, 13.0, a.group_named("constant"))[node].w_axis.x;
    assert!((x - 10.0).abs() < 1e-5, "constant at 13: {x}, Babylon.js 10");
}

/// A relative track (`loopBehavior` 0) of a looping group starts each round where the last
/// ended: at frame 13 of a 0-10 group going from 0 to 10, 10 + 3.
#[test]
fn a_relative_track_of_a_looping_group_adds_each_round() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    let a = model.animation().unwrap();
    let node = node_of(&model, "relative");
    for (frame, want) in [(5.0, 5.0), (13.0, 13.0), (27.5, 27.5)] {
        let x = worlds(&model, frame, a.group_named("relative"))[node].w_axis.x;
        assert!((x - want).abs() < 1e-4, "relative at {frame}: {x}, Babylon.js {want}");
    }
}

/// A span whose first key has an out tangent but whose last has no in tangent is linear, as
/// Babylon.js interpolates it (`useTangent` needs both): x at frame 5 is 5, not the Hermite
/// value with a zero in tangent (6.875 with the out tangent 30 scaled by the gap: 2.5 + ...).
#[test]
fn a_span_without_both_tangents_is_linear() {
    let bytes = s3d(KEYS);
    let model = Model::parse(&bytes).unwrap();
    let node = node_of(&model, "half-hermite");
    let x = worlds(&model, 5.0, None)[node].w_axis.x;
    assert!((x - 5.0).abs() < 1e-5, "half-hermite at 5: {x}, Babylon.js 5 (linear)");
}

/// Babylon.js's `Matrix.FromQuaternion` rows (row vectors: a point is `p · R`), in f64.
fn rotation_rows([x, y, z, w]: [f64; 4]) -> [[f64; 3]; 3] {
    [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (z * x - y * w)],
        [2.0 * (x * y - z * w), 1.0 - 2.0 * (z * z + x * x), 2.0 * (y * z + x * w)],
        [2.0 * (z * x + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (y * y + x * x)],
    ]
}

/// A unit quaternion turning `angle` radians about `axis`.
fn quaternion(axis: [f64; 3], angle: f64) -> [f64; 4] {
    let length = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    let s = (angle / 2.0).sin() / length;
    [axis[0] * s, axis[1] * s, axis[2] * s, (angle / 2.0).cos()]
}

/// Babylon.js's `Matrix.Compose(S, R, T)` as its `m[16]`: `S · R · T`, the rotation's rows
/// scaled, the translation in the last row.
fn compose(s: [f64; 3], q: [f64; 4], t: [f64; 3]) -> [f64; 16] {
    let r = rotation_rows(q);
    let mut m = [0.0; 16];
    for i in 0..3 {
        for j in 0..3 {
            m[4 * i + j] = s[i] * r[i][j];
        }
        m[12 + i] = t[i];
    }
    m[15] = 1.0;
    m
}

/// A `_matrix` key: its `S`, `R` and `T`, and the scaling and rotation rows `Matrix.decompose`
/// gives back (the row lengths, y negated when the determinant is negative, and the rows
/// divided by them).
struct MatrixKey {
    s: [f64; 3],
    q: [f64; 4],
    t: [f64; 3],
    scale_back: [f64; 3],
    /// Each rotation row's sign: `decompose` keeps x and z positive and y's sign is the
    /// determinant's, so a negative x comes back as a half turn about z (rows 0 and 1 negated).
    row_signs: [f64; 3],
}

fn matrix_keys() -> [MatrixKey; 3] {
    [
        // Non-uniform scale, positive determinant: S, R and T come back as they went in.
        MatrixKey {
            s: [2.0, 0.5, 1.5],
            q: quaternion([1.0, 2.0, 3.0], 0.7),
            t: [1.0, -2.0, 3.0],
            scale_back: [2.0, 0.5, 1.5],
            row_signs: [1.0; 3],
        },
        // A mirror in y (negative determinant), and a turn of 2.5 rad whose trace is negative
        // (`FromRotationMatrix`'s other branches): y's sign is the determinant's, so as given.
        MatrixKey {
            s: [1.5, -2.0, 0.5],
            q: quaternion([-1.0, 0.5, 2.0], 2.5),
            t: [-4.0, 0.25, 0.0],
            scale_back: [1.5, -2.0, 0.5],
            row_signs: [1.0; 3],
        },
        // A mirror in x: decomposed as a mirror in y and a half turn about z, the same matrix.
        MatrixKey {
            s: [-1.0, 1.0, 3.0],
            q: quaternion([0.0, 1.0, 1.0], -0.9),
            t: [0.0, 5.0, -1.0],
            scale_back: [1.0, -1.0, 3.0],
            row_signs: [-1.0, -1.0, 1.0],
        },
    ]
}

/// One skinned triangle whose root bone has the keys of [`matrix_keys`] at frames 0, 10 and 20.
fn skeleton_scene() -> String {
    let keys: Vec<_> = matrix_keys()
        .iter()
        .enumerate()
        .map(|(k, key)| json!({"frame": 10 * k, "values": compose(key.s, key.q, key.t)}))
        .collect();
    json!({
        "meshes": [{"name": "skinned", "id": "skinned", "positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0,1,2],
            "skeletonId": 0, "matricesIndices": [0, 0, 0], "matricesWeights": [1,0,0,0, 1,0,0,0, 1,0,0,0]}],
        "skeletons": [{"id": 0, "name": "rig", "bones": [{"name": "root", "index": 0, "parentBoneIndex": -1,
            "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],
            "animation": {"name": "m", "property": "_matrix", "dataType": 3, "framePerSecond": 30, "keys": keys}}]}]
    })
    .to_string()
}

/// Each `_matrix` key becomes a position, quaternion and scaling key of the bone's node as
/// `Matrix.decompose` gives them.
#[test]
fn matrix_keys_are_decomposed_as_babylon_decomposes_them() {
    let (scene, _) =
        read_babylon(skeleton_scene().as_bytes(), None, "test.babylon", &ConvertOptions::default()).unwrap();
    let bone = scene.animation.skins[0].bones[0].node;
    let track = |wanted: NodeProperty| {
        let found = scene.animation.tracks.iter().find(
            |t| matches!(t.target, TrackTarget::Node { node, property, .. } if node == bone && property == wanted),
        );
        found.unwrap_or_else(|| panic!("no {wanted:?} track"))
    };
    let close = |a: &[f32], b: &[f64], what: &str| {
        assert_eq!(a.len(), b.len(), "{what}");
        assert!(a.iter().zip(b).all(|(&x, y)| (f64::from(x) - y).abs() < 1e-5), "{what}: {a:?} vs {b:?}");
    };
    for (k, key) in matrix_keys().iter().enumerate() {
        let [position, quaternion, scaling] =
            [NodeProperty::Position, NodeProperty::RotationQuaternion, NodeProperty::Scaling].map(|p| {
                let t = track(p);
                assert!(t.keys[k].step, "matrix keys hold until the next one");
                t.keys[k].values.clone()
            });
        close(&position, &key.t, &format!("key {k}: translation"));
        close(&scaling, &key.scale_back, &format!("key {k}: scaling"));
        let q: [f64; 4] = core::array::from_fn(|c| f64::from(quaternion[c]));
        let length = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        assert!((length - 1.0).abs() < 1e-5, "key {k}: quaternion {q:?} is not unit");
        let (got, given) = (rotation_rows(q), rotation_rows(key.q));
        for i in 0..3 {
            let expected = given[i].map(|v| v * key.row_signs[i]);
            close(&got[i].map(|v| v as f32), &expected, &format!("key {k}: rotation row {i}"));
        }
    }
}

/// The pose of a bone at a `_matrix` key's frame, and until the next key (step), is the key's
/// matrix again: decomposing and composing (`S · R · T`) lose nothing, mirrors included.
#[test]
fn a_posed_bone_is_its_matrix_key() {
    let bytes = s3d(&skeleton_scene());
    let model = Model::parse(&bytes).unwrap();
    let bone = model.animation().and_then(|a| a.skin_at(0)).and_then(|s| s.bone_node(0)).unwrap();
    for (k, key) in matrix_keys().iter().enumerate() {
        let m = compose(key.s, key.q, key.t);
        // Past the last key (frame 20) the skeleton's looping group would start again.
        let held = if k + 1 < matrix_keys().len() { 5.0 } else { 0.0 };
        for frame in [10.0 * k as f32, 10.0 * k as f32 + held] {
            let got = worlds(&model, frame, None)[bone].to_cols_array();
            let close = got.iter().zip(m).all(|(&g, e)| (f64::from(g) - e).abs() < 1e-5);
            assert!(close, "frame {frame}: {got:?}\nvs key {k} {m:?}");
        }
    }
}
