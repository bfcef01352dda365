//! `Model::parse` on arbitrary bytes, then every accessor and a small render: never panics.
//!
//! A model with an animation section (`.s3d` version 2) also has every accessor of its
//! animation called (nodes, links, morphs and their deltas, skins and their bones and
//! influences, the animated camera and lights, tracks and their keys, groups; indices past the
//! last too) and what `Model::parse` promised about them checked; a pose evaluated at frames
//! taken from the input
//! (any bit pattern, NaN, infinities, huge, around a group's range), for every group at once,
//! one group, and groups past the last; pose memory sized by `pose_memory` (node matrices, bone
//! matrices, weights), one entry too small (`PoseError::TooSmall`, the pose left unset) and
//! larger; the pose's camera and lights read (the stored ones when unset); and the model drawn
//! posed (set and unset, with the posed lights) in two bands sharing a scratch. Counts are
//! u16 and tables may share records, so the accessor walk is bounded ([`BUDGET`]) to keep every
//! input fast.
#![no_main]
use embedded_graphics_core::pixelcolor::Rgb565;
use libfuzzer_sys::fuzz_target;
use soft3d::animation::{pose_memory, Animation, Pose, PoseError, TrackTarget};
use soft3d::{
    Band, Camera, Lights, Mat4, Model, RenderOptions, Renderer, Scratch, TransformedVertex, TriangleRows, Vec3, Vec4,
};

/// Accessor calls the animation walk may make for one input.
const BUDGET: usize = 1 << 15;

fuzz_target!(|data: &[u8]| {
    let Ok(model) = Model::parse(data) else { return };
    for (mesh, _) in model.draws() {
        for i in 0..mesh.vertex_count().min(4096) {
            let _ = (mesh.position(i), mesh.normal(i), mesh.uv(i), mesh.color(i));
        }
    }
    let camera = Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0).unwrap();
    let lights = Lights::<2>::from_model(&model);
    let mut color = [Rgb565::default(); 32 * 8];
    let mut depth = [0u16; 32 * 8];
    let mut band = Band::new(&mut color[..], &mut depth[..], 32, 32, 8).unwrap();
    // With the file's fog, whatever it holds.
    let renderer = Renderer::new(&camera, &lights, RenderOptions { fog: model.fog(), ..RenderOptions::default() });
    renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut Scratch::none()).expect("stored order needs no scratch");

    let hash = fnv(data);
    match model.animation() {
        Some(animation) => {
            accessors(&model, &animation);
            poses(&model, &animation, hash);
        }
        None => {
            // Without animation a pose draws the model at rest (as `draw`).
            let pose = Pose::new(&mut [], &mut []);
            draw_posed(&model, &pose);
        }
    }
});

