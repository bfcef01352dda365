//! Issue "Scenes that move": camera and light animations, on the hand-made
//! `tests/data/camera-light.babylon` (a white quad facing the camera; a `FreeCamera` whose
//! `position` and `fov` tracks dolly and zoom it, with `autoAnimate`; a directional light
//! whose `intensity` and `direction` tracks dim and swing it; a point light whose
//! `position.y` and `diffuse` tracks an animation group plays; an `upVector` and a `specular`
//! track soft3d does not play; a second camera's animation) and on small scenes written here:
//! what the converter reads and warns, the exact camera and lights a pose gives at chosen
//! frames, rendered frames, the format's validation of the new records, and the CLI.
#![cfg(feature = "convert")]

use std::path::Path;

use embedded_graphics_core::pixelcolor::Rgb888;
use soft3d::animation::{pose_memory, Aim, Pose};
use soft3d::convert::scene::*;
use soft3d::convert::{emit, read_babylon, read_babylon_file, to_scene, ConvertOptions, EmitOptions, Warning};
use soft3d::{Band, Camera, Lights, Mat4, Model, ParseError, Part, RenderOptions, Renderer, Scratch, Vec3};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/camera-light.babylon");

/// The data file, read.
fn read() -> (Scene, Vec<Warning>) {
    read_babylon_file(Path::new(DATA), &ConvertOptions::default()).unwrap()
}

/// The data file as `.s3d` bytes.
fn bytes() -> Vec<u8> {
    emit(&read().0, &EmitOptions::default()).unwrap()
}

/// Reads JSON text as a scene.
fn read_text(json: &str) -> (Scene, Vec<Warning>) {
    read_babylon(json.as_bytes(), None, "test.babylon", &ConvertOptions::default()).unwrap()
}

/// Whether a warning holds every needle.
fn has(warnings: &[Warning], needles: &[&str]) -> bool {
    warnings.iter().any(|w| needles.iter().all(|n| w.0.contains(n)))
}

/// Babylon.js's linear interpolation, `a + (b - a) · t`, in f32 as the pose computes it.
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

fn lerp3(a: [f32; 3], b: [f32; 3], t: f32) -> Vec3 {
    Vec3::new(lerp(a[0], b[0], t), lerp(a[1], b[1], t), lerp(a[2], b[2], t))
}

/// `f(pose)` for the data file posed at `frame` (every group, or `group`).
fn posed<T>(model: &Model<'_>, frame: f32, group: Option<usize>, f: impl FnOnce(&Pose<'_>) -> T) -> T {
    let a = model.animation().unwrap();
    let (n, w) = pose_memory(a.node_count(), a.palette_count(), a.weight_count());
    let (mut nodes, mut weights) = (vec![Mat4::IDENTITY; n], vec![0.0f32; w]);
    let mut pose = Pose::new(&mut nodes, &mut weights);
    pose.evaluate(&a, frame, group).unwrap();
    f(&pose)
}

