//! Gives the shared library a SONAME on Linux, so that a host linked
//! against it records the ABI it was built for (`libgranbed.so.0.1` for
//! version 0.1.x: before 1.0 a new minor version may change the ABI, the
//! numbering cargo-c uses). `install.sh` installs the library under that
//! name with the `libgranbed.so` link a linker looks for.
//!
//! It also links the shared library against libc: the compiler's own
//! `memcpy` and `memset` calls are the library's only undefined symbols,
//! and without `-lc` it would not name where they come from (no `NEEDED`
//! entry), so a loader or a `-Wl,--no-undefined` host build could not
//! resolve them from the library alone.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        let major = env!("CARGO_PKG_VERSION_MAJOR");
        let minor = env!("CARGO_PKG_VERSION_MINOR");
        let abi = if major == "0" {
            format!("0.{minor}")
        } else {
            major.to_string()
        };
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libgranbed.so.{abi}");
        println!("cargo:rustc-cdylib-link-arg=-lc");
    }
}
