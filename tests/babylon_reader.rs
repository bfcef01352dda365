//! The `.babylon` reader against the real scenes in `assets/` and against malformed input.
#![cfg(feature = "convert")]

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use soft3d::convert::scene::{Matrix, MeshData, Scene};
use soft3d::convert::{read_babylon, read_babylon_file, ConvertError, ConvertOptions, UvOrigin, Warning};

fn asset(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join(rel)
}

fn read_with(rel: &str, opts: &ConvertOptions) -> (Scene, Vec<Warning>) {
    read_babylon_file(&asset(rel), opts).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn read(rel: &str) -> (Scene, Vec<Warning>) {
    read_with(rel, &ConvertOptions::default())
}

/// Reads JSON text as a scene named `test.babylon` with no directory.
fn read_text(json: &str) -> Result<(Scene, Vec<Warning>), ConvertError> {
    read_babylon(json.as_bytes(), None, "test.babylon", &ConvertOptions::default())
}

fn triangles(scene: &Scene) -> usize {
    scene.meshes.iter().map(|m| m.indices.len() / 3).sum()
}

fn mesh<'s>(scene: &'s Scene, name: &str) -> &'s MeshData {
    scene.meshes.iter().find(|m| m.name == name).unwrap_or_else(|| panic!("no mesh {name}"))
}

fn point(m: &Matrix, p: [f32; 3]) -> [f32; 3] {
    core::array::from_fn(|c| p[0] * m[c] + p[1] * m[4 + c] + p[2] * m[8 + c] + m[12 + c])
}

/// Each triangle corner's position (in world space when `world`) and UV, in index order.
fn corners(m: &MeshData, world: bool) -> Vec<([f32; 3], [f32; 2])> {
    let uv = |i: usize| m.uvs.as_ref().map_or([0.; 2], |uv| uv[i]);
    let pos = |i: usize| {
        if world {
            point(&m.world, m.positions[i])
        } else {
            m.positions[i]
        }
    };
    m.indices.iter().map(|&i| (pos(i as usize), uv(i as usize))).collect()
}

fn assert_close(a: &[f32], b: &[f32], tol: f32, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths differ");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= tol, "{what}[{i}]: {x} vs {y}");
    }
}

fn assert_same_corners(a: &MeshData, b: &MeshData, world: bool, tol: f32) {
    let (ca, cb) = (corners(a, world), corners(b, world));
    assert_eq!(ca.len(), cb.len(), "{}: corner counts differ", a.name);
    for (k, ((pa, ua), (pb, ub))) in ca.iter().zip(&cb).enumerate() {
        assert_close(pa, pb, tol, &format!("{} corner {k} position", a.name));
        assert_close(ua, ub, tol, &format!("{} corner {k} uv", a.name));
    }
}

