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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constitutive::ReturnMethod;
    use crate::material::GranuleType;
    use crate::tensor::VOIGT_IDENTITY;

    fn blank_info() -> UpdateInfo {
        let mut state = VOIGT_IDENTITY;
        let mat = GranuleType::B2.params().validate().unwrap();
        update_point(
            &mat,
            &UpdateOptions::default(),
            &Mat3::identity(),
            &mut state,
        )
        .unwrap()
        .info
    }

    #[test]
    fn batch_matches_single_points_and_reports_the_failing_index() {
        let mat = GranuleType::B1.params().validate().unwrap();
        let opts = UpdateOptions::default();
        let f = [
            Mat3::identity() * 0.95,
            Mat3::from_diagonal(&[1.0, 1.0, 0.9].into()),
            Mat3::identity() * -1.0,
        ];
        let mut c = [VOIGT_IDENTITY; 3];
        let mut tau = [[0.0; 6]; 3];
        let mut info = [blank_info(); 3];
        let err = update_points(&mat, &opts, &f, &mut c, &mut tau, &mut info).unwrap_err();
        assert!(matches!(
            err,
            BatchError::Point {
                index: 2,
                error: UpdateError::InvertedDeformation { .. }
            }
        ));
        assert_eq!(c[2], VOIGT_IDENTITY);
        let plastic = update_points(
            &mat,
            &opts,
            &f[..2],
            &mut [VOIGT_IDENTITY; 2],
            &mut tau[..2],
            &mut info[..2],
        )
        .unwrap();
        assert_eq!(plastic, 2);
        for k in 0..2 {
            let mut s = VOIGT_IDENTITY;
            assert_eq!(
                update_point(&mat, &opts, &f[k], &mut s).unwrap().tau,
                tau[k]
            );
            assert_ne!(info[k].method, ReturnMethod::Elastic);
        }
        let short = update_points(&mat, &opts, &f, &mut c[..2], &mut tau, &mut info);
        assert_eq!(
            short,
            Err(BatchError::Length {
                buffer: "cp_inv",
                expected: 3,
                got: 2
            })
        );
    }
}