/// (a) The converter reads the camera's and lights' tracks, their groups and the camera's
/// aim, and warns about what it does not play.
#[test]
fn the_converter_reads_camera_and_light_tracks() {
    let (scene, warnings) = read();
    let a = &scene.animation;
    let camera = |property, first, count| TrackTarget::Camera { property, first, count };
    let light = |light, property, first, count| TrackTarget::Light { light, property, first, count };
    let targets: Vec<TrackTarget> = a.tracks.iter().map(|t| t.target).collect();
    assert_eq!(
        targets,
        [
            light(1, LightProperty::Vector, 1, 1),
            light(1, LightProperty::Diffuse, 0, 3),
            camera(CameraProperty::Position, 0, 3),
            camera(CameraProperty::Fov, 0, 1),
            light(0, LightProperty::Intensity, 0, 1),
            light(0, LightProperty::Vector, 0, 3),
        ]
    );
    assert!(a.tracks.iter().all(|t| t.fps == 10.0 && t.keys.len() == 2));
    assert_eq!(a.tracks[2].keys[1].values, [1.0, 0.0, -10.0]);
    assert_eq!(a.tracks[4].looping, Loop::Constant);
    let groups: Vec<_> =
        a.groups.iter().map(|g| (g.name.as_str(), g.from, g.to, g.looping, g.tracks.clone())).collect();
    assert_eq!(
        groups,
        [
            ("LampGroup", 0., 10., false, vec![0, 1]),
            ("cam", 0., 10., true, vec![2, 3]),
            ("sun", 0., 10., true, vec![4, 5])
        ]
    );
    // A FreeCamera keeps its rotation: it looks along its still direction while it moves.
    assert_eq!(a.camera_aim, CameraAim::Direction);
    assert!(a.nodes.is_empty() && a.morphs.is_empty() && a.skins.is_empty());
    for needles in [
        &["camera \"cam\": animations[2] (\"roll\")", "property \"upVector\" is not played", "skipped"][..],
        &["light \"sun\": animations[2] (\"shine\")", "property \"specular\" is not played", "skipped"],
        &["camera \"spare\": not the active camera: its animations are not played"],
    ] {
        assert!(has(&warnings, needles), "{needles:?} in {warnings:#?}");
    }
    assert_eq!(warnings.len(), 3, "{warnings:#?}");
}

/// (b) A pose gives the camera and lights the keys give at chosen frames, exactly (linear
/// interpolation by hand), with each group's loop: the camera's and the sun's groups loop, the
/// lamp's group stays at its last frame.
#[test]
fn a_pose_gives_the_camera_and_lights_at_chosen_frames() {
    let bytes = bytes();
    let model = Model::parse(&bytes).unwrap();
    let a = model.animation().unwrap();
    // 10 camera slots and 7 for each light, after no morph weights.
    assert_eq!(a.weight_count(), 24);
    assert_eq!(a.camera().map(|c| (c.aim(), c.slots())), Some((Aim::Direction, 0..10)));
    assert_eq!((a.animated_light_count(), a.animated_light_of(1).map(|l| l.slots())), (2, Some(17..24)));
    let (still, sun, lamp) = (model.camera().unwrap(), model.light(0).unwrap(), model.light(1).unwrap());
    // (frame, the camera's, the sun's and the lamp's place between their keys): 15 wraps to 5
    // for the camera; the sun's tracks are constant (`loopBehavior` 2), which Babylon.js holds
    // at their end once their looping group has gone round; the lamp's group does not loop.
    let frames = [
        (0.0, 0.0, 0.0, 0.0),
        (2.5, 0.25, 0.25, 0.25),
        (5.0, 0.5, 0.5, 0.5),
        (10.0, 1.0, 1.0, 1.0),
        (15.0, 0.5, 1.0, 1.0),
    ];
    for (frame, t, sun_t, lamp_t) in frames {
        let (camera, lights) = posed(&model, frame, None, |pose| {
            (pose.camera(&a, still), [0, 1].map(|i| pose.light(&a, i, model.light(i).unwrap())))
        });
        let eye = lerp3([0.0, 0.0, -10.0], [1.0, 0.0, -10.0], t);
        assert_eq!(camera.position, eye, "frame {frame}");
        // Along the still direction: (0, 0, 10) ahead.
        assert_eq!(camera.target, eye + (Vec3::ZERO - Vec3::new(0.0, 0.0, -10.0)), "frame {frame}");
        assert_eq!(camera.fov, lerp(0.8, 0.4, t), "frame {frame}");
        assert_eq!((camera.near, camera.far), (0.1, 100.0));
        assert_eq!(lights[0].intensity, lerp(1.0, 0.0, sun_t), "frame {frame}");
        assert_eq!(lights[0].vector, lerp3([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], sun_t), "frame {frame}");
        assert_eq!((lights[0].kind, lights[0].diffuse), (sun.kind, sun.diffuse));
        assert_eq!(lights[1].vector, Vec3::new(0.0, lerp(0.0, 2.0, lamp_t), -5.0), "frame {frame}");
        assert_eq!(lights[1].diffuse, lerp3([1.0; 3], [0.0; 3], lamp_t), "frame {frame}");
        assert_eq!((lights[1].kind, lights[1].intensity), (lamp.kind, lamp.intensity));
    }
    // The lamp's group alone leaves the camera and the sun as stored.
    let lamp_group = a.group_named("LampGroup");
    let (camera, sun_at) = posed(&model, 5.0, lamp_group, |pose| (pose.camera(&a, still), pose.light(&a, 0, sun)));
    assert_eq!((camera, sun_at), (still, sun));
    // Posed lights as the renderer takes them; an unset pose gives the stored ones.
    let lights = posed(&model, 10.0, None, |pose| Lights::<4>::from_model_posed(&model, pose));
    assert_eq!((lights.lights[0].intensity, lights.lights[1].diffuse), (0.0, Vec3::ZERO));
    let unset = Pose::new(&mut [], &mut []);
    assert_eq!(unset.camera(&a, still), still);
    assert_eq!(Lights::<4>::from_model_posed(&model, &unset).lights, Lights::<4>::from_model(&model).lights);
}

