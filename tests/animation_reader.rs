//! The `.babylon` reader's animations (`Scene::animation`): animated nodes and the meshes they
//! carry, tracks and groups, morph targets, against hand-made JSON and the real scenes in
//! `../shared/assets/`.
#![cfg(feature = "convert")]

use std::path::PathBuf;

use soft3d::convert::scene::*;
use soft3d::convert::{read_babylon, read_babylon_file, ConvertError, ConvertOptions, Warning};

/// Reads JSON text as a scene named `test.babylon` with no directory.
fn read_text(json: &str) -> Result<(Scene, Vec<Warning>), ConvertError> {
    read_babylon(json.as_bytes(), None, "test.babylon", &ConvertOptions::default())
}

/// A scene of `../shared/assets/`, or `None` (with a note) when that directory is absent.
fn shared(rel: &str) -> Option<(Scene, Vec<Warning>, serde_json::Value)> {
    let path = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/assets/")).join(rel);
    if !path.exists() {
        println!("note: {} is absent: skipped", path.display());
        return None;
    }
    let (scene, warnings) = read_babylon_file(&path, &ConvertOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let bytes = std::fs::read(&path).unwrap();
    let json = serde_json::from_slice(bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes)).unwrap();
    Some((scene, warnings, json))
}

fn mul(a: &Matrix, b: &Matrix) -> Matrix {
    core::array::from_fn(|i| (0..4).map(|k| a[i / 4 * 4 + k] * b[k * 4 + i % 4]).sum())
}

/// Babylon's `RotationYawPitchRoll(y, x, z)` as a row-vector matrix: `Rz · Rx · Ry`.
#[rustfmt::skip]
fn euler([rx, ry, rz]: [f32; 3]) -> Matrix {
    let ((sx, cx), (sy, cy), (sz, cz)) = (rx.sin_cos(), ry.sin_cos(), rz.sin_cos());
    let x = [1., 0., 0., 0.,   0., cx, sx, 0.,   0., -sx, cx, 0.,   0., 0., 0., 1.];
    let y = [cy, 0., -sy, 0.,  0., 1., 0., 0.,   sy, 0., cy, 0.,    0., 0., 0., 1.];
    let z = [cz, sz, 0., 0.,   -sz, cz, 0., 0.,  0., 0., 1., 0.,    0., 0., 0., 1.];
    mul(&mul(&z, &x), &y)
}

/// A node's local matrix at rest, `S · R · T`.
fn rest_local(node: &NodeData) -> Matrix {
    let Rotation::Euler(r) = node.rotation else { panic!("{}: a quaternion", node.name) };
    let mut m = euler(r);
    for (i, v) in m[..12].iter_mut().enumerate() {
        *v *= node.scaling[i / 4];
    }
    m[12..15].copy_from_slice(&node.position);
    m
}

/// `World(node)` at rest: `Local · above · World(parent)`.
fn rest_world(anim: &AnimationData, node: u16) -> Matrix {
    let n = &anim.nodes[node as usize];
    let here = mul(&rest_local(n), &n.above);
    n.parent.map_or(here, |p| {
        assert!(p < node, "{}: parent {p} after it", n.name);
        mul(&here, &rest_world(anim, p))
    })
}

fn assert_close(a: &[f32], b: &[f32], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= 1e-5, "{what}[{i}]: {x} vs {y}\n{a:?}\n{b:?}");
    }
}

fn translation(x: f32, y: f32, z: f32) -> Matrix {
    let mut m = IDENTITY;
    m[12..15].copy_from_slice(&[x, y, z]);
    m
}

fn mesh_index(scene: &Scene, name: &str) -> u16 {
    scene.meshes.iter().position(|m| m.name == name).unwrap_or_else(|| panic!("no mesh {name}")) as u16
}

fn has(warnings: &[Warning], needles: &[&str]) -> bool {
    warnings.iter().any(|w| needles.iter().all(|n| w.0.contains(n)))
}

const TRIANGLE: &str = r#""positions":[0,0,0, 1,0,0, 0,1,0],"indices":[0,1,2]"#;

