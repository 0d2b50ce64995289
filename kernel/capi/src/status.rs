//! Status codes and their messages.

use core::ffi::{CStr, c_char};

use granbed_kernel::constitutive::UpdateError;

/// Success.
pub const GRANBED_OK: i32 = 0;
/// A required pointer argument is NULL.
pub const GRANBED_ERR_NULL_POINTER: i32 = 1;
/// A material parameter is outside its range (see `granbed_material_check`).
pub const GRANBED_ERR_INVALID_PARAMETER: i32 = 2;
/// A non-material argument is outside its range (a flag, a count, a time
/// step, a mass, a granule type name).
pub const GRANBED_ERR_INVALID_ARGUMENT: i32 = 3;
/// An input (a deformation gradient, coordinate, weight, normal or gap)
/// is NaN or infinite, or a result would overflow.
pub const GRANBED_ERR_NON_FINITE: i32 = 4;
/// det F ≤ 0: the point or element is inverted.
pub const GRANBED_ERR_INVERTED: i32 = 5;
/// The stored plastic state C_p⁻¹ is corrupt (not positive definite, or
/// its determinant not finite).
pub const GRANBED_ERR_INVALID_STATE: i32 = 6;
/// The return map did not reach the yield surface.
pub const GRANBED_ERR_NO_CONVERGENCE: i32 = 7;
/// A quad or hex is degenerate (zero edge, zero normal, non-positive
/// Jacobian).
pub const GRANBED_ERR_DEGENERATE: i32 = 8;
/// A batch call: at least one point or element failed; see its status.
pub const GRANBED_ERR_POINT_FAILED: i32 = 9;
/// An array size overflows the address space.
pub const GRANBED_ERR_SIZE: i32 = 10;

/// The status code of a kernel update error.
pub(crate) fn update_status(e: &UpdateError) -> i32 {
    match e {
        UpdateError::NonFinite => GRANBED_ERR_NON_FINITE,
        UpdateError::InvertedDeformation { .. } => GRANBED_ERR_INVERTED,
        UpdateError::InvalidState { .. } => GRANBED_ERR_INVALID_STATE,
        UpdateError::NoConvergence { .. } => GRANBED_ERR_NO_CONVERGENCE,
    }
}

/// A short English description of status `code`, NUL-terminated, in static
/// storage (never NULL; unknown codes give "unknown status code").
#[unsafe(no_mangle)]
pub extern "C" fn granbed_status_message(code: i32) -> *const c_char {
    let m: &CStr = match code {
        GRANBED_OK => c"ok",
        GRANBED_ERR_NULL_POINTER => c"a required pointer argument is NULL",
        GRANBED_ERR_INVALID_PARAMETER => {
            c"a material parameter is outside its range (granbed_material_check names it)"
        }
        GRANBED_ERR_INVALID_ARGUMENT => c"an argument is outside its documented range",
        GRANBED_ERR_NON_FINITE => c"an input is not finite, or a result would overflow",
        GRANBED_ERR_INVERTED => c"inverted element or point: det F <= 0",
        GRANBED_ERR_INVALID_STATE => {
            c"invalid plastic state: Cp^-1 not positive definite, or its determinant not finite"
        }
        GRANBED_ERR_NO_CONVERGENCE => c"the return map did not converge",
        GRANBED_ERR_DEGENERATE => c"degenerate quad or hex",
        GRANBED_ERR_POINT_FAILED => c"at least one point or element failed (see its status)",
        GRANBED_ERR_SIZE => c"an array size overflows the address space",
        _ => c"unknown status code",
    };
    m.as_ptr()
}