#[test]
fn every_asset_reads_with_the_expected_triangle_counts() {
    let top = ConvertOptions { uv_origin: UvOrigin::Top, ..Default::default() };
    let cases: [(&str, usize, usize, usize); 10] = [
        // file, meshes, triangles, instances
        ("suzanne/monkey.babylon", 1, 966, 0),
        ("blender-legacy/blender.babylon", 2, 14, 0),
        ("blender-split/blender.babylon", 2, 14, 0),
        ("teapot/teapot.babylon", 1, 1560, 0),
        ("tree/tree.babylon", 1, 968, 0),
        ("double-sided/DoubleSidedMaterial.babylon", 1, 4, 0),
        ("instances/Instances.babylon", 1, 12, 2),
        ("opaque/Opaque.babylon", 3, 2880, 0),
        ("opaque/Opaque.binary.babylon", 3, 2880, 0),
        ("shapekey/shapekeyAnimation.babylon", 4, 3210, 0),
    ];
    for (file, meshes, tris, instances) in cases {
        let opts = if file.starts_with("suzanne") { top } else { ConvertOptions::default() };
        let (scene, warnings) = read_with(file, &opts);
        let vertices: usize = scene.meshes.iter().map(|m| m.positions.len()).sum();
        println!(
            "{file}: {} meshes, {vertices} vertices, {} triangles, {} instances, {} materials, {} textures, {} lights, camera {}",
            scene.meshes.len(),
            triangles(&scene),
            scene.instances.len(),
            scene.materials.len(),
            scene.textures.len(),
            scene.lights.len(),
            scene.camera.is_some()
        );
        for t in &scene.textures {
            println!("    texture {:?} {}x{} alpha {}", t.name, t.width, t.height, t.has_alpha());
        }
        for w in &warnings {
            println!("    warning: {w}");
        }
        assert_eq!((scene.meshes.len(), triangles(&scene), scene.instances.len()), (meshes, tris, instances), "{file}");
        for m in &scene.meshes {
            let n = m.positions.len();
            assert!(m.indices.iter().all(|&i| (i as usize) < n) && m.indices.len() % 3 == 0);
            assert_eq!(m.normals.len(), n);
            assert!(m.normals.iter().all(|v| ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.).abs() < 1e-4));
            assert!(m.uvs.as_ref().is_none_or(|uv| uv.len() == n));
            assert!(!m.submeshes.is_empty());
            for s in &m.submeshes {
                assert!(s.index_start % 3 == 0 && s.index_count % 3 == 0);
                assert!((s.index_start + s.index_count) as usize <= m.indices.len());
                assert!(s.material.is_none_or(|i| (i as usize) < scene.materials.len()));
            }
        }
        for mat in &scene.materials {
            assert!(mat.texture.is_none_or(|t| (t as usize) < scene.textures.len()));
        }
        for t in &scene.textures {
            assert_eq!(t.rgba.len(), t.width as usize * t.height as usize * 4);
        }
    }
}

#[test]
fn missing_textures_are_warnings_and_keep_the_diffuse_colour() {
    let (scene, warnings) = read("blender-split/blender.babylon");
    assert!(scene.textures.is_empty());
    assert_eq!(scene.materials.len(), 2);
    assert!(scene.materials.iter().all(|m| m.texture.is_none() && m.diffuse == [0.64; 3]));
    let text: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    assert!(text.iter().any(|w| w.contains("\"concrete5.png\" not found") && w.contains("mesh \"Plane\"")), "{text:?}");
    assert!(text.iter().any(|w| w.contains("\"Metal1.png\" not found")), "{text:?}");
}

/// A texture named relative to another folder than the scene's is found by its bare name
/// next to the scene, then in the folder above, with a warning naming where it looked.
#[test]
fn texture_paths_fall_back_to_the_bare_file_name() {
    let root = std::env::temp_dir().join(format!("soft3d-texture-paths-{}", std::process::id()));
    let models = root.join("models");
    std::fs::create_dir_all(&models).unwrap();
    let png = |path: &Path| image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 0, 0, 255])).save(path).unwrap();
    png(&models.join("drone.png"));
    png(&root.join("shared.png"));
    let scene = |texture: &str| {
        format!(
            r#"{{"materials":[{{"id":"m","diffuseTexture":{{"name":"{texture}"}}}}],
            "meshes":[{{"name":"M","materialId":"m","positions":[0,0,0,1,0,0,0,1,0],"uvs":[0,0,1,0,0,1]}}]}}"#
        )
    };
    let read_in_models = |texture: &str| {
        let json = scene(texture);
        read_babylon(json.as_bytes(), Some(&models), "scene.babylon", &ConvertOptions::default()).unwrap()
    };
    let (found, warnings) = read_in_models("./models/drone.png");
    assert_eq!(found.textures.len(), 1);
    let text: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    let tried = models.join("./models/drone.png").display().to_string();
    let used = models.join("drone.png").display().to_string();
    assert!(text.len() == 1 && text[0].contains(&format!("not found at {tried}: {used} used")), "{text:?}");
    // A Windows separator (an escaped backslash in the JSON).
    let (found, warnings) = read_in_models("textures\\\\shared.png");
    assert_eq!(found.textures.len(), 1);
    assert!(warnings[0].0.contains(&format!("{} used", root.join("shared.png").display())), "{warnings:?}");
    let (found, warnings) = read_in_models("nowhere/missing.png");
    assert!(found.textures.is_empty());
    let missing = root.join("missing.png").display().to_string();
    assert!(warnings[0].0.contains("not found (tried") && warnings[0].0.contains(&missing), "{warnings:?}");
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn legacy_and_split_blender_scenes_have_the_same_geometry() {
    let (legacy, _) = read("blender-legacy/blender.babylon");
    let (split, _) = read("blender-split/blender.babylon");
    for name in ["Plane", "Cube"] {
        let (a, b) = (mesh(&legacy, name), mesh(&split, name));
        assert_eq!(a.indices.len(), b.indices.len(), "{name}");
        let plane = name == "Plane";
        // The legacy plane has its scaling baked into the vertices: compare it in world space.
        assert_same_corners(a, b, plane, 1e-4);
    }
    // The cube is animated (autoAnimate): both files show its first frame, whatever their
    // static `position` says (legacy 9.975, split 0); the rotation keys differ in sign only.
    let (a, b) = (mesh(&legacy, "Cube"), mesh(&split, "Cube"));
    assert_close(&a.world[12..15], &[0., 0., 0.0291], 1e-6, "legacy cube translation");
    assert_close(&b.world[12..15], &[0., 0., 0.0291], 1e-6, "split cube translation");
    assert_close(&a.world, &b.world, 0.04, "cube world");
    assert_eq!(legacy.camera, split.camera);
    assert_eq!(legacy.lights, split.lights);
}