/// root (still transform node) > arm (animated mesh) > hand (still mesh) > wrist (animated
/// transform node) > finger (still mesh); a still mesh beside them.
fn hierarchy() -> String {
    let spin = r#"{"name":"spin","property":"rotation.y","dataType":0,"framePerSecond":10,
        "keys":[{"frame":0,"values":[0]},{"frame":10,"values":[3]}]}"#;
    let slide = r#"{"property":"position","dataType":1,"loopBehavior":2,
        "keys":[{"frame":5,"values":[0,0,1]},{"frame":20,"values":[0,0,4]}]}"#;
    format!(
        r#"{{
        "transformNodes": [
            {{"name":"root","id":"root","position":[10,0,0],"rotation":[0,1.5707964,0]}},
            {{"name":"wrist","id":"wrist","parentId":"hand","position":[0,0,2],"animations":[{slide}]}}
        ],
        "meshes": [
            {{"name":"arm","id":"arm","parentId":"root","position":[0,2,0],"scaling":[2,2,2],{TRIANGLE},
              "animations":[{spin}],"instances":[{{"name":"arm2","position":[5,5,5]}}]}},
            {{"name":"hand","id":"hand","parentId":"arm","position":[0,0,1],"scaling":[3,3,3],{TRIANGLE}}},
            {{"name":"finger","id":"finger","parentId":"wrist","position":[1,0,0],{TRIANGLE}}},
            {{"name":"still","id":"still","parentId":"root",{TRIANGLE}}}
        ]}}"#
    )
}

/// Nodes come after their animated parents; `above` is the still part between a node and
/// its animated parent (its still ancestors' world matrix when it has none), `below` the still
/// part between a mesh and its animated node, so that at rest they rebuild each mesh's world.
#[test]
fn nodes_and_links_of_a_hierarchy() {
    let (scene, warnings) = read_text(&hierarchy()).unwrap();
    let anim = &scene.animation;
    let names: Vec<&str> = anim.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names, ["arm", "wrist"]);
    let (arm, wrist) = (&anim.nodes[0], &anim.nodes[1]);
    // The arm's parent is still: `above` is the root's world matrix, Ry(90°) then a move.
    assert_eq!(arm.parent, None);
    assert_close(&arm.above, &[0., 0., -1., 0., 0., 1., 0., 0., 1., 0., 0., 0., 10., 0., 0., 1.], "arm above");
    assert_eq!((arm.position, arm.rotation, arm.scaling), ([0., 2., 0.], Rotation::Euler([0.; 3]), [2.; 3]));
    // The wrist hangs from the arm through the still hand.
    assert_eq!(wrist.parent, Some(0));
    let hand_local = [3., 0., 0., 0., 0., 3., 0., 0., 0., 0., 3., 0., 0., 0., 1., 1.];
    assert_close(&wrist.above, &hand_local, "wrist above");
    assert_eq!(wrist.position, [0., 0., 2.]);

    let link = |name: &str| {
        let mesh = mesh_index(&scene, name);
        anim.links.iter().find(|l| l.mesh == mesh).unwrap_or_else(|| panic!("{name} not linked"))
    };
    assert_eq!((link("arm").node, link("arm").below), (0, IDENTITY));
    assert_eq!(link("hand").node, 0);
    assert_close(&link("hand").below, &hand_local, "hand below");
    assert_eq!(link("finger").node, 1);
    assert_close(&link("finger").below, &translation(1., 0., 0.), "finger below");
    assert_eq!(anim.links.len(), 3, "the still mesh is not linked: {:?}", anim.links);
    // At rest (no autoAnimate) `below · World(node)` is the still picture's world matrix.
    for l in &anim.links {
        let world = mul(&l.below, &rest_world(anim, l.node));
        assert_close(&world, &scene.meshes[l.mesh as usize].world, &scene.meshes[l.mesh as usize].name);
    }

    assert_eq!(anim.tracks.len(), 2);
    let spin = &anim.tracks[0];
    let target = TrackTarget::Node { node: 0, property: NodeProperty::Rotation, first: 1, count: 1 };
    assert_eq!((spin.target, spin.fps, spin.looping), (target, 10., Loop::Cycle));
    assert_eq!(
        spin.keys.iter().map(|k| (k.frame, k.values.clone())).collect::<Vec<_>>(),
        [(0., vec![0.]), (10., vec![3.])]
    );
    let slide = &anim.tracks[1];
    let target = TrackTarget::Node { node: 1, property: NodeProperty::Position, first: 0, count: 3 };
    assert_eq!((slide.target, slide.fps, slide.looping), (target, 30., Loop::Constant));
    // One group per node for tracks in no group, over their keys, looping.
    let groups: Vec<_> =
        anim.groups.iter().map(|g| (g.name.as_str(), g.from, g.to, g.looping, g.tracks.clone())).collect();
    assert_eq!(groups, [("arm", 0., 10., true, vec![0]), ("wrist", 5., 20., true, vec![1])]);
    assert!(anim.morphs.is_empty() && !anim.is_empty());
    assert!(has(&warnings, &["mesh \"arm\"", "instances of animated meshes are drawn still"]), "{warnings:?}");
}

