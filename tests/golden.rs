//! Every picture pinned: the `soft3d render` CLI draws every scene in `../shared/assets/` in
//! each mode, shading, pixel format and depth kind (plus bands, filters, dithering, specular,
//! sub-spans and the fixed-point vertex path), and the hash of each picture's pixels must equal
//! the one recorded in `tests/golden/cli-renders.txt`.
//!
//! The other image tests compare bands with whole frames and QEMU with the host, so they would
//! not notice a picture that changed everywhere; this one does. The hashes were recorded at
//! commit `25acddd` (before the pipeline was split into stage modules); two changed since, by one
//! RGB565/gray step at one pixel each, when affine planes stopped being built on unbounded
//! gradients (see `tests/regressions.rs`), and twelve of the teapot's when small triangles'
//! boxes grew from 24 to 32 pixel centres (`raster::small`: those triangles' pixels get exact
//! varyings instead of affine ones within 1/16 texel; at most 18 pixels of a render differ, by
//! one step of 8-bit or RGB565 colour), and the 143 renders of the six scenes without a camera
//! when those got `Camera::fit`'s tight framing instead of the bounding sphere's. A change to any
//! picture must be deliberate: rerun with `SOFT3D_BLESS=1` to record new hashes, and say why in
//! the commit.
//!
//! Without `../shared/assets` (a clone without the shared folder beside it) the test says so and
//! passes, unless `SOFT3D_REQUIRE_GOLDEN` is set, as the test command sets it.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Frame size of every render: small, so that the whole set takes seconds.
const SIZE: &str = "160x120";

/// The variants drawn of every scene: each mode, each shading, each pixel format, each depth
/// kind, and the options that choose other code paths.
const VARIANTS: &[&str] = &[
    "",
    "--mode wire",
    "--mode points",
    "--mode solid-wire",
    "--shading unlit",
    "--shading flat",
    "--shading phong",
    "--format rgb565",
    "--format gray8",
    "--format mono",
    "--depth f32",
    "--depth none",
    "--bands 7",
    "--filter bilinear",
    "--format rgb565 --dither",
    "--format mono --dither",
    "--specular 32",
    "--shading flat --specular 16",
    "--subspan 8",
    "--fixed-vertices",
    "--fixed-vertices --format rgb565 --bands 5",
    "--shading phong --format rgb565 --bands 3",
    "--texture-format rgb565 --format rgb565",
    "--float-positions",
    "--eye 0,0.5,-0.4 --target 0,0,0 --near 0.05",
];

fn shared_assets() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets");
    dir.is_dir().then_some(dir)
}

/// Every `.babylon` below `dir`, sorted.
fn scenes(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "babylon") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// FNV-1a (64 bits) of `bytes`.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// The hash of the pixels `soft3d render` draws of `scene` with `variant`, or `error` when it
/// refuses (a refusal is pinned too).
fn render_hash(scene: &Path, variant: &str, out: &Path) -> String {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_soft3d"));
    cmd.arg("render").arg(scene).arg("-o").arg(out).args(["--size", SIZE]);
    cmd.args(variant.split_whitespace());
    let result = cmd.output().unwrap();
    if !result.status.success() {
        return "error".into();
    }
    let img = image::open(out).unwrap().to_rgb8();
    format!("{:016x}", fnv1a(img.as_raw()))
}

/// `scene | variant | hash` for every scene and variant, in a fixed order.
fn all_hashes(assets: &Path) -> Vec<String> {
    let jobs: Vec<(PathBuf, &str)> =
        scenes(assets).into_iter().flat_map(|s| VARIANTS.iter().map(move |v| (s.clone(), *v))).collect();
    let tmp = std::env::temp_dir().join(format!("soft3d-golden-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    assert!(!jobs.is_empty(), "no .babylon scene in {}", assets.display());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let chunk = jobs.len().div_ceil(threads);
    let lines: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = jobs
            .chunks(chunk)
            .enumerate()
            .map(|(k, part)| {
                let out = tmp.join(format!("{k}.png"));
                s.spawn(move || {
                    part.iter()
                        .map(|(scene, variant)| {
                            let name = scene.strip_prefix(assets).unwrap().display().to_string();
                            format!("{name} | {variant} | {}", render_hash(scene, variant, &out))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    let _ = std::fs::remove_dir_all(&tmp);
    lines
}

#[test]
fn cli_renders_of_every_shared_scene_are_unchanged() {
    let Some(assets) = shared_assets() else {
        // The test command sets SOFT3D_REQUIRE_GOLDEN: there a missing folder is a failure.
        assert!(std::env::var_os("SOFT3D_REQUIRE_GOLDEN").is_none(), "no ../shared/assets beside the repository");
        println!("skipped: no ../shared/assets beside the repository");
        return;
    };
    let recorded_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/cli-renders.txt");
    let lines = all_hashes(&assets);
    if std::env::var_os("SOFT3D_BLESS").is_some() {
        std::fs::write(&recorded_path, lines.join("\n") + "\n").unwrap();
        println!("recorded {} hashes in {}", lines.len(), recorded_path.display());
        return;
    }
    let recorded = std::fs::read_to_string(&recorded_path).unwrap();
    let recorded: Vec<&str> = recorded.lines().collect();
    let differing: Vec<String> = lines
        .iter()
        .zip(&recorded)
        .filter(|(now, then)| now.as_str() != **then)
        .map(|(now, then)| format!("  now  {now}\n  then {then}"))
        .collect();
    assert_eq!(lines.len(), recorded.len(), "the set of renders changed");
    assert!(differing.is_empty(), "{} of {} pictures changed:\n{}", differing.len(), lines.len(), differing.join("\n"));
    let refused = lines.iter().filter(|l| l.ends_with("| error")).count();
    println!("{} pictures unchanged ({refused} refused, as recorded)", lines.len());
}
