//! Links Embree 3 only when the `embree` feature asks for it, so that the normal build
//! never needs the library.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_EMBREE").is_some() {
        println!("cargo:rustc-link-lib=dylib=embree3");
    }
}
