//! no_std probe of `granbed-kernel`: one exported function that validates a
//! standard material and runs a full stress update, so the whole kernel path
//! is compiled and linked into a cdylib that has no allocator and no std.
#![no_std]

use granbed_kernel::constitutive::update_point;
use granbed_kernel::material::GranuleType;
use granbed_kernel::tensor::{Mat3, VOIGT_IDENTITY, pressure};

/// Pressure (Pa) of granule type B2 after one update from the virgin state
/// to the deformation gradient F (row-major); NaN on any error.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn granbed_probe_pressure(
    f11: f64,
    f12: f64,
    f13: f64,
    f21: f64,
    f22: f64,
    f23: f64,
    f31: f64,
    f32: f64,
    f33: f64,
) -> f64 {
    let Ok(mat) = GranuleType::B2.params().validate() else {
        return f64::NAN;
    };
    let f = Mat3::new(f11, f12, f13, f21, f22, f23, f31, f32, f33);
    let mut cp_inv = VOIGT_IDENTITY;
    match update_point(&mat, &Default::default(), &f, &mut cp_inv) {
        Ok(up) => pressure(&up.tau),
        Err(_) => f64::NAN,
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