/// The Babylon.js logo spins, moves and scales by `autoAnimate`: one node, three tracks of
/// three keys at 24 frames a second, one looping group over frames 1 to 100.
#[test]
fn logo_animation() {
    let Some((scene, _, _)) = shared("logo-animation/logo.babylon") else { return };
    let anim = &scene.animation;
    assert_eq!(anim.nodes.len(), 1);
    let logo = &anim.nodes[0];
    assert_eq!((logo.name.as_str(), logo.parent, logo.above), ("logo", None, IDENTITY));
    assert_eq!(logo.position, [0., 1.142, 0.]);
    assert_eq!(logo.rotation, Rotation::Euler([0., 1.3963, 0.]));
    let properties: Vec<_> = anim.tracks.iter().map(|t| t.target).collect();
    let node = |property| TrackTarget::Node { node: 0, property, first: 0, count: 3 };
    assert_eq!(properties, [node(NodeProperty::Rotation), node(NodeProperty::Position), node(NodeProperty::Scaling)]);
    for t in &anim.tracks {
        assert_eq!((t.keys.len(), t.fps, t.looping), (3, 24., Loop::Cycle));
        assert!(t.keys.iter().all(|k| k.values.len() == 3 && k.tangents.is_none() && !k.step));
    }
    assert_eq!(anim.tracks[1].keys[1].values, [0., 2., 0.]);
    let g = &anim.groups;
    assert_eq!(g.len(), 1);
    assert_eq!((g[0].name.as_str(), g[0].from, g[0].to, g[0].looping), ("logo", 1., 100., true));
    assert_eq!(g[0].tracks, [0, 1, 2]);
    let logo_mesh = mesh_index(&scene, "logo");
    assert_eq!(anim.links, [MeshLink { mesh: logo_mesh, node: 0, below: IDENTITY }]);
    assert!(anim.morphs.is_empty());
}

/// Two cubes with two morph targets each: deltas with normals for the 36 vertices, one
/// influence track per target.
#[test]
fn morph_cube() {
    let Some((scene, _, json)) = shared("morph-cube/AnimatedMorphCube.babylon") else { return };
    let anim = &scene.animation;
    assert!(anim.nodes.is_empty() && anim.links.is_empty());
    assert_eq!(anim.morphs.len(), 2);
    for (k, morph) in anim.morphs.iter().enumerate() {
        let mesh = &scene.meshes[morph.mesh as usize];
        assert_eq!(mesh.positions.len(), 36);
        let names: Vec<&str> = morph.targets.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["Box002", "Box003"]);
        for (t, target) in morph.targets.iter().enumerate() {
            assert_eq!(target.positions.len(), 36);
            assert_eq!(target.normals.as_ref().map(Vec::len), Some(36));
            assert!(target.positions.iter().any(|d| d.iter().any(|&x| x.abs() > 1e-3)), "{} moves", target.name);
            // Base + delta is the file's absolute target position.
            let file = &json["morphTargetManagers"][k]["targets"][t]["positions"];
            for (v, (p, d)) in mesh.positions.iter().zip(&target.positions).enumerate() {
                let expected: Vec<f32> = (0..3).map(|c| file[3 * v + c].as_f64().unwrap() as f32).collect();
                assert_close(&[p[0] + d[0], p[1] + d[1], p[2] + d[2]], &expected, "target position");
            }
        }
    }
    assert_eq!(anim.tracks.len(), 4);
    let targets: Vec<_> = anim.tracks.iter().map(|t| t.target).collect();
    let morph = |morph, target| TrackTarget::Morph { morph, target };
    assert_eq!(targets, [morph(0, 0), morph(0, 1), morph(1, 0), morph(1, 1)]);
    assert!(anim.tracks.iter().all(|t| t.fps == 30. && t.keys.iter().all(|k| k.values.len() == 1)));
    // Each target's own tracks are a group of their own, over their keys.
    assert_eq!(anim.groups.len(), 4);
    assert!(anim.groups.iter().all(|g| g.looping && g.tracks.len() == 1));
}

