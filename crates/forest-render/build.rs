// intel_tex_2's ISPC kernels include a C++ object (the ASTC encoder) that needs the C++
// runtime; the crate does not link it itself.
fn main() {
    let target = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target == "linux" {
        println!("cargo:rustc-link-lib=dylib=stdc++");
    }
}
