//! Every image decoder the converter uses, on arbitrary bytes: a `.babylon` scene whose one
//! material's texture is the input (embedded as base64, so no file is read; named `.tga`, the one format with no magic bytes) converts or fails
//! with an error, never a panic. Seeds: a small image in each format (fuzz/seeds/texture).
#![no_main]
use base64::Engine;
use libfuzzer_sys::fuzz_target;
use soft3d::convert::{read_babylon, ConvertOptions};

fuzz_target!(|data: &[u8]| {
    let texture = base64::engine::general_purpose::STANDARD.encode(data);
    let json = format!(
        r#"{{"materials":[{{"id":"m","name":"m","diffuseTexture":{{"name":"t.tga","base64String":"{texture}"}}}}],
        "meshes":[{{"id":"t","name":"t","materialId":"m","positions":[0,0,0,1,0,0,0,1,0],"indices":[0,1,2],
        "uvs":[0,0,1,0,0,1]}}]}}"#
    );
    let options = ConvertOptions { max_texture: Some(64), ..ConvertOptions::default() };
    let _ = read_babylon(json.as_bytes(), None, "fuzz.babylon", &options);
});
