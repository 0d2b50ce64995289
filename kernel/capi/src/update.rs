//! The constitutive update for a batch of integration points.

use granbed_kernel::constitutive::{PointUpdate, UpdateOptions, update_point};
use granbed_kernel::material::Material;
use granbed_kernel::tensor::{self, Mat3, Voigt};

use crate::buffers::{input, one, optional_output, output, status};
use crate::material::{GranbedMaterialParams, validated};
use crate::status::{
    GRANBED_ERR_INVALID_ARGUMENT, GRANBED_ERR_POINT_FAILED, GRANBED_OK, update_status,
};

/// Stress measure flag: Kirchhoff stress τ = Jσ, Pa.
pub const GRANBED_STRESS_KIRCHHOFF: i32 = 0;
/// Stress measure flag: Cauchy stress σ = τ/J, Pa.
pub const GRANBED_STRESS_CAUCHY: i32 = 1;

/// What one point's update did (all zero for a failed point).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedPointInfo {
    /// J = det F (current / reference volume).
    pub j: f64,
    /// Relative density η = η0/J after the step.
    pub eta: f64,
    /// Plastic dissipation of the step per unit reference volume, J/m³:
    /// Δγ τ:∂φ/∂τ at the returned stress (0 for an elastic step). The
    /// return map is not exactly work-conjugate, so the stress work less
    /// the change of ψ (the header's energy) and the summed dissipation
    /// leave a gap, a few per cent of the work for the standard types with
    /// `volume_fix` = 1 and more without; a host that needs an exact
    /// balance takes the dissipation as that difference instead.
    pub dissipation_density: f64,
    /// Hourglass energy (k/2) Σ|q|² stored in the element, J
    /// (`granbed_hex_forces`; 0 for a material point), for a host's energy
    /// balance (with the same gap as `dissipation_density`).
    pub hourglass_energy: f64,
    /// 1 if the step was plastic, else 0.
    pub plastic: i32,
    /// Return-map iterations (0 for elastic steps and the radial return).
    pub iterations: i32,
}

/// The update options of the `volume_fix` flag (1: the volume-drift
/// correction of physics.md §1.6, the default; 0: the published algorithm
/// literally).
pub(crate) fn options(volume_fix: i32) -> Result<UpdateOptions, i32> {
    match volume_fix {
        0 | 1 => Ok(UpdateOptions {
            volume_fix: volume_fix == 1,
            ..UpdateOptions::default()
        }),
        _ => Err(GRANBED_ERR_INVALID_ARGUMENT),
    }
}

/// Row-major 9 values as a 3×3 matrix.
pub(crate) fn mat_row_major(f: &[f64; 9]) -> Mat3 {
    Mat3::new(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8])
}

/// The info record of a successful update at det F = `j`.
pub(crate) fn point_info(up: &PointUpdate, j: f64) -> GranbedPointInfo {
    GranbedPointInfo {
        j,
        eta: up.info.eta,
        dissipation_density: up.dissipation_density(),
        hourglass_energy: 0.0,
        plastic: i32::from(up.info.plastic),
        iterations: i32::try_from(up.info.iterations).unwrap_or(i32::MAX),
    }
}

/// The stress of `up` in the measure `measure` at det F = `j`.
pub(crate) fn stress_in(up: &PointUpdate, j: f64, measure: i32) -> Voigt {
    if measure == GRANBED_STRESS_CAUCHY {
        tensor::cauchy_from_kirchhoff(&up.tau, j)
    } else {
        up.tau
    }
}

/// One point: the update, its stress and info, or its status code.
pub(crate) fn update_one(
    mat: &Material,
    opts: &UpdateOptions,
    f: &Mat3,
    cp_inv: &mut Voigt,
) -> Result<(PointUpdate, f64), i32> {
    let up = update_point(mat, opts, f, cp_inv).map_err(|e| update_status(&e))?;
    Ok((up, tensor::det_mat(f)))
}