#[test]
fn binary_opaque_equals_json_opaque() {
    let (json, _) = read("opaque/Opaque.babylon");
    let (binary, _) = read("opaque/Opaque.binary.babylon");
    assert_eq!(json.meshes.len(), 3);
    for (a, b) in json.meshes.iter().zip(&binary.meshes) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.indices, b.indices);
        assert_eq!(a.submeshes, b.submeshes);
        assert_close(a.positions.as_flattened(), b.positions.as_flattened(), 1e-6, "positions");
        assert_close(a.normals.as_flattened(), b.normals.as_flattened(), 1e-6, "normals");
        let (ua, ub) = (a.uvs.as_ref().unwrap(), b.uvs.as_ref().unwrap());
        assert_close(ua.as_flattened(), ub.as_flattened(), 1e-6, "uvs");
        assert_close(&a.world, &b.world, 1e-6, "world");
    }
    assert_eq!(json.materials, binary.materials);
    // PBR metallic-roughness materials use their baseColor.
    let diffuse: Vec<[f32; 3]> = json.materials.iter().map(|m| m.diffuse).collect();
    assert_eq!(diffuse, [[1., 0., 0.], [0., 1., 0.], [0., 0., 0.8]]);
}

#[test]
fn suzanne_uv_origin_top_flips_v() {
    let (bottom, _) = read("suzanne/monkey.babylon");
    let (top, _) =
        read_with("suzanne/monkey.babylon", &ConvertOptions { uv_origin: UvOrigin::Top, ..Default::default() });
    let (b, t) = (bottom.meshes[0].uvs.as_ref().unwrap(), top.meshes[0].uvs.as_ref().unwrap());
    assert_eq!(b.len(), 886);
    for (b, t) in b.iter().zip(t) {
        assert_eq!(b[0], t[0]);
        assert!((t[1] - (1. - b[1])).abs() < 1e-6);
    }
    let tex = &top.textures[0];
    assert_eq!((tex.name.as_str(), tex.has_alpha()), ("Suzanne.jpg", false));
    // The 2013 light is written as `data`.
    assert_eq!(top.lights[0].vector, [4.0762, 5.9039, 1.0055]);
}

#[test]
fn tree_texture_is_a_tga_with_alpha() {
    let (scene, warnings) = read("tree/tree.babylon");
    // Its opacity map is said to be left out (the diffuse texture's alpha cuts the leaves).
    assert!(warnings.len() == 1 && warnings[0].0.contains("'s opacityTexture"), "{warnings:?}");
    let tex = &scene.textures[0];
    assert_eq!((tex.width, tex.height), (512, 512));
    assert!(tex.has_alpha());
    assert_eq!(scene.materials[0].texture, Some(0));
}

#[test]
fn textures_are_resized_on_request() {
    let opts = ConvertOptions { max_texture: Some(100), power_of_two: true, ..Default::default() };
    let (scene, _) = read_with("tree/tree.babylon", &opts);
    let tex = &scene.textures[0];
    assert_eq!((tex.width, tex.height, tex.rgba.len()), (64, 64, 64 * 64 * 4));
}