/// Blender shape keys: three targets on Male_Head, without normals, played by the file's
/// `KeyAction` group.
#[test]
fn shapekey_animation() {
    let Some((scene, warnings, _)) = shared("shapekey/shapekeyAnimation.babylon") else { return };
    let anim = &scene.animation;
    assert!(anim.nodes.is_empty() && anim.links.is_empty());
    assert_eq!(anim.morphs.len(), 1);
    let head = mesh_index(&scene, "Male_Head");
    let morph = &anim.morphs[0];
    assert_eq!(morph.mesh, head);
    let names: Vec<&str> = morph.targets.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["head-open", "head-wide", "head-upper"]);
    let vertices = scene.meshes[head as usize].positions.len();
    assert!(morph.targets.iter().all(|t| t.normals.is_none() && t.positions.len() == vertices && t.influence == 0.));
    assert_eq!(anim.groups.len(), 1);
    let group = &anim.groups[0];
    assert_eq!((group.name.as_str(), group.from, group.to), ("KeyAction", 1., 124.));
    assert!(!group.looping, "no loopAnimation: Babylon.js's default, false");
    assert_eq!(group.tracks, [0, 1, 2]);
    let targets: Vec<_> = anim.tracks.iter().map(|t| t.target).collect();
    let morph = |target| TrackTarget::Morph { morph: 0, target };
    assert_eq!(targets, [morph(0), morph(1), morph(2)]);
    assert!(anim.tracks.iter().all(|t| t.fps == 24.));
    assert!(!has(&warnings, &["morph"]), "{warnings:?}");
}

/// The rabbit's skeleton: four bones as nodes (bone 0 the root), their `_matrix` keys as step
/// tracks of position, quaternion and scaling, one looping group over the keys, and the
/// skinned mesh's four influences a vertex.
#[test]
fn rabbit_skeleton_is_read() {
    let Some((scene, warnings, _)) = shared("rabbit/Rabbit.babylon") else { return };
    assert!(!has(&warnings, &["skeleton"]), "{warnings:?}");
    let anim = &scene.animation;
    let parents: Vec<Option<u16>> = anim.nodes.iter().map(|n| n.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(0), Some(0)]);
    assert_eq!(anim.tracks.len(), 12);
    assert!(anim.tracks.iter().all(|t| t.fps == 60. && t.keys.len() == 141 && t.keys.iter().all(|k| k.step)));
    assert_eq!(anim.groups.len(), 1);
    let g = &anim.groups[0];
    assert!(g.looping && g.from == 0. && (g.to - 100.014_29).abs() < 1e-4 && g.tracks.len() == 12, "{g:?}");
    assert_eq!(anim.skins.len(), 1);
    let skin = &anim.skins[0];
    assert_eq!(skin.bones.len(), 4);
    assert_eq!(skin.vertices.len(), scene.meshes[skin.mesh as usize].positions.len());
    assert!(skin.vertices.iter().all(|(_, w)| (w.iter().sum::<f32>() - 1.0).abs() < 1e-3));
    // The root bone's inverse bind undoes its matrix (the bind pose).
    let bind = soft3d::Mat4::from_cols_array(&skin.bones[0].inverse_bind).inverse();
    assert!((bind.w_axis.y - 1.874).abs() < 1e-3, "{bind}");
}

/// A still scene has no animation.
#[test]
fn still_scenes_have_no_animation() {
    for rel in ["suzanne/monkey.babylon", "teapot/teapot.babylon", "instances/Instances.babylon"] {
        let Some((scene, _, _)) = shared(rel) else { return };
        assert!(scene.animation.is_empty(), "{rel}: {:?}", scene.animation);
        assert_eq!(scene.animation, AnimationData::default(), "{rel}");
    }
}

fn error_of(json: &str) -> String {
    match read_text(json) {
        Ok(_) => panic!("accepted: {json}"),
        Err(e) => e.to_string(),
    }
}