/// Updates `n` integration points to their end-of-step deformation
/// gradients.
///
/// * `params`: the material (validated on each call, every field, the
///   friction and true density included).
/// * `volume_fix`: 1 (recommended) or 0, the published return map
///   literally (see the header's first comment).
/// * `f`: in, n×9, F_{n+1} of each point, row-major (F11 F12 F13 F21 … F33):
///   the total deformation gradient from the configuration where the
///   point's state was initialised, not the step's increment.
/// * `cp_inv`: in/out, n×6, C_p⁻¹ of each point (Voigt xx yy zz yz xz xy;
///   start with `granbed_state_init`). A failed point keeps its state. An
///   all-zero state is not positive definite: `GRANBED_ERR_INVALID_STATE`
///   (only `granbed_vumat` reads zeros as the virgin state).
/// * `stress_measure`: `GRANBED_STRESS_KIRCHHOFF` or
///   `GRANBED_STRESS_CAUCHY`.
/// * `stress`: out, n×6, Pa, Voigt order (zero for a failed point).
/// * `info`: out, n records, or NULL.
/// * `point_status`: out, n status codes: `GRANBED_OK`, or the point's
///   `GRANBED_ERR_NON_FINITE`, `GRANBED_ERR_INVERTED` (det F ≤ 0),
///   `GRANBED_ERR_INVALID_STATE` or `GRANBED_ERR_NO_CONVERGENCE`.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_POINT_FAILED` if any point failed,
/// `GRANBED_ERR_INVALID_PARAMETER` (`params` fails
/// `granbed_material_check`), `GRANBED_ERR_INVALID_ARGUMENT` (`volume_fix`
/// not 0 or 1, an unknown `stress_measure`) or an argument error; on any
/// but the first two nothing is written.
///
/// # Safety
/// Every non-NULL pointer points to an array of the documented length;
/// output arrays do not overlap each other or the inputs.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn granbed_update_points(
    params: *const GranbedMaterialParams,
    volume_fix: i32,
    n: usize,
    f: *const f64,
    cp_inv: *mut f64,
    stress_measure: i32,
    stress: *mut f64,
    info: *mut GranbedPointInfo,
    point_status: *mut i32,
) -> i32 {
    status((|| {
        // SAFETY (all four): the caller's contract on lengths and aliasing.
        let mat = validated(unsafe { one(params) }?, None)?;
        let opts = options(volume_fix)?;
        if stress_measure != GRANBED_STRESS_KIRCHHOFF && stress_measure != GRANBED_STRESS_CAUCHY {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        }
        let f = unsafe { input(f, n, 9) }?;
        let cp = unsafe { output(cp_inv, n, 6) }?;
        let stress = unsafe { output(stress, n, 6) }?;
        let mut info = unsafe { optional_output(info, n, 1) }?;
        let codes = unsafe { output(point_status, n, 1) }?;
        let (f, _) = f.as_chunks::<9>();
        let (cp, _) = cp.as_chunks_mut::<6>();
        let (stress, _) = stress.as_chunks_mut::<6>();
        let mut failed = false;
        for (k, (((f, c), s), code)) in f
            .iter()
            .zip(cp.iter_mut())
            .zip(stress.iter_mut())
            .zip(codes.iter_mut())
            .enumerate()
        {
            let record = info.as_deref_mut().and_then(|i| i.get_mut(k));
            match update_one(&mat, &opts, &mat_row_major(f), c) {
                Ok((up, j)) => {
                    *s = stress_in(&up, j, stress_measure);
                    *code = GRANBED_OK;
                    if let Some(r) = record {
                        *r = point_info(&up, j);
                    }
                }
                Err(e) => {
                    *s = [0.0; 6];
                    *code = e;
                    failed = true;
                    if let Some(r) = record {
                        *r = GranbedPointInfo::default();
                    }
                }
            }
        }
        Ok(if failed {
            GRANBED_ERR_POINT_FAILED
        } else {
            GRANBED_OK
        })
    })())
}