#[test]
fn double_sided_has_two_submeshes_with_their_own_textures() {
    let (scene, warnings) = read("double-sided/DoubleSidedMaterial.babylon");
    assert!(warnings.is_empty(), "{warnings:?}");
    let m = &scene.meshes[0];
    assert_eq!(m.submeshes.len(), 2);
    let (a, b) = (m.submeshes[0].material.unwrap(), m.submeshes[1].material.unwrap());
    assert_ne!(a, b);
    let (ta, tb) = (scene.materials[a as usize].texture.unwrap(), scene.materials[b as usize].texture.unwrap());
    assert_ne!(ta, tb);
    assert_eq!(scene.textures[ta as usize].name, "TestImage.png");
    assert_eq!(scene.textures[tb as usize].name, "Warhol.jpg");
    // vScale -1 and invertY false cancel out: v' = 1 - (-v) = 1 + v, the same texel as v.
    let uv = m.uvs.as_ref().unwrap();
    assert_close(&uv[0], &[0., 2.], 1e-6, "uv 0");
    assert_close(&uv[2], &[1., 3.], 1e-6, "uv 2");
}

#[test]
fn instances_make_three_boxes() {
    let (scene, _) = read("instances/Instances.babylon");
    assert_eq!(scene.meshes.len(), 1);
    let offsets: Vec<[f32; 3]> = scene.instances.iter().map(|i| [i.world[12], i.world[13], i.world[14]]).collect();
    assert!(scene.instances.iter().all(|i| i.mesh == 0));
    let base = [scene.meshes[0].world[12], scene.meshes[0].world[13], scene.meshes[0].world[14]];
    assert_eq!(offsets, [[2., 0., 0.], [4., 0., 0.]]);
    assert_ne!(base, offsets[0]);
}

#[test]
fn shapekey_has_embedded_textures_and_a_hierarchy() {
    let (scene, warnings) = read("shapekey/shapekeyAnimation.babylon");
    // Its morph targets and their animation group are read (tests/animation_reader.rs).
    assert!(warnings.is_empty(), "{warnings:?}");
    // Two distinct embedded images (the teeth texture is shared by name), both decoded.
    let names: Vec<&str> = scene.textures.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["skin1.png", "teeth3 copy.jpg"]);
    assert!(scene.textures.iter().all(|t| t.width > 1 && t.height > 1));
    assert!(scene.materials.iter().all(|m| m.texture.is_some()));
    // The ArcRotateCamera looks at the origin.
    let cam = scene.camera.as_ref().unwrap();
    assert_eq!((cam.position, cam.target), ([0., 0., -0.5], [0.; 3]));

    // The file's parent is the identity: move it and check the children follow.
    let path = asset("shapekey/shapekeyAnimation.babylon");
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    json["meshes"][0]["position"] = serde_json::json!([1, 2, 3]);
    json["meshes"][0]["rotation"] = serde_json::json!([0, 0.5, 0]);
    let bytes = serde_json::to_vec(&json).unwrap();
    let (moved, _) = read_babylon(&bytes, path.parent(), "shapekey", &ConvertOptions::default()).unwrap();
    let (parent, child) = (mesh(&moved, "Male_Head"), mesh(&moved, "teeth1"));
    let child_local = mesh(&scene, "teeth1").world; // parent is the identity in the file
    assert_close(&child_local[..3], &[0.917, 0., 0.], 1e-6, "teeth1 local");
    assert_ne!(child.world, child_local);
    let p = [0.1, 0.2, 0.3];
    assert_close(&point(&child.world, p), &point(&parent.world, point(&child_local, p)), 1e-5, "composed");
}

