//! `soft3d info`'s animation lines: the groups (frames, loop, tracks and what their keys
//! cost), the skinned meshes and the morphed meshes with their bytes, the camera and lights
//! that move.

use soft3d::animation::{Animation, Track, TrackTarget};
use soft3d::Model;

/// The bytes a track's record and keys take in the file.
fn track_bytes(t: &Track<'_>) -> usize {
    let floats = t.component_count() * if t.has_tangents() { 3 } else { 1 };
    24 + t.key_count() * (8 + 4 * floats)
}

/// What a track moves, in words.
fn target_name(t: &Track<'_>) -> String {
    match t.target() {
        TrackTarget::Position(n) => format!("node {n} position"),
        TrackTarget::Rotation(n) => format!("node {n} rotation"),
        TrackTarget::Scaling(n) => format!("node {n} scaling"),
        TrackTarget::Quaternion(n) => format!("node {n} rotationQuaternion"),
        TrackTarget::Influence(w) => format!("morph weight {w}"),
        TrackTarget::CameraPosition => "camera position".into(),
        TrackTarget::CameraTarget => "camera target".into(),
        TrackTarget::CameraRotation => "camera rotation".into(),
        TrackTarget::CameraFov => "camera fov".into(),
        TrackTarget::LightVector(l) => format!("light {l} position or direction"),
        TrackTarget::LightDiffuse(l) => format!("light {l} diffuse"),
        TrackTarget::LightIntensity(l) => format!("light {l} intensity"),
    }
}

/// Prints `model`'s animations (nothing for a still model).
pub(crate) fn print_animation(model: &Model<'_>) {
    let Some(a) = model.animation() else { return };
    println!(
        "  animation: {} groups, {} tracks, {} animated nodes and bones, {} morphed meshes, {} pose weights, {} skinned meshes ({} bones)",
        a.group_count(),
        a.track_count(),
        a.node_count(),
        a.morph_count(),
        a.weight_count(),
        a.skin_count(),
        a.palette_count()
    );
    for g in (0..a.group_count()).filter_map(|g| a.group(g)) {
        let (from, to) = g.range();
        let tracks: Vec<Track<'_>> = g.tracks().filter_map(|t| a.track(t)).collect();
        let bytes: usize = tracks.iter().map(track_bytes).sum();
        let fps = tracks.first().map_or(0.0, Track::fps);
        let looping = if g.loops() { "looping" } else { "once" };
        println!(
            "    group \"{}\": frames {from} to {to} at {fps} fps, {looping}, {} tracks, {bytes} bytes",
            g.name(),
            tracks.len()
        );
        for t in &tracks {
            println!(
                "      {}: {} keys{}",
                target_name(t),
                t.key_count(),
                if t.has_tangents() { " with tangents" } else { "" }
            );
        }
    }
    print_morphs(model, &a);
    print_view(&a);
}

/// The animated camera and lights: how the camera aims, which lights move, their slots.
fn print_view(a: &Animation<'_>) {
    if let Some(c) = a.camera() {
        println!("    camera moves, aimed by {:?} (weights {:?})", c.aim(), c.slots());
    }
    for l in (0..a.animated_light_count()).filter_map(|i| a.animated_light(i)) {
        println!("    light {} moves (weights {:?})", l.light(), l.slots());
    }
}

fn print_morphs(model: &Model<'_>, a: &Animation<'_>) {
    for s in (0..a.skin_count()).filter_map(|i| a.skin_at(i)) {
        let vertices = model.mesh(s.mesh()).map_or(0, |mesh| mesh.vertex_count() as usize);
        println!(
            "    skin of mesh {}: {} bones (palette {:?}), {} bytes",
            s.mesh(),
            s.bone_count(),
            s.palette(),
            16 + 52 * s.bone_count() + 12 * vertices
        );
    }
    for m in (0..a.morph_count()).filter_map(|i| a.morph_at(i)) {
        let vertices = model.mesh(m.mesh()).map_or(0, |mesh| mesh.vertex_count() as usize);
        let per_target = 20 + 6 * vertices * if m.has_normals() { 2 } else { 1 };
        println!(
            "    morph of mesh {}: {} targets (weights {:?}), {} bytes{}",
            m.mesh(),
            m.target_count(),
            m.weights(),
            per_target * m.target_count() as usize,
            if m.has_normals() { ", with normals" } else { "" }
        );
    }
}

/// The model's lights, fog and camera, a line each.
pub(crate) fn print_lights_fog_camera(model: &Model<'_>) {
    for l in model.lights() {
        println!(
            "  light {:?} {:?} diffuse {:?} intensity {}",
            l.kind,
            l.vector.to_array(),
            l.diffuse.to_array(),
            l.intensity
        );
    }
    if let Some(f) = model.fog() {
        println!(
            "  fog {:?} colour {:?}, density {}, start {}, end {}",
            f.mode,
            f.color.to_array(),
            f.density,
            f.start,
            f.end
        );
    }
    if let Some(c) = model.camera() {
        println!(
            "  camera at {:?} looking at {:?}, fov {}, near {}, far {}",
            c.position.to_array(),
            c.target.to_array(),
            c.fov,
            c.near,
            c.far
        );
    }
}
