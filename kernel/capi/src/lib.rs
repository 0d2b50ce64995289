#![cfg_attr(not(test), no_std)]
//! # granbed-capi
//!
//! The C ABI of `granbed-kernel`, for finite-element codes in C, C++ and
//! Fortran: material validation and derived constants, state
//! initialisation, the porous
//! elastoplastic update for a batch of points, the one-point hex element
//! for a batch of elements, and the node-to-quad projection and kinematic
//! contact force. The header is `include/granbed.h` (cbindgen); the
//! Fortran interface module is `fortran/granbed.f90`.
//!
//! Conventions of every function:
//! * Only C types cross the boundary: `double`, `int32_t`, `size_t`,
//!   `char`, plain `#[repr(C)]` structs of those, and pointers to arrays.
//! * Units are SI (m, Pa, kg, s).
//! * Arrays are flat and row-major (C order) unless the function says
//!   otherwise; a "n×9" array holds point i's nine values at 9i..9i+9.
//! * Symmetric tensors are 6 values in the kernel's Voigt order
//!   xx, yy, zz, yz, xz, xy (no factor 2 on the shear terms).
//! * The return value is a status code ([`GRANBED_OK`] = 0, or one of the
//!   `GRANBED_ERR_*` constants); [`granbed_status_message`] names it.
//!   Batch functions also write one status per point or element and carry
//!   on past a failing one; a failed point's state is left unchanged.
//! * No function panics, allocates, keeps global state or is unsafe to
//!   call from several threads on separate buffers. `.ci/capi-check` proves
//!   the first: the shared library is built with `panic = "abort"` and LTO,
//!   and it must contain no panic handler (it would be linked in if any
//!   exported function could reach a panic).

mod buffers;
mod contact;
mod element;
mod material;
mod status;
mod update;
mod vumat;

pub use contact::*;
pub use element::*;
pub use material::*;
pub use status::*;
pub use update::*;
pub use vumat::*;

/// The major version of the header (with GRANBED_VERSION_MINOR and
/// GRANBED_VERSION_PATCH the crate's version): a host can compare it with
/// granbed_version() of the library it loaded.
pub const GRANBED_VERSION_MAJOR: u32 = 0;
/// The minor version of the header.
pub const GRANBED_VERSION_MINOR: u32 = 1;
/// The patch version of the header.
pub const GRANBED_VERSION_PATCH: u32 = 0;

/// The library version, NUL-terminated (static storage): the header's
/// `GRANBED_VERSION_MAJOR.MINOR.PATCH` for a library built with it.
#[unsafe(no_mangle)]
pub extern "C" fn granbed_version() -> *const core::ffi::c_char {
    const VERSION: &core::ffi::CStr = match core::ffi::CStr::from_bytes_with_nul(
        concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes(),
    ) {
        Ok(v) => v,
        Err(_) => c"unknown",
    };
    VERSION.as_ptr()
}

// The C library's abort(3). The library is only ever linked into a C,
// C++ or Fortran program, so libc is always there; it is resolved at the
// final link (static library) or at load time (shared library).
#[cfg(not(test))]
unsafe extern "C" {
    safe fn abort() -> !;
}

// Unreachable: .ci/capi-check fails if this handler is linked into the
// shared library, i.e. if any exported function can reach a panic. Should
// one ever run anyway it must not hang the host (as `loop {}` did): it
// aborts the process with SIGABRT, as a failed C assert() does. abort(3)
// rather than a trap instruction (`asm!("ud2")`): it works on every target
// with a C library, needs no per-architecture code, and tells the host's
// debugger and core dump what happened. (`core::intrinsics::abort` is not
// stable.)
#[cfg(not(test))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    abort()
}

/// Only with the `panic-probe` feature: an exported function that can
/// panic (a checked slice index), so that `.ci/capi-check` can show its
/// panic-handler test would catch one.
#[cfg(feature = "panic-probe")]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_panic_probe(p: *const f64, n: usize, i: usize) -> f64 {
    // SAFETY: test-only; the caller passes n readable doubles.
    let s = unsafe { core::slice::from_raw_parts(p, n) };
    s[i]
}

#[cfg(test)]
mod tests {
    /// The header's version constants are the crate's version, which
    /// granbed_version() returns.
    #[test]
    fn the_version_constants_are_the_crate_version() {
        let text = format!(
            "{}.{}.{}",
            super::GRANBED_VERSION_MAJOR,
            super::GRANBED_VERSION_MINOR,
            super::GRANBED_VERSION_PATCH
        );
        assert_eq!(text, env!("CARGO_PKG_VERSION"));
    }

    /// The header's comments are plain text: no rustdoc link brackets.
    #[test]
    fn the_header_has_no_rustdoc_links() {
        let header = include_str!("../include/granbed.h");
        for (i, line) in header.lines().enumerate() {
            assert!(!line.contains("[`"), "include/granbed.h:{}: {line}", i + 1);
        }
    }
}