/// The pixels of the data file drawn at `frame` into a 64x64 RGB888 frame (black background),
/// with the posed camera and lights, and that camera.
fn render(model: &Model<'_>, frame: f32) -> (Vec<Rgb888>, Camera) {
    let a = model.animation().unwrap();
    let mut color = vec![Rgb888::new(0, 0, 0); 64 * 64];
    let mut depth = vec![u16::MAX; 64 * 64];
    let camera = posed(model, frame, None, |pose| {
        let camera = Camera::from_scene(&pose.camera(&a, model.camera().unwrap()), 1.0).unwrap();
        let lights = Lights::<4>::from_model_posed(model, pose);
        let mut band = Band::new(&mut color[..], &mut depth[..], 64, 64, 0).unwrap();
        let renderer = Renderer::new(&camera, &lights, RenderOptions::default());
        renderer.draw_posed(&mut band, model, pose, Mat4::IDENTITY, &mut Scratch::none()).unwrap();
        camera
    });
    (color, camera)
}

/// The columns and rows of pixels that are not the background (at least one is).
fn covered_box(color: &[Rgb888], background: Rgb888) -> [usize; 4] {
    let covered = || (0..64 * 64).filter(|&i| color[i] != background);
    let (cols, rows) = (covered().map(|i| i % 64), covered().map(|i| i / 64));
    [cols.clone().min().unwrap(), cols.max().unwrap(), rows.clone().min().unwrap(), rows.max().unwrap()]
}

/// The box of pixel centres the quad (corners at ±1 in x and y) covers as `camera` sees it.
fn expected_box(camera: &Camera) -> [f32; 4] {
    let corners =
        [(-1.0, -1.0), (1.0, 1.0)].map(|(x, y)| camera.view_projection().project_point3(Vec3::new(x, y, 0.0)));
    let column = |ndc: f32| (ndc + 1.0) * 32.0 - 0.5;
    let row = |ndc: f32| (1.0 - ndc) * 32.0 - 0.5;
    [column(corners[0].x), column(corners[1].x), row(corners[1].y), row(corners[0].y)]
}

