//! The `.s3d` format: every asset converts, emit and parse agree, bad bytes are rejected.
use proptest::prelude::*;
use soft3d::convert::{emit, to_scene, EmitOptions, TextureChoice};
use soft3d::{Model, ParseError, Part, TextureFormat};

mod common;
use common::{asset, scene, ASSETS};

/// Touches every accessor of every record: must never panic on a parsed model.
fn walk(model: &Model<'_>) -> u64 {
    let mut sum = 0u64;
    for (mesh, world) in model.draws() {
        sum += world.is_finite() as u64 + mesh.name().len() as u64;
        for i in 0..mesh.vertex_count() {
            sum += mesh.position(i).is_finite() as u64 + mesh.normal(i).is_finite() as u64;
            sum += mesh.uv(i)[0].is_finite() as u64 + mesh.color(i)[0] as u64;
        }
        for t in 0..mesh.triangle_count() {
            let tri = mesh.triangle(t);
            assert!(tri.iter().all(|&i| i < mesh.vertex_count()));
        }
        for s in mesh.submeshes() {
            assert!(s.first_triangle + s.triangle_count <= mesh.triangle_count());
            if let Some(m) = s.material {
                assert!(model.material(m).is_some());
            }
        }
    }
    for i in 0..model.texture_count() as u16 {
        let t = model.texture(i).unwrap();
        sum += t.rgba(t.width as u32 - 1, t.height as u32 - 1)[0] as u64;
    }
    sum + model.lights().count() as u64 + model.camera().is_some() as u64
}

#[test]
fn every_asset_converts_and_reports_its_size() {
    println!("{:<44} {:>10} {:>10} {:>10}", "asset", ".babylon", ".s3d", "geometry");
    for rel in ASSETS {
        let sc = scene(rel);
        let bytes = emit(&sc, &EmitOptions::default()).unwrap();
        let model = Model::parse(&bytes).unwrap();
        walk(&model);
        let texels: usize = (0..model.texture_count() as u16).map(|i| model.texture(i).unwrap().texels.len()).sum();
        let mut source = std::fs::metadata(asset(rel)).unwrap().len();
        if rel.contains(".binary.") {
            // Geometry lives in side files next to the scene.
            for f in std::fs::read_dir(asset(rel).parent().unwrap()).unwrap() {
                let f = f.unwrap().path();
                if f.extension().is_some_and(|e| e == "babylonbinarymeshdata") {
                    source += std::fs::metadata(f).unwrap().len();
                }
            }
        }
        println!("{rel:<44} {source:>10} {:>10} {:>10}", bytes.len(), bytes.len() - texels);
        // Texels at a multiple of 4 in the file (the Armv6-M span loop's halfword loads).
        for i in 0..model.texture_count() as u16 {
            let offset = model.texture(i).unwrap().texels.as_ptr() as usize - bytes.as_ptr() as usize;
            assert_eq!(offset % 4, 0, "{rel}: texture {i} at byte {offset}");
        }
        // Geometry alone is always much smaller than the JSON it came from.
        assert!(((bytes.len() - texels) as u64) < source, "{rel}");
    }
}

#[test]
fn emit_parse_round_trip_is_exact() {
    for rel in ASSETS {
        for opts in [
            EmitOptions::default(),
            EmitOptions { textures: TextureChoice::Fixed(TextureFormat::Rgba8888), float_positions: true },
            EmitOptions { textures: TextureChoice::Fixed(TextureFormat::Rgb888), float_positions: false },
        ] {
            let first = emit(&scene(rel), &opts).unwrap();
            let decoded = to_scene(&Model::parse(&first).unwrap());
            let second = emit(&decoded, &opts).unwrap();
            let third = emit(&to_scene(&Model::parse(&second).unwrap()), &opts).unwrap();
            // Quantization settles after one pass; from then on the layout is a fixed point.
            assert_eq!(second, third, "{rel} {opts:?}");
            assert_eq!(first.len(), second.len(), "{rel}");
        }
    }
}

