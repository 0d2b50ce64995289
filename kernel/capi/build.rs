//! Gives the shared library a SONAME on Linux, so that a host linked
//! against it records the ABI it was built for (`libgranbed.so.0.1` for
//! version 0.1.x: before 1.0 a new minor version may change the ABI, the
//! numbering cargo-c uses). `install.sh` installs the library under that
//! name with the `libgranbed.so` link a linker looks for.

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
    }
}