/// (c) Rendered frames follow the camera and lights: at frame 0 the quad is lit white in the
/// middle; at frame 10 the camera has moved right and zoomed in (the quad's covered box moves
/// left and grows, where the posed camera projects it) and both lights are out (intensity 0,
/// black diffuse): the quad is black.
#[test]
fn rendered_frames_follow_the_camera_and_lights() {
    let bytes = bytes();
    let model = Model::parse(&bytes).unwrap();
    let black = Rgb888::new(0, 0, 0);
    let (first, camera) = render(&model, 0.0);
    let lit: Vec<Rgb888> = first.iter().copied().filter(|&c| c != black).collect();
    assert!(lit.len() > 100 && lit.iter().all(|&c| c == Rgb888::new(255, 255, 255)), "{} lit", lit.len());
    let close = |got: [usize; 4], want: [f32; 4]| got.iter().zip(want).all(|(&g, w)| (g as f32 - w).abs() <= 1.0);
    let got = covered_box(&first, black);
    assert!(close(got, expected_box(&camera)), "{got:?} vs {:?}", expected_box(&camera));
    assert!(got[0] > 16 && got[1] < 48, "centred: {got:?}");

    // At frame 10 nothing lights the quad: draw it on grey to see its (black) pixels.
    let (last, camera) = render(&model, 10.0);
    let drawn = last.iter().filter(|&&c| c != black).count();
    assert_eq!(drawn, 0, "the quad is black at frame 10");
    let a = model.animation().unwrap();
    let mut color = vec![Rgb888::new(9, 9, 9); 64 * 64];
    let mut depth = vec![u16::MAX; 64 * 64];
    posed(&model, 10.0, None, |pose| {
        let lights = Lights::<4>::from_model_posed(&model, pose);
        let mut band = Band::new(&mut color[..], &mut depth[..], 64, 64, 0).unwrap();
        Renderer::new(&camera, &lights, RenderOptions::default())
            .draw_posed(&mut band, &model, pose, Mat4::IDENTITY, &mut Scratch::none())
            .unwrap();
        assert_eq!(pose.camera(&a, model.camera().unwrap()).fov, 0.4);
    });
    let moved = covered_box(&color, Rgb888::new(9, 9, 9));
    assert!(close(moved, expected_box(&camera)), "{moved:?} vs {:?}", expected_box(&camera));
    assert!(moved[0] < got[0] && moved[1] < got[1] + 1 && moved[1] - moved[0] > got[1] - got[0], "{moved:?} {got:?}");
}

/// A scene of the white quad with `camera` (JSON) as its active camera and `lights` (JSON).
fn quad_with(camera: &str, lights: &str) -> String {
    format!(
        r#"{{"meshes":[{{"name":"q","id":"q","positions":[-1,-1,0,1,-1,0,1,1,0,-1,1,0],
        "indices":[0,1,2,0,2,3],"normals":[0,0,-1,0,0,-1,0,0,-1,0,0,-1]}}],
        "transformNodes":[{{"name":"rig","id":"rig","position":[0,3,0]}},
            {{"name":"turntable","id":"turntable","rotation":[0,1,0]}}],
        "cameras":[{camera}],"activeCameraID":"c","lights":[{lights}]}}"#
    )
}

