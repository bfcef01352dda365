//! Sets `cfg(soft_float)` on targets without a floating-point unit (Arm `eabi` such as
//! thumbv6m and thumbv7m, RISC-V without the `f` extension), where `math` converts floats to
//! integers in integer code instead of calling the soft-float library (see `math::to_i32`),
//! and `cfg(no_hw_divide)` on targets without a divide instruction (Armv6-M and Armv8-M
//! Baseline, RISC-V without the `m` extension), where the rasterizer walks edges without
//! dividing (see `pipeline/raster/walk.rs`), and `cfg(span_asm)` on Armv7-M and Armv8-M
//! Mainline (Thumb-2 with `usat` and `mla`), where the span loop draws the common variant in
//! assembly (see `pipeline/span/`), and `cfg(span_asm_v6m)` on Armv6-M and Armv8-M Baseline,
//! where it draws that variant's runs in Thumb-1 assembly (`cfg(asm_runs)`: either), unless the
//! feature `checked-spans` asks for the checked Rust loop.

fn main() {
    // What follows reads only the target and the features (each build of its own), not the
    // package's files: without this line any edited file, a script or a note, rebuilt the crate.
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(soft_float)");
    println!("cargo::rustc-check-cfg=cfg(no_hw_divide)");
    println!("cargo::rustc-check-cfg=cfg(span_asm)");
    println!("cargo::rustc-check-cfg=cfg(span_asm_v6m)");
    println!("cargo::rustc-check-cfg=cfg(asm_runs)");
    let var = |name: &str| std::env::var(name).unwrap_or_default();
    let (arch, abi, features) =
        (var("CARGO_CFG_TARGET_ARCH"), var("CARGO_CFG_TARGET_ABI"), var("CARGO_CFG_TARGET_FEATURE"));
    let has_f = features.split(',').any(|f| f == "f");
    if (arch == "arm" && abi == "eabi") || (arch.starts_with("riscv") && !has_f) {
        println!("cargo::rustc-cfg=soft_float");
    }
    let target = var("TARGET");
    let armv6m_or_v8m_base = target.starts_with("thumbv6m") || target.starts_with("thumbv8m.base");
    if armv6m_or_v8m_base || (arch.starts_with("riscv") && !features.split(',').any(|f| f == "m")) {
        println!("cargo::rustc-cfg=no_hw_divide");
    }
    let thumb2 = ["thumbv7m", "thumbv7em", "thumbv8m.main"].iter().any(|t| target.starts_with(t));
    let checked = std::env::var_os("CARGO_FEATURE_CHECKED_SPANS").is_some();
    if thumb2 && !checked {
        println!("cargo::rustc-cfg=span_asm");
    }
    if armv6m_or_v8m_base && !checked {
        println!("cargo::rustc-cfg=span_asm_v6m");
    }
    if (thumb2 || armv6m_or_v8m_base) && !checked {
        println!("cargo::rustc-cfg=asm_runs");
    }
}