#[test]
fn cameras_and_lights() {
    let (teapot, warnings) = read("teapot/teapot.babylon");
    assert!(warnings.is_empty(), "{warnings:?}");
    let cam = teapot.camera.unwrap();
    // `rotation` [0.4615, -0.8149, 0]: forward (0,0,1) rotated by Ry·Rx.
    let (rx, ry) = (0.4615f32, -0.8149f32);
    let forward = [rx.cos() * ry.sin(), -rx.sin(), rx.cos() * ry.cos()];
    let expect: Vec<f32> = (0..3).map(|k| cam.position[k] + forward[k]).collect();
    assert_close(&cam.target, &expect, 1e-5, "teapot target");
    assert_eq!((cam.fov, cam.near, cam.far), (0.8576, 0.1, 100.));
    assert_eq!(teapot.meshes[0].uvs, None);
}

#[test]
fn missing_normals_are_computed_facing_the_front() {
    // One triangle, counter-clockwise seen from -z (the camera side): its normal is -z.
    let (scene, _) =
        read_text(r#"{"meshes":[{"name":"T","positions":[0,0,0, 1,0,0, 0,1,0],"indices":null}]}"#).unwrap();
    let m = &scene.meshes[0];
    assert_eq!(m.indices, [0, 1, 2]);
    assert!(m.normals.iter().all(|n| *n == [0., 0., -1.]));
    assert_eq!(m.submeshes.len(), 1);
    assert_eq!(m.submeshes[0].material, None);
}

#[test]
fn transform_nodes_and_geometries_are_followed() {
    let json = r#"{
        "geometries": {"vertexData": [{"id": "g", "positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0,1,2]}]},
        "transformNodes": [{"id": "root", "position": [0, 5, 0]}],
        "meshes": [
            {"name": "empty", "id": "e", "position": [1, 0, 0], "parentId": "root"},
            {"name": "m", "geometryId": "g", "parentId": "e"}
        ]}"#;
    let (scene, warnings) = read_text(json).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(&scene.meshes[0].world[12..15], &[1., 5., 0.]);
}

/// Parents are found as Babylon.js's loader finds them: cameras and lights too, by `id`,
/// then `name`; a numeric `parentId` by `uniqueId`.
#[test]
fn parents_can_be_cameras_lights_and_unique_ids() {
    let json = r#"{
        "geometries": {"vertexData": [{"id": "g", "positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0,1,2]}]},
        "cameras": [{"name": "cam", "id": "c1", "uniqueId": 7, "position": [0, 0, -10], "target": [0, 0, 0]},
                    {"name": "side", "id": "c2", "position": [10, 0, 0], "target": [0, 0, 0]}],
        "lights": [{"name": "lamp", "id": "l1", "uniqueId": 9, "type": 0, "position": [3, 4, 5]}],
        "transformNodes": [{"name": "car", "id": "t", "uniqueId": 12, "position": [0, 2, 0]}],
        "meshes": [
            {"name": "on-camera", "geometryId": "g", "position": [0, 0, 1], "parentId": "c1"},
            {"name": "on-camera-by-unique-id", "geometryId": "g", "position": [0, 0, 1], "parentId": 7},
            {"name": "on-turned-camera", "geometryId": "g", "position": [0, 0, 1], "parentId": "c2"},
            {"name": "on-light-by-name", "geometryId": "g", "position": [1, 0, 0], "parentId": "lamp"},
            {"name": "wheel", "geometryId": "g", "position": [1, 0, 0], "parentId": 12}
        ],
        "activeCameraID": "c1"}"#;
    let (scene, warnings) = read_text(json).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let at = |name: &str| point(&mesh(&scene, name).world, [0., 0., 0.]);
    assert_close(&at("on-camera"), &[0., 0., -9.], 1e-5, "on-camera");
    assert_close(&at("on-camera-by-unique-id"), &[0., 0., -9.], 1e-5, "by uniqueId");
    // A camera at +x looking at the origin looks along -x: one unit ahead is x = 9.
    assert_close(&at("on-turned-camera"), &[9., 0., 0.], 1e-5, "turned camera");
    assert_close(&at("on-light-by-name"), &[4., 4., 5.], 1e-5, "light");
    assert_close(&at("wheel"), &[1., 2., 0.], 1e-5, "transform node by uniqueId");
    // A parent that matches nothing is still said, once.
    let (_, warnings) =
        read_text(r#"{"meshes":[{"name":"M","positions":[0,0,0,1,0,0,0,1,0],"parentId":99}]}"#).unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].0.contains("parent \"99\" not found"), "{warnings:?}");
    // An empty `parentId` is no parent (Babylon.js's loader skips it), and no warning.
    let (scene, warnings) =
        read_text(r#"{"meshes":[{"name":"M","positions":[0,0,0,1,0,0,0,1,0],"parentId":""}]}"#).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.meshes.len(), 1);
}

/// Every feature the file has and soft3d does not draw is named, in one warning line each,
/// with its first users; defaults (absent, zero, -1, empty, black) are not features.
#[test]
fn what_is_not_drawn_is_said_once_a_feature() {
    let mesh = |k: u32| {
        format!(
            r#"{{"name":"m{k}","positions":[0,0,0,1,0,0,0,1,0],"billboardMode":7,"skeletonId":-1,"animations":[]}}"#
        )
    };
    let meshes: Vec<String> = (0..5).map(mesh).collect();
    let json = format!(
        r#"{{"skeletons":[{{"id":0}}],"morphTargetManagers":[],"fogMode":0,"ambientColor":[0,0,0],
        "materials":[{{"id":"a","emissive":[0,0,0],"bumpTexture":{{"name":"n.png"}}}}],
        "meshes":[{}]}}"#,
        meshes.join(",")
    );
    let (_, warnings) = read_text(&json).unwrap();
    let text: Vec<String> = warnings.iter().map(ToString::to_string).filter(|w| w.contains("by soft3d yet")).collect();
    // Skeletons are played (the one here has no bones: nothing to say).
    assert_eq!(text.len(), 2, "{text:#?}");
    assert!(text[0].contains("(material \"a\"'s bumpTexture)"), "{text:?}");
    let billboards =
        "billboards are not drawn by soft3d yet (mesh \"m0\"'s billboardMode, mesh \"m1\"'s billboardMode, \
                      mesh \"m2\"'s billboardMode and 2 more)";
    assert!(text[1].starts_with(billboards), "{text:?}");
}

fn error_of(json: &str) -> String {
    match read_text(json) {
        Ok(_) => panic!("accepted: {json}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn malformed_input_is_an_error() {
    let real = std::fs::read(asset("instances/Instances.babylon")).unwrap();
    let truncated = read_babylon(&real[..real.len() / 2], None, "Instances.babylon", &ConvertOptions::default());
    assert!(matches!(truncated, Err(ConvertError::Json { .. })), "{truncated:?}");

    let e = error_of(r#"{"meshes":[{"name":"M","positions":"x"}]}"#);
    assert_eq!(e, r#"test.babylon: mesh "M": positions: expected an array, found "x""#);
    let e = error_of(r#"{"meshes":[{"name":"M","positions":[0,0,0,1,0,0,0,1,0],"indices":[0,1,9001]}]}"#);
    assert_eq!(e, r#"test.babylon: mesh "M": indices[2] = 9001 but only 3 vertices"#);
    let e = error_of(r#"{"meshes":[{"name":"M","positions":[0,0,0,1,0,0,0,1]}]}"#);
    assert!(e.contains("mesh \"M\": positions: 8 numbers is not a multiple of 3"), "{e}");
    let e = error_of(r#"{"meshes":[{"name":"M","positions":[0,0,0,1,0,0,0,1,0],"indices":[0,1]}]}"#);
    assert!(e.contains("not a multiple of 3"), "{e}");
    let e = error_of(
        r#"{"meshes":[{"name":"A","id":"a","parentId":"b"},{"name":"B","id":"b","parentId":"a","positions":[0,0,0,1,0,0,0,1,0]}]}"#,
    );
    assert!(e.contains("parentId cycle"), "{e}");
    let e = error_of(r#"{"meshes":[{"name":"M","positions":[1e39,0,0,1,0,0,0,1,0]}]}"#);
    assert!(e.contains("positions[0]"), "{e}");
    assert!(read_text(r#"{"meshes":[{"positions":[1e999,0,0,1,0,0,0,1,0]}]}"#).is_err());
    let e = error_of(
        r#"{"meshes":[{"name":"M","positions":[0,0,0,1,0,0,0,1,0],"subMeshes":[{"indexStart":0,"indexCount":6}]}]}"#,
    );
    assert!(e.contains("subMeshes[0]: indexStart 0 + indexCount 6 > 3 indices"), "{e}");
    let e = error_of(r#"{"meshes":[{"name":"M","vertices":[0,0,0,0,0,1,0],"uvCount":1}]}"#);
    assert!(e.contains("vertices: 7 numbers"), "{e}");
    let e = error_of(r#"{"meshes":[{"name":"M","delayLoadingFile":"x.babylonbinarymeshdata"}]}"#);
    assert!(e.contains("delayLoadingFile"), "{e}");
    assert!(read_text("[1, 2]").is_err());
    assert!(read_text(r#"{"meshes": 3}"#).is_err());
    assert!(read_text(r#"{"lights":[{"type":0,"position":[1,"a",3]}]}"#).is_err());
}

#[test]
fn odd_but_valid_input_gives_warnings() {
    let json = r#"{
        "materials": [{"id": "m", "diffuseTexture": {"name": "nowhere.png"}}],
        "meshes": [
            {"name": "A", "materialId": "m", "positions": [0,0,0, 1,0,0, 0,1,0], "uvs": [0,0, 1,0, 0,1]},
            {"name": "B", "materialId": "unknown", "positions": [0,0,0, 1,0,0, 0,1,0], "parentId": "nobody"},
            {"name": "C", "positions": []}
        ],
        "lights": [{"name": "spot", "type": 2}]}"#;
    let (scene, warnings) = read_text(json).unwrap();
    assert_eq!(scene.meshes.len(), 2);
    assert_eq!(scene.materials.len(), 1);
    assert!(scene.lights.is_empty());
    let text: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    for needle in [
        "\"nowhere.png\" not found",
        "material \"unknown\" not found",
        "parent \"nobody\"",
        "mesh \"C\": has no vertices",
        "light \"spot\"",
    ] {
        assert!(text.iter().any(|w| w.contains(needle)), "{needle} in {text:?}");
    }
}

/// Random JSON built from the format's own vocabulary, so that the reader's deeper paths run.
fn babylonish() -> impl Strategy<Value = serde_json::Value> {
    use serde_json::{json, Value};
    let key = prop::sample::select(vec![
        "meshes",
        "positions",
        "normals",
        "uvs",
        "uvs2",
        "colors",
        "indices",
        "vertices",
        "uvCount",
        "subMeshes",
        "materialIndex",
        "indexStart",
        "indexCount",
        "materialId",
        "materials",
        "multiMaterials",
        "id",
        "name",
        "parentId",
        "position",
        "rotation",
        "rotationQuaternion",
        "scaling",
        "instances",
        "lights",
        "type",
        "data",
        "direction",
        "cameras",
        "activeCamera",
        "target",
        "geometries",
        "vertexData",
        "geometryId",
        "diffuseTexture",
        "albedoTexture",
        "base64String",
        "uScale",
        "vAng",
        "wrapU",
        "hasAlpha",
        "autoAnimate",
        "animations",
        "keys",
        "frame",
        "values",
        "property",
        "delayLoadingFile",
        "_binaryInfo",
        "transformNodes",
        "isVisible",
    ]);
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::Bool),
        (-4i64..12).prop_map(|n| json!(n)),
        any::<f64>().prop_map(|x| json!(x)),
        prop::sample::select(vec!["a", "b", "root", "m", "position", "data:image/png;base64,iVBORw0KGgo=", ""])
            .prop_map(|s| json!(s)),
    ];
    leaf.prop_recursive(5, 96, 8, move |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..10).prop_map(Value::Array),
            prop::collection::vec((key.clone(), inner), 0..8)
                .prop_map(|kv| Value::Object(kv.into_iter().map(|(k, v)| (k.to_owned(), v)).collect())),
        ]
    })
}

/// Meshes whose fields are each plausible, in random combinations: reaches the geometry checks.
fn plausible_mesh() -> impl Strategy<Value = serde_json::Value> {
    use serde_json::json;
    // A length that is usually right for `n` vertices of `per` numbers, sometimes one off.
    let sized = |n: usize, per: usize, skew: usize| {
        (0..n * per + skew % 3).map(|k| (k % 7) as f32 * 0.3 - 1.).collect::<Vec<_>>()
    };
    let id = || prop::sample::select(vec![None, Some("a"), Some("b"), Some("c")]);
    let sub = (0u32..4, 0u32..4, 0u32..4)
        .prop_map(|(m, s, c)| json!({"materialIndex": m, "indexStart": 3 * s, "indexCount": 3 * c}));
    let skew = prop_oneof![8 => Just(0usize), 1 => Just(1), 1 => Just(2)];
    (
        (0usize..7, skew, 0usize..3, any::<bool>(), any::<bool>()),
        (
            prop::collection::vec([0u32..64, 0u32..64, 0u32..64], 0..5),
            prop::option::of(prop::collection::vec(sub, 1..3)),
        ),
        (id(), id(), prop::sample::select(vec![None, Some("m"), Some("mm"), Some("x")])),
        prop::collection::vec(prop::collection::vec(-2.0f32..2.0, 3), 0..3),
    )
        .prop_map(move |((n, skew, uv_count, legacy, normals), (tris, subs), (id, parent, mat), inst)| {
            // Indices below `n`, except now and then one equal to it or a triangle cut short.
            let limit = (n as u32 + u32::from(skew == 1)).max(1);
            let mut ix: Vec<u32> = tris.as_flattened().iter().map(|x| x % limit).collect();
            ix.truncate(ix.len().saturating_sub(usize::from(skew == 2 && !legacy)));
            let mut m = json!({"name": "M", "id": id, "parentId": parent, "materialId": mat, "subMeshes": subs,
                "instances": inst.iter().map(|t| json!({"position": t, "parentId": parent})).collect::<Vec<_>>()});
            if legacy {
                m["vertices"] = json!(sized(n, 6 + 2 * uv_count, skew));
                m["uvCount"] = json!(uv_count);
            } else {
                m["positions"] = json!(sized(n, 3, skew));
                m["uvs"] = json!(sized(n, 2, 0));
                if normals {
                    m["normals"] = json!(sized(n, 3, 0));
                }
            }
            if !ix.is_empty() {
                m["indices"] = json!(ix);
            }
            m
        })
}

proptest! {
    #[test]
    fn mutated_real_files_never_panic(
        file in prop::sample::select(vec!["instances/Instances.babylon", "blender-split/blender.babylon", "blender-legacy/blender.babylon"]),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let path = asset(file);
        let mut bytes = std::fs::read(&path).unwrap();
        for (at, byte) in edits {
            let i = at.index(bytes.len());
            bytes[i] = byte;
        }
        let _ = read_babylon(&bytes, path.parent(), file, &ConvertOptions::default());
    }

    #[test]
    fn json_ish_text_never_panics(text in r#"[\[\]{}",:0-9a-z.eE+ -]{0,200}"#) {
        let _ = read_text(&text);
        let _ = read_text(&format!(r#"{{"meshes":[{text}]}}"#));
    }

    #[test]
    fn babylon_shaped_json_never_panics(meshes in babylonish(), rest in babylonish()) {
        let mut root = serde_json::json!({ "meshes": [meshes] });
        if let (Some(obj), serde_json::Value::Object(extra)) = (root.as_object_mut(), rest) {
            obj.extend(extra);
        }
        let bytes = serde_json::to_vec(&root).unwrap();
        let _ = read_babylon(&bytes, Some(&asset("opaque")), "random", &ConvertOptions::default());
    }

    #[test]
    fn plausible_meshes_never_panic(meshes in prop::collection::vec(plausible_mesh(), 1..4)) {
        let root = serde_json::json!({
            "materials": [{"id": "m", "diffuseTexture": {"name": "TestImage.png", "uScale": 2, "wAng": 0.5}}],
            "multiMaterials": [{"id": "mm", "materials": ["m", null, "x"]}],
            "meshes": meshes,
        });
        let bytes = serde_json::to_vec(&root).unwrap();
        let dir = asset("double-sided");
        if let Ok((scene, _)) = read_babylon(&bytes, Some(&dir), "random", &ConvertOptions::default()) {
            for m in &scene.meshes {
                prop_assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
                prop_assert!(m.normals.iter().all(|n| n.iter().all(|x| x.is_finite())));
            }
        }
    }
}