/// Two keys, frame 0 and 10, of `property` with values `a` and `b` (JSON arrays or numbers).
fn track(property: &str, a: &str, b: &str) -> String {
    format!(r#"{{"property":"{property}","keys":[{{"frame":0,"values":{a}}},{{"frame":10,"values":{b}}}]}}"#)
}

/// The posed camera of a scene at `frame`.
fn camera_at(scene: &Scene, frame: f32) -> soft3d::SceneCamera {
    let bytes = emit(scene, &EmitOptions::default()).unwrap();
    let model = Model::parse(&bytes).unwrap();
    let a = model.animation().unwrap();
    posed(&model, frame, None, |pose| pose.camera(&a, model.camera().unwrap()))
}

/// A `FreeCamera` turned by its rotation: without a target it turns from its own `rotation`
/// (the target one unit ahead); with one, from the rotation `setTarget` gives (yaw and pitch),
/// its target's distance ahead; one component at a time.
#[test]
fn a_free_camera_turns_by_its_rotation() {
    let quarter = core::f32::consts::FRAC_PI_2;
    let yaw = track("rotation.y", "0", &quarter.to_string());
    let camera =
        format!(r#"{{"id":"c","type":"FreeCamera","position":[0,0,-10],"rotation":[0,0,0],"animations":[{yaw}]}}"#);
    let (scene, warnings) = read_text(&quad_with(&camera, ""));
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.animation.camera_aim, CameraAim::Rotation { rotation: [0.0; 3], distance: 1.0 });
    let c = camera_at(&scene, 10.0);
    assert!((c.target - Vec3::new(1.0, 0.0, -10.0)).length() < 1e-6, "{c:?}");
    assert!((camera_at(&scene, 5.0).target - Vec3::new(0.5f32.sqrt(), 0.0, 0.5f32.sqrt() - 10.0)).length() < 1e-6);

    // Looking along +x at its target 10 away, then pitched up a quarter turn's half.
    let pitch = track("rotation.x", "0", &(-quarter / 2.0).to_string());
    let camera =
        format!(r#"{{"id":"c","type":"FreeCamera","position":[0,0,-10],"target":[10,0,-10],"animations":[{pitch}]}}"#);
    let (scene, warnings) = read_text(&quad_with(&camera, ""));
    assert!(warnings.is_empty(), "{warnings:?}");
    let CameraAim::Rotation { rotation, distance } = scene.animation.camera_aim else { panic!() };
    assert!((rotation[1] - quarter).abs() < 1e-6 && rotation[0] == 0.0 && distance == 10.0, "{rotation:?}");
    let c = camera_at(&scene, 10.0);
    let up = 10.0 * 0.5f32.sqrt();
    assert!((c.target - Vec3::new(up, up, -10.0)).length() < 1e-5, "{c:?}");
}

/// An `ArcRotateCamera` keeps looking at its target while it moves; whole vectors of a
/// parented camera or light go through the parent (a point light's position as a point, a
/// component where the parent only moves it); a parent that turns leaves one component alone.
#[test]
fn orbiting_cameras_look_at_their_target_and_parents_place_keys() {
    let dolly = track("position", "[0,0,-10]", "[10,0,-10]");
    let camera = format!(r#"{{"id":"c","type":"ArcRotateCamera","position":[0,0,-10],"animations":[{dolly}]}}"#);
    let rise = track("position.y", "0", "2");
    let lamp = format!(r#"{{"name":"lamp","type":0,"position":[0,0,-5],"parentId":"rig","animations":[{rise}]}}"#);
    let swing = track("direction", "[0,0,1]", "[1,0,1]");
    let sun = format!(r#"{{"name":"sun","type":1,"direction":[0,0,1],"parentId":"turntable","animations":[{swing}]}}"#);
    let (scene, warnings) = read_text(&quad_with(&camera, &format!("{lamp},{sun}")));
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.animation.camera_aim, CameraAim::Target);
    let c = camera_at(&scene, 5.0);
    assert_eq!((c.position, c.target), (Vec3::new(5.0, 0.0, -10.0), Vec3::ZERO));
    // The lamp's position.y keys moved by the rig's 3; the sun's directions turned by y = 1.
    assert_eq!(scene.animation.tracks[1].keys[1].values, [5.0]);
    let (s, c1) = (libm::sinf(1.0), libm::cosf(1.0));
    let turned = &scene.animation.tracks[2].keys[1].values;
    let want = [c1 + s, 0.0, c1 - s];
    assert!(turned.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-6), "{turned:?} vs {want:?}");

    // One component of a light the parent turns: skipped.
    let nudge = track("direction.x", "0", "1");
    let sun = format!(r#"{{"name":"sun","type":1,"direction":[0,0,1],"parentId":"turntable","animations":[{nudge}]}}"#);
    let (scene, warnings) = read_text(&quad_with(r#"{"id":"c","position":[0,0,-10],"target":[0,0,0]}"#, &sun));
    assert!(scene.animation.tracks.is_empty());
    assert!(has(&warnings, &["light \"sun\": animations[0]", "the parent turns or scales", "skipped"]), "{warnings:?}");
}

/// What a camera or light cannot play is skipped with a warning that says why.
#[test]
fn unplayable_camera_and_light_tracks_say_why() {
    let free = format!(
        r#"{{"id":"c","type":"FreeCamera","position":[0,0,-10],"target":[0,0,0],"animations":[{},{},{}]}}"#,
        track("target.x", "0", "1"),
        track("fov", "0.8", "3.5"),
        track("alpha", "0", "1"),
    );
    let sun = format!(
        r#"{{"name":"sun","type":1,"direction":[0,0,1],"animations":[{}]}}"#,
        track("position", "[0,0,0]", "[1,1,1]")
    );
    let lamp = format!(
        r#"{{"name":"lamp","type":0,"position":[0,0,-5],"animations":[{}]}}"#,
        track("direction", "[0,0,1]", "[1,1,1]")
    );
    let (scene, warnings) = read_text(&quad_with(&free, &format!("{sun},{lamp}")));
    assert!(scene.animation.tracks.is_empty(), "{:?}", scene.animation.tracks);
    assert_eq!(scene.animation, AnimationData::default(), "nothing moves");
    for needles in [
        &["camera \"c\": animations[0]", "one component of this camera's target has no effect"][..],
        &["camera \"c\": animations[1]", "a field of view outside 0 to pi"],
        &["camera \"c\": animations[2]", "property \"alpha\" is not played"],
        &["light \"sun\": animations[0]", "a directional or hemispheric light's position does not light it"],
        &["light \"lamp\": animations[0]", "a point light's direction does not light it"],
    ] {
        assert!(has(&warnings, needles), "{needles:?} in {warnings:#?}");
    }
    let orbit = format!(
        r#"{{"id":"c","type":"ArcRotateCamera","position":[0,0,-10],"animations":[{}]}}"#,
        track("rotation", "[0,0,0]", "[1,1,1]")
    );
    let (_, warnings) = read_text(&quad_with(&orbit, ""));
    assert!(has(&warnings, &["animations[0]", "an ArcRotateCamera turns by alpha and beta"]), "{warnings:?}");
    let locked = format!(
        r#"{{"id":"c","position":[0,0,-10],"lockedTargetId":"q","animations":[{}]}}"#,
        track("target", "[0,0,0]", "[1,1,1]")
    );
    let (_, warnings) = read_text(&quad_with(&locked, ""));
    assert!(has(&warnings, &["animations[0]", "looks at its locked target"]), "{warnings:?}");
    // The active camera ignored (it looks at its own position): its animations too.
    let blind =
        format!(r#"{{"id":"c","position":[0,0,0],"target":[0,0,0],"animations":[{}]}}"#, track("fov", "0.8", "1"));
    let (scene, warnings) = read_text(&quad_with(&blind, ""));
    assert!(scene.camera.is_none() && scene.animation.tracks.is_empty());
    assert!(
        has(&warnings, &["camera \"c\": the active camera, ignored: its animations are not played"]),
        "{warnings:?}"
    );
}

/// `.s3d` files written before camera and light animations (version 2, header flags 0, a
/// 40-byte animation section) still read: the logo seed was converted before the change. A
/// scene whose camera and lights stay still is written as before (no flag).
#[test]
fn files_without_camera_or_light_animation_read_and_write_as_before() {
    let seed = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz/seeds/parse/logo-animation-logo.s3d")).unwrap();
    assert_eq!((seed[4], seed[6], seed[7]), (2, 0, 0), "a version 2 file with no flags");
    let model = Model::parse(&seed).unwrap();
    let a = model.animation().unwrap();
    assert!(a.camera().is_none() && a.animated_light_count() == 0);
    let still = soft3d::SceneCamera { position: Vec3::Z, target: Vec3::ZERO, fov: 1.0, near: 1.0, far: 2.0 };
    assert_eq!(posed(&model, 25.0, None, |pose| pose.camera(&a, still)), still);

    let mut scene = read().0;
    scene.animation = AnimationData {
        nodes: vec![NodeData {
            name: "n".into(),
            parent: None,
            above: IDENTITY,
            position: [0.0; 3],
            rotation: Rotation::Euler([0.0; 3]),
            scaling: [1.0; 3],
        }],
        tracks: vec![TrackData {
            target: TrackTarget::Node { node: 0, property: NodeProperty::Position, first: 0, count: 1 },
            fps: 10.0,
            looping: Loop::Cycle,
            keys: vec![KeyData { frame: 0.0, values: vec![1.0], tangents: None, step: false }],
        }],
        groups: vec![GroupData { name: "g".into(), from: 0.0, to: 0.0, looping: true, tracks: vec![0] }],
        ..AnimationData::default()
    };
    let bytes = emit(&scene, &EmitOptions::default()).unwrap();
    assert_eq!((bytes[4], bytes[6], bytes[7]), (2, 0, 0));
    let section = u32::from_le_bytes(bytes[48..52].try_into().unwrap()) as usize;
    // The node table right after the 40-byte section, as before.
    assert_eq!(u32::from_le_bytes(bytes[section + 12..section + 16].try_into().unwrap()) as usize, section + 40);
    assert!(Model::parse(&bytes).unwrap().animation().unwrap().camera().is_none());
}

/// `to_scene` reads the camera's aim and the tracks back: a second `emit` gives the same bytes.
#[test]
fn camera_and_light_tracks_survive_a_round_trip() {
    let bytes = bytes();
    let scene = to_scene(&Model::parse(&bytes).unwrap());
    assert_eq!(scene.animation.camera_aim, CameraAim::Direction);
    assert_eq!(
        scene.animation.tracks.iter().map(|t| t.target).collect::<Vec<_>>(),
        read().0.animation.tracks.iter().map(|t| t.target).collect::<Vec<_>>()
    );
    assert_eq!(emit(&scene, &EmitOptions::default()).unwrap(), bytes);
}

/// Little-endian fields of a file, for corrupting it.
fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}
fn u32_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize
}
fn put_u16(b: &mut [u8], at: usize, v: u16) {
    b[at..at + 2].copy_from_slice(&v.to_le_bytes());
}

/// `Model::parse` checks the new records once: the header's flags, the camera and light
/// records (rest values, aim, slots inside the weights, light references and order) and the
/// tracks that name them.
#[test]
fn the_format_refuses_broken_camera_and_light_records() {
    let good = bytes();
    let section = u32_at(&good, 48);
    let (camera, lights) = (u32_at(&good, section + 40), u32_at(&good, section + 48));
    assert_eq!(u16_at(&good, section + 44), 2);
    let tracks = u32_at(&good, section + 24);
    assert_eq!(good[tracks], 9, "the lamp's position.y comes first");
    let refused = |what: &str, change: &dyn Fn(&mut Vec<u8>)| {
        let mut bytes = good.clone();
        change(&mut bytes);
        Model::parse(&bytes).expect_err(what)
    };
    let invalid = |part, offset| ParseError::Invalid { part, offset };
    // Unknown flags; and without the flag, the lamp's track names a light without a record.
    assert_eq!(refused("flag 2", &|b| put_u16(b, 6, 3)), invalid(Part::Header, 6));
    assert_eq!(refused("no flag", &|b| put_u16(b, 6, 0)), invalid(Part::Track, tracks + 4));
    // The flag with no animation section.
    assert_eq!(refused("no section", &|b| b[48..52].fill(0)), invalid(Part::Header, 6));
    // The camera's slots past the weights, a bad aim, a field of view of 0, a NaN.
    assert_eq!(refused("slots", &|b| put_u16(b, camera + 2, 15)), invalid(Part::AnimatedCamera, camera + 2));
    assert_eq!(refused("aim", &|b| put_u16(b, camera, 3)), invalid(Part::AnimatedCamera, camera));
    assert_eq!(refused("fov", &|b| b[camera + 28..camera + 32].fill(0)), invalid(Part::AnimatedCamera, camera));
    let e = refused("NaN", &|b| b[camera + 4..camera + 8].copy_from_slice(&f32::NAN.to_le_bytes()));
    assert_eq!(e, ParseError::NotFinite { part: Part::AnimatedCamera, offset: camera + 4 });
    // A light past the model's, lights out of order, a light's slots past the weights.
    let e = refused("light 2", &|b| put_u16(b, lights + 32, 2));
    assert_eq!(e, ParseError::BadReference { part: Part::AnimatedLight, offset: lights + 32, index: 2, count: 2 });
    assert_eq!(refused("order", &|b| put_u16(b, lights + 32, 0)), invalid(Part::AnimatedLight, lights + 32));
    assert_eq!(refused("light slots", &|b| put_u16(b, lights + 34, 18)), invalid(Part::AnimatedLight, lights + 34));
    // The lamp's track naming a light without a record (only the sun's is left).
    assert_eq!(refused("no record", &|b| put_u16(b, section + 44, 1)), invalid(Part::Track, tracks + 4));
    let e = refused("fov of 3 components", &|b| b[tracks + 24 * 3 + 2] = 3);
    assert_eq!(e, invalid(Part::Track, tracks + 24 * 3 + 1));
    // No camera record for the animated camera.
    assert_eq!(refused("no camera", &|b| b[44..48].fill(0)), invalid(Part::AnimatedCamera, section + 40));
}

/// `soft3d render --frame` and a `.gif` draw the scene's camera and lights where the pose puts
/// them, unless `--eye`/`--target` or `--light` replace them.
#[test]
fn the_cli_renders_the_posed_camera_and_lights() {
    let dir = std::env::temp_dir().join(format!("soft3d-camera-light-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |name: &str, args: &[&str]| {
        let out = dir.join(name);
        let all = ["render", DATA, "-o", out.to_str().unwrap(), "--size", "64x64", "--background", "0,0,0"];
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_soft3d")).args(all).args(args).output().unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        out
    };
    let picture = |name: &str, args: &[&str]| image::open(run(name, args)).unwrap().to_rgb8();
    let lit = |p: &image::RgbImage| p.pixels().filter(|p| p.0 != [0, 0, 0]).count();
    let first = picture("f0.png", &["--frame", "0"]);
    assert!(lit(&first) > 100);
    // Frame 10: both lights out.
    assert_eq!(lit(&picture("f10.png", &["--frame", "10"])), 0);
    // The user's light lights it; the user's eye and target see it centred, zoomed by the fov.
    let own_light = picture("light.png", &["--frame", "10", "--light", "dir:0,0,1"]);
    assert!(lit(&own_light) > lit(&first));
    let columns = |p: &image::RgbImage| {
        let c: Vec<u32> = p.enumerate_pixels().filter(|(_, _, q)| q.0 != [0, 0, 0]).map(|(x, _, _)| x).collect();
        (*c.iter().min().unwrap(), *c.iter().max().unwrap())
    };
    let centred =
        picture("eye.png", &["--frame", "10", "--eye", "0,0,-10", "--target", "0,0,0", "--light", "dir:0,0,1"]);
    let ((l0, r0), (l1, r1), (l2, r2)) = (columns(&first), columns(&own_light), columns(&centred));
    assert!(l1 < l0 && r1 < 32, "moved left: {l1}..{r1} from {l0}..{r0}");
    assert!(l2 < l0 && r2 > r0 && (l2 + r2).abs_diff(63) <= 1, "centred and larger: {l2}..{r2}");
    // The GIF plays the frames: its last is dark, its first is not.
    let gif = run("anim.gif", &[]);
    let decoder =
        image::codecs::gif::GifDecoder::new(std::io::BufReader::new(std::fs::File::open(gif).unwrap())).unwrap();
    let frames = image::AnimationDecoder::into_frames(decoder).collect_frames().unwrap();
    let lit_rgba = |f: &image::Frame| f.buffer().pixels().filter(|p| p.0[..3] != [0, 0, 0]).count();
    assert_eq!(frames.len(), 11);
    assert!(lit_rgba(&frames[0]) > 100 && lit_rgba(&frames[10]) == 0);
    std::fs::remove_dir_all(&dir).unwrap();
}
