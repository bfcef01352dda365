//! The `.babylon` reader and the `.s3d` writer on arbitrary JSON-ish bytes: never panic, and
//! whatever `emit` writes, `Model::parse` accepts.
#![no_main]
use libfuzzer_sys::fuzz_target;
use soft3d::convert::{emit, read_babylon, ConvertOptions, EmitOptions};
use soft3d::Model;

fuzz_target!(|data: &[u8]| {
    let Ok((scene, _)) = read_babylon(data, None, "fuzz.babylon", &ConvertOptions::default()) else { return };
    if let Ok(bytes) = emit(&scene, &EmitOptions::default()) {
        Model::parse(&bytes).expect("emit output parses");
    }
});