/// FNV-1a of the input: the frames and groups the pose is evaluated at.
fn fnv(data: &[u8]) -> u64 {
    data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// Every public accessor of `animation`, with what `Model::parse` checked asserted.
fn accessors(model: &Model<'_>, animation: &Animation<'_>) {
    let mut budget = BUDGET;
    let mut spend = |n: usize| {
        budget = budget.saturating_sub(n);
        budget > 0
    };
    let nodes = animation.node_count();
    let weights = animation.weight_count();
    let tracks = animation.track_count();
    let groups = animation.group_count();
    let morphs = animation.morph_count();
    let links = animation.link_count();
    let skins = animation.skin_count();
    let palette = animation.palette_count();
    let meshes = model.mesh_count();

    for i in 0..nodes {
        if !spend(1) {
            break;
        }
        let node = animation.node(i).expect("a node below the count");
        if let Some(parent) = node.parent() {
            assert!(parent < i, "node {i}'s parent {parent} comes after it");
        }
        let (rotation, _quaternion) = node.rotation();
        assert!(node.position().is_finite() && rotation.is_finite() && node.scaling().is_finite());
        assert!(node.above().is_finite());
    }
    assert!(animation.node(nodes).is_none() && animation.node(usize::MAX).is_none());

    for i in 0..tracks {
        if !spend(1) {
            break;
        }
        let track = animation.track(i).expect("a track below the count");
        let (first, count) = (track.first_component(), track.component_count());
        match track.target() {
            TrackTarget::Position(n) | TrackTarget::Rotation(n) | TrackTarget::Scaling(n) => {
                assert!((n as usize) < nodes && count >= 1 && first + count <= 3);
            }
            TrackTarget::Quaternion(n) => assert!((n as usize) < nodes && first == 0 && count == 4),
            TrackTarget::Influence(w) => assert!((w as usize) < weights && first == 0 && count == 1),
            TrackTarget::CameraPosition | TrackTarget::CameraTarget | TrackTarget::CameraRotation => {
                assert!(animation.camera().is_some() && count >= 1 && first + count <= 3);
            }
            TrackTarget::CameraFov => assert!(animation.camera().is_some() && first == 0 && count == 1),
            TrackTarget::LightVector(l) | TrackTarget::LightDiffuse(l) => {
                assert!(animation.animated_light_of(l as usize).is_some() && count >= 1 && first + count <= 3);
            }
            TrackTarget::LightIntensity(l) => {
                assert!(animation.animated_light_of(l as usize).is_some() && first == 0 && count == 1);
            }
        }
        assert!(track.loop_mode() <= 2);
        let tangents = track.has_tangents();
        assert!(track.fps().is_finite() && track.fps() > 0.0);
        let keys = track.key_count();
        assert!(keys >= 1);
        let mut last = f32::NEG_INFINITY;
        for k in 0..keys {
            if !spend(1) {
                break;
            }
            let frame = track.frame(k);
            assert!(frame.is_finite() && frame >= last, "track {i} key {k}: frame {frame} after {last}");
            last = frame;
            let _ = track.is_step(k);
            for set in [0, 1, 2, usize::MAX] {
                let value = track.value(k, set);
                assert!((count..4).all(|c| value[c] == 0.0), "components past the count are zero");
                if set == 0 || tangents {
                    assert!(value.is_finite());
                }
            }
        }
        // Past the last key: zeros, not a neighbour's bytes or a panic.
        for k in [keys, usize::MAX / 2, usize::MAX] {
            assert!(track.frame(k) == 0.0 && !track.is_step(k));
            assert!(track.value(k, 0) == Vec4::ZERO && track.value(k, usize::MAX) == Vec4::ZERO);
        }
    }
    assert!(animation.track(tracks).is_none() && animation.track(usize::MAX).is_none());

    for g in 0..groups {
        if !spend(1) {
            break;
        }
        let group = animation.group(g).expect("a group below the count");
        let (from, to) = group.range();
        assert!(from.is_finite() && to.is_finite() && from <= to);
        let _ = group.loops();
        for t in group.tracks() {
            if !spend(1) {
                break;
            }
            assert!(t < tracks && animation.track(t).is_some());
        }
        let name = group.name();
        // The first group of that name (the name costs a walk over the groups).
        if spend(g + 1) {
            let found = animation.group_named(name).expect("a group's own name finds a group");
            assert!(found <= g && animation.group(found).unwrap().name() == name);
        }
    }
    assert!(animation.group(groups).is_none() && animation.group(usize::MAX).is_none());
    if spend(groups) {
        let _ = animation.group_named("\u{0}not a group name\u{0}");
    }

    let mut last_mesh = None;
    for i in 0..morphs {
        if !spend(1) {
            break;
        }
        let morph = animation.morph_at(i).expect("a morph below the count");
        let mesh = morph.mesh();
        assert!(mesh < meshes && last_mesh.is_none_or(|l| l < mesh), "morphs by increasing mesh");
        last_mesh = Some(mesh);
        let targets = morph.target_count() as usize;
        assert!(targets >= 1);
        let range = morph.weights();
        assert!(range.len() == targets && range.end <= weights);
        let normals = morph.has_normals();
        let vertices = model.mesh(mesh).map_or(0, |m| m.vertex_count());
        for t in 0..targets {
            if !spend(1) {
                break;
            }
            assert!(morph.default_influence(t).is_finite());
            // Every vertex, then past the last (zero or a neighbour's bytes, not a panic).
            let _ = (morph.delta(t, u32::MAX, false), morph.delta(t, u32::MAX, true));
            for v in 0..=vertices {
                if !spend(1) {
                    break;
                }
                let _ = morph.delta(t, v, false);
                let n = morph.delta(t, v, true);
                if !normals {
                    assert_eq!(n, Vec3::ZERO);
                }
            }
        }
    }
    // Past the last target: zeros.
    for morph in (0..morphs.min(64)).filter_map(|i| animation.morph_at(i)) {
        for t in [morph.target_count() as usize, usize::MAX / 2, usize::MAX] {
            assert_eq!(morph.default_influence(t), 0.0);
            assert!(morph.delta(t, 0, false) == Vec3::ZERO && morph.delta(t, u32::MAX, true) == Vec3::ZERO);
        }
    }
    assert!(animation.morph_at(morphs).is_none() && animation.morph_at(usize::MAX).is_none());

    view(model, animation, &mut spend);

    let mut last_mesh = None;
    for i in 0..skins {
        if !spend(1) {
            break;
        }
        let skin = animation.skin_at(i).expect("a skin below the count");
        let mesh = skin.mesh();
        assert!(mesh < meshes && last_mesh.is_none_or(|l| l < mesh), "skins by increasing mesh");
        last_mesh = Some(mesh);
        let bones = skin.bone_count();
        assert!(bones >= 1);
        let range = skin.palette();
        assert!(range.len() == bones && range.end <= palette);
        for b in 0..bones {
            if !spend(1) {
                break;
            }
            assert!(skin.bone_node(b).is_some_and(|n| n < nodes));
            assert!(skin.inverse_bind(b).is_finite());
        }
        assert!(skin.bone_node(bones).is_none() && skin.bone_node(usize::MAX).is_none());
        assert_eq!(skin.inverse_bind(usize::MAX), Mat4::IDENTITY);
        // Every vertex, then past the last (zero weights, not a panic).
        let vertices = model.mesh(mesh).map_or(0, |m| m.vertex_count());
        for v in 0..vertices {
            if !spend(1) {
                break;
            }
            let (b, w) = skin.influences(v);
            assert!(b.iter().all(|&b| (b as usize) < bones) && w.iter().all(|w| (0.0..=1.0).contains(w)));
        }
        let _ = (skin.influences(vertices), skin.influences(u32::MAX));
    }
    assert!(animation.skin_at(skins).is_none() && animation.skin_at(usize::MAX).is_none());

    // Every mesh's morph, skin and link (and one past the last mesh: none).
    for mesh in 0..=meshes {
        if !spend(morphs + skins + links + 1) {
            break;
        }
        if let Some(morph) = animation.morph_of(mesh) {
            assert_eq!(morph.mesh(), mesh);
        }
        if let Some(skin) = animation.skin_of(mesh) {
            assert_eq!(skin.mesh(), mesh);
        }
        if let Some((node, below)) = animation.link_of(mesh) {
            assert!(mesh < meshes && node < nodes && below.is_finite());
        }
    }
}

/// The animated camera and lights, with what `Model::parse` checked asserted.
fn view(model: &Model<'_>, animation: &Animation<'_>, spend: &mut impl FnMut(usize) -> bool) {
    let weights = animation.weight_count();
    if let Some(c) = animation.camera() {
        assert!(model.camera().is_some(), "an animated camera needs a camera record");
        let _ = c.aim();
        assert!(c.slots().len() == 10 && c.slots().end <= weights);
        assert!(c.position().is_finite() && c.target().is_finite() && c.rotation().is_finite());
        assert!(c.fov() > 0.0 && c.fov() < core::f32::consts::PI && c.distance() >= 0.0);
    }
    let mut last = None;
    for i in 0..animation.animated_light_count() {
        if !spend(1) {
            break;
        }
        let l = animation.animated_light(i).expect("an animated light below the count");
        let light = l.light();
        assert!(light < model.light_count() && last.is_none_or(|last| last < light), "lights by increasing light");
        last = Some(light);
        assert!(l.slots().len() == 7 && l.slots().end <= weights);
        assert!(l.vector().is_finite() && l.diffuse().is_finite() && l.intensity().is_finite());
        if spend(8) {
            assert_eq!(animation.animated_light_of(light).map(|l| l.light()), Some(light));
        }
    }
    let n = animation.animated_light_count();
    assert!(animation.animated_light(n).is_none() && animation.animated_light(usize::MAX).is_none());
    assert!(animation.animated_light_of(usize::MAX).is_none());
}

/// The pose's camera and lights: the stored ones when the pose is not set (`set` false).
fn posed_view(model: &Model<'_>, animation: &Animation<'_>, pose: &Pose<'_>, set: bool) {
    if let Some(still) = model.camera() {
        let c = pose.camera(animation, still);
        assert!(c.near == still.near && c.far == still.far);
        if !set || animation.camera().is_none() {
            assert_eq!(c, still);
        }
        let _ = Camera::from_scene(&c, 1.0);
    }
    for (i, still) in model.lights().enumerate().take(64) {
        let l = pose.light(animation, i, still);
        assert_eq!(l.kind, still.kind);
        if !set || animation.animated_light_of(i).is_none() {
            assert_eq!(l, still);
        }
    }
    let _ = pose.light(animation, usize::MAX, Lights::<1>::point(Vec3::ZERO, 1.0));
}

/// Poses at frames and groups taken from `hash`, in memory too small (drawn unset), of
/// `pose_memory`'s size (one set pose drawn) and larger.
fn poses(model: &Model<'_>, animation: &Animation<'_>, hash: u64) {
    let (nodes, bones) = (animation.node_count(), animation.palette_count());
    let (n, w) = pose_memory(nodes, bones, animation.weight_count());
    let groups = animation.group_count();
    let mut matrices = vec![Mat4::IDENTITY; n + 1];
    let mut weights = vec![0.0f32; w + 1];
    let picked = (groups > 0).then(|| (hash >> 40) as usize % groups);
    let (from, to) = picked.and_then(|g| animation.group(g)).map_or((0.0, 100.0), |g| g.range());
    let t = ((hash >> 48) as u16 as f32 / 65535.0) * 3.0 - 1.0;
    let frames = [
        f32::from_bits(hash as u32),
        from + (to - from) * t,
        to,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MAX,
        -1e30,
        (hash >> 32) as u16 as f32 * 1e6,
    ];
    let choices = [None, picked, Some(groups), Some((hash >> 8) as usize), Some(usize::MAX)];

    // Too small: one node matrix or one weight short, whatever the frame and group.
    if n > 0 || w > 0 {
        let (sn, sw) = if n > 0 && (w == 0 || hash & 1 == 0) { (n - 1, w) } else { (n, w - 1) };
        let mut pose = Pose::new(&mut matrices[..sn], &mut weights[..sw]);
        for (frame, group) in [(frames[0], None), (frames[1], picked), (frames[3], Some(usize::MAX))] {
            let err = pose.evaluate(animation, frame, group).expect_err("memory too small");
            assert_eq!(err, PoseError::TooSmall { nodes: n, weights: w });
            assert!(!err.to_string().is_empty());
            assert_unset(&pose, nodes);
        }
        posed_view(model, animation, &pose, false);
        draw_posed(model, &pose);
    }

    // Exactly `pose_memory`: every frame with every group choice; a set pose drawn at a frame
    // taken from the input.
    let mut pose = Pose::new(&mut matrices[..n], &mut weights[..w]);
    assert_unset(&pose, nodes);
    let drawn_at = (hash as usize >> 4) % frames.len();
    for (k, &frame) in frames.iter().enumerate() {
        for &group in &choices {
            match pose.evaluate(animation, frame, group) {
                Ok(()) => {
                    assert!(group.is_none_or(|g| g < groups));
                    assert_eq!(pose.weights().len(), w);
                    assert!((0..nodes.min(BUDGET)).all(|i| pose.node_world(i).is_some()));
                    assert!(pose.node_world(nodes).is_none() && pose.node_world(usize::MAX).is_none());
                    assert_eq!(pose.palette().len(), bones);
                    posed_view(model, animation, &pose, true);
                }
                Err(PoseError::NoSuchGroup(g)) => {
                    assert!(Some(g) == group && g >= groups);
                    assert!(!PoseError::NoSuchGroup(g).to_string().is_empty());
                    assert_unset(&pose, nodes);
                }
                Err(e) => panic!("memory of pose_memory's size: {e}"),
            }
        }
        if k == drawn_at {
            pose.evaluate(animation, frame, if hash & 2 == 0 { None } else { picked }).unwrap();
            draw_posed(model, &pose);
        }
    }

    // More than enough: the extra is left alone.
    let mut pose = Pose::new(&mut matrices, &mut weights);
    if pose.evaluate(animation, frames[1], picked).is_ok() {
        assert_eq!((pose.weights().len(), pose.palette().len()), (w, bones));
        assert!(pose.node_world(nodes).is_none());
    }
}

/// A pose that is not set: no node matrices, no weights.
fn assert_unset(pose: &Pose<'_>, nodes: usize) {
    assert!(pose.weights().is_empty() && pose.palette().is_empty());
    assert!((0..nodes.min(BUDGET)).all(|i| pose.node_world(i).is_none()));
}

/// Draws `model` in `pose`, rows 8..16 then 16..24 of a 32x32 frame sharing one scratch (its
/// rows and vertices keyed by the pose), framed on the model's bounds when it has some.
fn draw_posed(model: &Model<'_>, pose: &Pose<'_>) {
    let camera = model
        .bounds()
        .and_then(|(c, r)| Camera::perspective(c - Vec3::Z * 3.0 * r, c, 0.8, 1.0, 0.1 * r, 10.0 * r).ok())
        .unwrap_or_else(|| Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0).unwrap());
    let lights = Lights::<2>::from_model_posed(model, pose);
    let renderer = Renderer::new(&camera, &lights, RenderOptions::default());
    let (triangles, vertices) = model.draw_counts();
    let mut rows = vec![TriangleRows::UNKNOWN; triangles.min(1 << 16)];
    let mut verts = vec![TransformedVertex::UNKNOWN; vertices.min(1 << 16)];
    let mut scratch = Scratch::none().with_rows(&mut rows).with_vertices(&mut verts);
    let mut color = [Rgb565::default(); 32 * 8];
    let mut depth = [0u16; 32 * 8];
    for first_row in [8, 16] {
        let mut band = Band::new(&mut color[..], &mut depth[..], 32, 32, first_row).unwrap();
        renderer.draw_posed(&mut band, model, pose, Mat4::IDENTITY, &mut scratch).expect("stored order");
    }
}