/// A key of the wrong type is an error naming the node, the animation, the key and the field.
#[test]
fn malformed_keys_are_errors_naming_the_place() {
    let e = error_of(&format!(
        r#"{{"meshes":[{{"name":"M",{TRIANGLE},"animations":[{{"property":"position","dataType":1,
        "keys":[{{"frame":0,"values":[0,0,0]}},{{"frame":"ten","values":[1,1,1]}}]}}]}}]}}"#
    ));
    assert_eq!(e, r#"test.babylon: mesh "M": animations[0].keys[1].frame: expected a finite number, found "ten""#);
    let e = error_of(&format!(
        r#"{{"meshes":[{{"name":"M",{TRIANGLE},"animations":[{{"property":"scaling","keys":[{{"frame":0,"values":[1,"x",1]}}]}}]}}]}}"#
    ));
    assert!(e.contains(r#"mesh "M": animations[0].keys[0].values[1]: expected a finite number"#), "{e}");
    let e = error_of(
        r#"{"animationGroups":[{"name":"G","targetedAnimations":[{"targetId":"t","animation":
        {"property":"influence","keys":[{"frame":0}]}}]}]}"#,
    );
    assert_eq!(e, r#"test.babylon: animation group "G": targetedAnimations[0].animation.keys[0].values: missing"#);
    let e = error_of(r#"{"morphTargetManagers":[{"id":1,"targets":[{"name":"T","positions":[0,null]}]}]}"#);
    assert!(e.contains(r#"morph target manager "1": targets[0].positions[1]"#), "{e}");
}

/// A morph target of the wrong length drops the mesh's morph targets, with a warning naming
/// the mesh, the manager and the target; skipped properties, data types, targets and empty
/// tracks are warnings naming them; unsorted keys are sorted.
#[test]
fn odd_animations_are_warnings_naming_the_place() {
    let json = format!(
        r#"{{
        "morphTargetManagers":[{{"id":"mm","targets":[
            {{"name":"good","positions":[0,0,1, 1,0,1, 0,1,1],
              "animations":[{{"property":"influence","keys":[{{"frame":0,"values":1}}]}}]}},
            {{"name":"short","positions":[0,0,1, 1,0,1]}}]}}],
        "cameras":[{{"name":"cam","id":"cam","position":[0,0,-5],"animations":[{{"property":"fov","keys":[]}}]}}],
        "meshes":[
            {{"name":"M","id":"m",{TRIANGLE},"morphTargetManagerId":"mm","animations":[
                {{"name":"m","property":"_matrix","dataType":3,"keys":[{{"frame":0,"values":[]}}]}},
                {{"property":"rotation","dataType":2,"keys":[{{"frame":0,"values":[0,0,0,1]}}]}},
                {{"property":"scaling","keys":[]}},
                {{"property":"position.y","keys":[{{"frame":9,"values":2}},{{"frame":3,"values":1}}]}}]}}
        ],
        "animationGroups":[{{"name":"G","targetedAnimations":[
            {{"targetId":"nobody","animation":{{"property":"position","keys":[{{"frame":0,"values":[0,0,0]}}]}}}},
            {{"targetId":"cam","animation":{{"property":"upVector","keys":[{{"frame":0,"values":[0,0,0]}}]}}}}]}}]
        }}"#
    );
    let (scene, warnings) = read_text(&json).unwrap();
    let anim = &scene.animation;
    for needles in [
        &["mesh \"M\"", "morph target manager \"mm\"", "target \"short\"", "positions has 6 numbers but 3 vertices"][..],
        &["mesh \"M\": animations[0] (\"m\")", "property \"_matrix\" is not played", "skipped"],
        &["mesh \"M\": animations[1]", "dataType 2 (quaternion) for property \"rotation\""],
        &["mesh \"M\": animations[2]", "no keys, skipped"],
        &["mesh \"M\": animations[3]", "keys are not in frame order"],
        &["animation group \"G\": targetedAnimations[0] (target \"nobody\")", "no mesh or transform node"],
        &["animation group \"G\": targetedAnimations[1] (target \"cam\")", "property \"upVector\" is not played"],
        &["morph target manager \"mm\"", "no drawn mesh uses it"],
        &["camera \"cam\": animations[0]", "no keys, skipped"],
    ] {
        assert!(has(&warnings, needles), "{needles:?} in {warnings:#?}");
    }
    assert!(anim.morphs.is_empty());
    assert_eq!(anim.tracks.len(), 1);
    let frames: Vec<f32> = anim.tracks[0].keys.iter().map(|k| k.frame).collect();
    assert_eq!(frames, [3., 9.]);
    assert_eq!(anim.groups.len(), 1, "the empty file group is dropped: {:?}", anim.groups);
    assert_eq!((anim.groups[0].from, anim.groups[0].to), (3., 9.));
}

/// Babylon.js's packed key layout (tangents and the interpolation after the value), morph
/// deltas against the file's normals, a group naming a morph target by id and a node by name,
/// and `autoAnimate` ranges.
#[test]
fn packed_keys_groups_and_auto_animate() {
    let json = format!(
        r#"{{
        "morphTargetManagers":[{{"id":7,"targets":[
            {{"name":"up","id":"m-up","influence":0.25,"positions":[0,0,1, 1,0,1, 0,1,1],"normals":[0,1,0, 0,1,0, 0,1,0]}}]}}],
        "meshes":[
            {{"name":"M","id":"m-id",{TRIANGLE},"normals":[0,0,2, 0,0,2, 0,0,2],"morphTargetManagerId":7,
              "rotationQuaternion":[0,0,0,1],
              "autoAnimate":true,"autoAnimateFrom":2,"autoAnimateTo":8,"autoAnimateLoop":false,"animations":[
                {{"property":"rotationQuaternion","dataType":2,"framePerSecond":60,"keys":[
                    {{"frame":0,"values":[0,0,0,1, 0,0,0,0, 0,0,0.5,0]}},
                    {{"frame":10,"values":[0,1,0,0, 0,0,0.5,0, 0,0,0,0, 1]}}]}}]}}
        ],
        "animationGroups":[{{"name":"G","from":0,"to":50,"loopAnimation":true,"targetedAnimations":[
            {{"targetId":"m-up","animation":{{"property":"influence","dataType":0,"keys":[
                {{"frame":0,"values":[0, null, 1]}},{{"frame":50,"values":[1, 2, null, 1]}}]}}}},
            {{"targetId":"M","animation":{{"property":"scaling.x","keys":[{{"frame":0,"values":[1]}}]}}}}]}}]
        }}"#
    );
    let (scene, warnings) = read_text(&json).unwrap();
    let anim = &scene.animation;
    assert!(warnings.is_empty(), "{warnings:?}");
    let morph = &anim.morphs[0].targets[0];
    assert_eq!((morph.name.as_str(), morph.influence), ("up", 0.25));
    assert_eq!(morph.positions, [[0., 0., 1.]; 3]);
    // Against the file's normals (0, 0, 2), not the unit ones the mesh keeps.
    assert_eq!(morph.normals.as_deref(), Some(&[[0., 1., -2.]; 3][..]));
    assert_eq!(anim.nodes[0].rotation, Rotation::Quaternion([0., 0., 0., 1.]));

    let [influence, scaling, quaternion] = &anim.tracks[..] else { panic!("{:?}", anim.tracks) };
    assert_eq!(influence.target, TrackTarget::Morph { morph: 0, target: 0 });
    // A missing (null, or zero quaternion) tangent stays missing: that span is linear.
    assert_eq!(influence.keys[0].tangents, Some((vec![], vec![1.])));
    assert_eq!(influence.keys[1].tangents, Some((vec![2.], vec![])));
    assert!(influence.keys[1].step && !influence.keys[0].step);
    assert_eq!(scaling.target, TrackTarget::Node { node: 0, property: NodeProperty::Scaling, first: 0, count: 1 });
    let target = TrackTarget::Node { node: 0, property: NodeProperty::RotationQuaternion, first: 0, count: 4 };
    assert_eq!((quaternion.target, quaternion.fps), (target, 60.));
    assert_eq!(quaternion.keys[0].tangents, Some((vec![], vec![0., 0., 0.5, 0.])));
    assert_eq!(quaternion.keys[1].tangents, Some((vec![0., 0., 0.5, 0.], vec![])));
    assert!(quaternion.keys[1].step);
    let groups: Vec<_> =
        anim.groups.iter().map(|g| (g.name.as_str(), g.from, g.to, g.looping, g.tracks.clone())).collect();
    assert_eq!(groups, [("G", 0., 50., true, vec![0, 1]), ("M", 2., 8., false, vec![2])]);
}
