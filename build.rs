//! Sets `cfg(soft_float)` on targets without a floating-point unit (Arm `eabi` such as
//! thumbv6m and thumbv7m, RISC-V without the `f` extension), where `math` converts floats to
//! integers in integer code instead of calling the soft-float library (see `math::to_i32`),
//! and `cfg(no_hw_divide)` on targets without a divide instruction (Armv6-M and Armv8-M
//! Baseline, RISC-V without the `m` extension), where the rasterizer walks edges without
//! dividing (see `pipeline/raster/walk.rs`).

fn main() {
    println!("cargo::rustc-check-cfg=cfg(soft_float)");
    println!("cargo::rustc-check-cfg=cfg(no_hw_divide)");
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
}
