//! A block material routine in the calling convention of explicit FE
//! user materials (Abaqus/Explicit VUMAT style): a block of `nblock`
//! points, every array stored component-major as Fortran declares it,
//! `a(nblock, ncomp)`, so component k of point i is `a[i + k·nblock]`.

use granbed_kernel::tensor::{Mat3, VOIGT_IDENTITY, Voigt};

use crate::buffers::{input, output, status};
use crate::material::{GranbedMaterialParams, validated};
use crate::status::{GRANBED_ERR_INVALID_ARGUMENT, GRANBED_ERR_POINT_FAILED, GRANBED_OK};
use crate::update::{GRANBED_STRESS_CAUCHY, options, stress_in, update_one};

/// Number of state variables the block routine uses (more are allowed and
/// copied through): C_p⁻¹ (6, in the order 11 22 33 12 23 31), η, and the
/// plastic flag of the last step (0/1).
pub const GRANBED_VUMAT_NSTATEV: usize = 8;
/// Number of material properties: the 8 fields of `GranbedMaterialParams`
/// in order.
pub const GRANBED_VUMAT_NPROPS: usize = 8;

/// Kernel Voigt index (xx yy zz yz xz xy) of each VUMAT component
/// 11 22 33 12 23 31.
const VUMAT_ORDER: [usize; 6] = [0, 1, 2, 5, 3, 4];

/// `a(i, k)` of a column-major `a(nblock, ·)`, 0 if out of range.
fn at(a: &[f64], nblock: usize, i: usize, k: usize) -> f64 {
    k.checked_mul(nblock)
        .and_then(|o| o.checked_add(i))
        .and_then(|o| a.get(o))
        .copied()
        .unwrap_or(0.0)
}

/// Sets `a(i, k)` if in range.
fn set(a: &mut [f64], nblock: usize, i: usize, k: usize, v: f64) {
    if let Some(slot) = k
        .checked_mul(nblock)
        .and_then(|o| o.checked_add(i))
        .and_then(|o| a.get_mut(o))
    {
        *slot = v;
    }
}

/// Updates a block of `nblock` points (VUMAT-style arrays, column-major):
///
/// * `props(nprops)`: the material, `GRANBED_VUMAT_NPROPS` = 8 values in
///   the field order of `GranbedMaterialParams` (E, ν, σ_y, η0, c_p, η_c,
///   ρ_true, μ); `nprops` ≥ 8.
/// * `defgrad_new(nblock, 9)`: F at the end of the step in the VUMAT
///   component order F11 F22 F33 F12 F23 F31 F21 F32 F13.
/// * `state_old(nblock, nstatev)`, `state_new(nblock, nstatev)`: the state
///   variables, `nstatev` ≥ 6 (see `GRANBED_VUMAT_NSTATEV`). An all-zero
///   C_p⁻¹ (the zero initial state variables FE codes supply) is read as
///   the virgin state, the identity. Extra variables are copied through.
/// * `stress_new(nblock, 6)`: out, Cauchy stress σ, Pa, order 11 22 33 12
///   23 31, **in the global (spatial) basis**. Abaqus/Explicit expects the
///   co-rotational stress RᵀσR (F = RU): a VUMAT wrapper must rotate it.
/// * `point_status(nblock)`: out, one code per point; a failed point gets
///   zero stress and `state_new` = `state_old`.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_POINT_FAILED`,
/// `GRANBED_ERR_INVALID_PARAMETER` (`props` fails `granbed_material_check`),
/// `GRANBED_ERR_INVALID_ARGUMENT` (`nprops` < 8 or `nstatev` < 6) or an
/// argument error.
///
/// # Safety
/// Every pointer points to an array of the documented size; outputs do not
/// overlap inputs (`state_new` may not be `state_old`).
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn granbed_vumat(
    nblock: usize,
    nstatev: usize,
    nprops: usize,
    props: *const f64,
    defgrad_new: *const f64,
    state_old: *const f64,
    state_new: *mut f64,
    stress_new: *mut f64,
    point_status: *mut i32,
) -> i32 {
    status((|| {
        if nprops < GRANBED_VUMAT_NPROPS || nstatev < 6 {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        }
        // SAFETY (all): the caller's contract on sizes and aliasing.
        let props = unsafe { input(props, nprops, 1) }?;
        let [e, nu, sy, eta0, cp, eta_c, rho, mu, ..] = props else {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        };
        let params = GranbedMaterialParams {
            youngs_modulus_pa: *e,
            poisson_ratio: *nu,
            yield_stress_pa: *sy,
            eta0: *eta0,
            cp: *cp,
            eta_c: *eta_c,
            true_density_kg_m3: *rho,
            friction: *mu,
        };
        let mat = validated(&params, None)?;
        let opts = options(1)?;
        let f = unsafe { input(defgrad_new, nblock, 9) }?;
        let old = unsafe { input(state_old, nblock, nstatev) }?;
        let new = unsafe { output(state_new, nblock, nstatev) }?;
        let stress = unsafe { output(stress_new, nblock, 6) }?;
        let codes = unsafe { output(point_status, nblock, 1) }?;
        new.copy_from_slice(old);
        let mut failed = false;
        for (i, code) in codes.iter_mut().enumerate() {
            // F11 F22 F33 F12 F23 F31 F21 F32 F13.
            let g = |k| at(f, nblock, i, k);
            let fm = Mat3::new(g(0), g(3), g(8), g(6), g(1), g(4), g(5), g(7), g(2));
            let mut c: Voigt = [0.0; 6];
            for (k, &v) in VUMAT_ORDER.iter().enumerate() {
                if let Some(slot) = c.get_mut(v) {
                    *slot = at(old, nblock, i, k);
                }
            }
            if c.iter().all(|&v| v == 0.0) {
                c = VOIGT_IDENTITY;
            }
            match update_one(&mat, &opts, &fm, &mut c) {
                Ok((up, j)) => {
                    let s = stress_in(&up, j, GRANBED_STRESS_CAUCHY);
                    for (k, &v) in VUMAT_ORDER.iter().enumerate() {
                        set(stress, nblock, i, k, s.get(v).copied().unwrap_or(0.0));
                        set(new, nblock, i, k, c.get(v).copied().unwrap_or(0.0));
                    }
                    set(new, nblock, i, 6, up.info.eta);
                    set(new, nblock, i, 7, f64::from(u8::from(up.info.plastic)));
                    *code = GRANBED_OK;
                }
                Err(e) => {
                    for k in 0..6 {
                        set(stress, nblock, i, k, 0.0);
                    }
                    *code = e;
                    failed = true;
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
