//! The constitutive update over slices of integration points.

use core::fmt;

use crate::constitutive::update::{UpdateError, UpdateInfo, UpdateOptions, update_point};
use crate::material::Material;
use crate::tensor::{Mat3, Voigt};

/// Why a batch update stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BatchError {
    /// A buffer does not have one entry per point.
    Length {
        /// Buffer name, as in [`update_points`].
        buffer: &'static str,
        /// Entries expected (the length of `f_np1`).
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// The update of point `index` failed; points before it are updated,
    /// points from it on are untouched.
    Point {
        /// Index of the failing point.
        index: usize,
        /// Its error.
        error: UpdateError,
    },
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Length {
                buffer,
                expected,
                got,
            } => write!(
                f,
                "buffer `{buffer}` has {got} entries, expected {expected}"
            ),
            Self::Point { index, error } => write!(f, "point {index}: {error}"),
        }
    }
}

impl core::error::Error for BatchError {}

/// Updates `f_np1.len()` points in index order.
///
/// * `f_np1[i]`: in, end-of-step deformation gradient of point i.
/// * `cp_inv[i]`: in/out, C_p⁻¹ of point i (Voigt), start → end of step.
/// * `tau[i]`: out, Kirchhoff stress of point i, Pa (Voigt).
/// * `info[i]`: out, diagnostics of point i.
///
/// Returns the number of plastic points.
pub fn update_points(
    mat: &Material,
    opts: &UpdateOptions,
    f_np1: &[Mat3],
    cp_inv: &mut [Voigt],
    tau: &mut [Voigt],
    info: &mut [UpdateInfo],
) -> Result<usize, BatchError> {
    let n = f_np1.len();
    for (buffer, got) in [
        ("cp_inv", cp_inv.len()),
        ("tau", tau.len()),
        ("info", info.len()),
    ] {
        if got != n {
            return Err(BatchError::Length {
                buffer,
                expected: n,
                got,
            });
        }
    }
    let mut plastic = 0;
    for (index, (((f, c), t), i)) in f_np1
        .iter()
        .zip(cp_inv.iter_mut())
        .zip(tau.iter_mut())
        .zip(info.iter_mut())
        .enumerate()
    {
        let up =
            update_point(mat, opts, f, c).map_err(|error| BatchError::Point { index, error })?;
        *t = up.tau;
        *i = up.info;
        plastic += usize::from(up.info.plastic);
    }
    Ok(plastic)
}