#[test]
fn decoded_values_match_the_scene() {
    let sc = scene("suzanne/monkey.babylon");
    let bytes = emit(&sc, &EmitOptions::default()).unwrap();
    let model = Model::parse(&bytes).unwrap();
    let mesh = model.mesh(0).unwrap();
    let m = &sc.meshes[0];
    let extent = 3.0f32; // Suzanne spans about 2.7 units: quantization step is extent / 65535.
    for (i, p) in m.positions.iter().enumerate() {
        let q = mesh.position(i as u32).to_array();
        for k in 0..3 {
            assert!((q[k] - p[k]).abs() <= extent / 65535.0, "position {i}");
        }
        let n = mesh.normal(i as u32).to_array();
        for (a, b) in n.iter().zip(m.normals[i]) {
            assert!((a - b).abs() <= 1.0 / 32767.0);
        }
    }
    assert_eq!(mesh.triangle_count() as usize, m.indices.len() / 3);
    assert_eq!(mesh.triangle(5), [m.indices[15], m.indices[16], m.indices[17]]);
}

fn small_file() -> Vec<u8> {
    emit(&scene("instances/Instances.babylon"), &EmitOptions::default()).unwrap()
}

#[test]
fn truncated_files_are_rejected() {
    let bytes = small_file();
    for len in 0..bytes.len() {
        assert!(Model::parse(&bytes[..len]).is_err(), "prefix of {len} bytes accepted");
    }
    assert!(matches!(Model::parse(&bytes[..10]), Err(ParseError::Truncated { .. })));
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(Model::parse(&longer), Err(ParseError::Truncated { .. })));
}

#[test]
fn corrupted_headers_and_records_are_rejected_with_offsets() {
    let bytes = small_file();
    let mut bad = bytes.clone();
    bad[0] = b'X';
    assert_eq!(Model::parse(&bad).unwrap_err(), ParseError::BadMagic);
    let mut bad = bytes.clone();
    bad[4] = 9;
    assert_eq!(Model::parse(&bad).unwrap_err(), ParseError::UnsupportedVersion(9));

    // Mesh table offset (header 24..28) pointing past the end.
    let mut bad = bytes.clone();
    bad[24..28].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_eq!(Model::parse(&bad).unwrap_err(), ParseError::OutOfBounds { part: Part::Mesh, offset: 24 });

    // A NaN in the first mesh's world matrix.
    let mesh_at = u32::from_le_bytes(bytes[24..28].try_into().unwrap()) as usize;
    let mut bad = bytes.clone();
    bad[mesh_at + 4..mesh_at + 8].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(Model::parse(&bad).unwrap_err(), ParseError::NotFinite { part: Part::Mesh, offset: mesh_at + 4 });

    // An index past the vertex count: the error names the index, its offset and the count.
    let indices_at = u32::from_le_bytes(bytes[mesh_at + 132..mesh_at + 136].try_into().unwrap()) as usize;
    let mut bad = bytes.clone();
    bad[indices_at + 6..indices_at + 8].copy_from_slice(&9001u16.to_le_bytes());
    let err = Model::parse(&bad).unwrap_err();
    assert_eq!(err, ParseError::IndexOutOfRange { offset: indices_at + 6, index: 9001, vertex_count: 36 });
    assert_eq!(err.to_string(), format!("indices: index 9001 at offset {} but only 36 vertices", indices_at + 6));

    // An instance naming a mesh that does not exist.
    let inst_at = u32::from_le_bytes(bytes[36..40].try_into().unwrap()) as usize;
    let mut bad = bytes.clone();
    bad[inst_at..inst_at + 2].copy_from_slice(&7u16.to_le_bytes());
    assert_eq!(
        Model::parse(&bad).unwrap_err(),
        ParseError::BadReference { part: Part::Instance, offset: inst_at, index: 7, count: 1 }
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn parse_never_panics_on_random_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        if let Ok(model) = Model::parse(&bytes) {
            walk(&model);
        }
    }

    #[test]
    fn parse_never_panics_on_mutated_files(edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut bytes = small_file();
        for (at, v) in edits {
            let i = at.index(bytes.len());
            bytes[i] = v;
        }
        if let Ok(model) = Model::parse(&bytes) {
            walk(&model);
        }
    }
}
