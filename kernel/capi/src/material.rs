//! Material parameters: presets, validation with a named error, and the
//! state initialisation.

use core::ffi::c_char;

use granbed_kernel::material::{GranuleType, Material, MaterialParams, ParamError};
use granbed_kernel::tensor::VOIGT_IDENTITY;

use crate::buffers::{one, one_mut, output, status};
use crate::status::{GRANBED_ERR_INVALID_ARGUMENT, GRANBED_ERR_INVALID_PARAMETER, GRANBED_OK};

/// Material parameters of a porous granule, SI units (the kernel's
/// `MaterialParams`, field for field; 8 doubles in this order, so a
/// Fortran `props(8)` array maps onto it).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedMaterialParams {
    /// Young's modulus E of the skeleton, Pa. Range: 1e-3 ≤ E ≤ 1e13.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν. Range: −1 < ν < 0.5.
    pub poisson_ratio: f64,
    /// Yield stress σ_y, Pa. Range: ≥ 1e-3 and ≥ 1e-6 E (+inf: purely
    /// elastic).
    pub yield_stress_pa: f64,
    /// Initial relative density η0. Range: η_c < η0 ≤ 1.
    pub eta0: f64,
    /// Yield-surface constant c_p. Range: 0 ≤ c_p ≤ 1e3.
    pub cp: f64,
    /// Critical relative density η_c. Range: 0 ≤ η_c < 1.
    pub eta_c: f64,
    /// True (solid) density, kg/m³. Range: 1e-3 ≤ ρ ≤ 1e5.
    pub true_density_kg_m3: f64,
    /// Coulomb friction coefficient. Range: 0 ≤ μ ≤ 10.
    pub friction: f64,
}

/// Builds a `$to` from `$from` with the same eight material fields (the two
/// structs mirror each other; the list is written once).
macro_rules! material_fields {
    ($from:expr => $to:ident) => {{
        let p = $from;
        $to {
            youngs_modulus_pa: p.youngs_modulus_pa,
            poisson_ratio: p.poisson_ratio,
            yield_stress_pa: p.yield_stress_pa,
            eta0: p.eta0,
            cp: p.cp,
            eta_c: p.eta_c,
            true_density_kg_m3: p.true_density_kg_m3,
            friction: p.friction,
        }
    }};
}

impl From<&GranbedMaterialParams> for MaterialParams {
    fn from(p: &GranbedMaterialParams) -> Self {
        material_fields!(p => MaterialParams)
    }
}

impl From<MaterialParams> for GranbedMaterialParams {
    fn from(p: MaterialParams) -> Self {
        material_fields!(p => GranbedMaterialParams)
    }
}

/// Bytes of `GranbedParamError::field`, NUL included.
pub const GRANBED_FIELD_LEN: usize = 40;
/// Bytes of `GranbedParamError::allowed`, NUL included.
pub const GRANBED_ALLOWED_LEN: usize = 80;

/// Which material parameter was rejected, its value and the allowed range.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GranbedParamError {
    /// Field name as in `GranbedMaterialParams`, NUL-terminated.
    pub field: [c_char; GRANBED_FIELD_LEN],
    /// The allowed range, human readable, NUL-terminated.
    pub allowed: [c_char; GRANBED_ALLOWED_LEN],
    /// The rejected value.
    pub value: f64,
}

/// Copies `text` into `dst` as a NUL-terminated C string (truncated to fit).
fn copy_c_string(dst: &mut [c_char], text: &str) {
    let room = dst.len().saturating_sub(1);
    let mut end = 0;
    for (d, b) in dst.iter_mut().zip(text.bytes().take(room)) {
        *d = b as c_char;
        end += 1;
    }
    if let Some(d) = dst.get_mut(end) {
        *d = 0;
    }
}

/// The validated kernel material of `params`, the rejection written to
/// `error` when it is not NULL.
pub(crate) fn validated(
    params: &GranbedMaterialParams,
    error: Option<&mut GranbedParamError>,
) -> Result<Material, i32> {
    MaterialParams::from(params)
        .validate()
        .map_err(|e: ParamError| {
            if let Some(out) = error {
                copy_c_string(&mut out.field, e.field);
                copy_c_string(&mut out.allowed, e.allowed);
                out.value = e.value;
            }
            GRANBED_ERR_INVALID_PARAMETER
        })
}

/// Writes the parameters of the standard granule type `name` ("A1" … "C3",
/// case-insensitive, NUL-terminated) to `out`.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_NULL_POINTER`, or
/// `GRANBED_ERR_INVALID_ARGUMENT` for an unknown name.
///
/// # Safety
/// `name` is NULL or a NUL-terminated string; `out` is NULL or points to a
/// writable `GranbedMaterialParams`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_material_preset(
    name: *const c_char,
    out: *mut GranbedMaterialParams,
) -> i32 {
    status((|| {
        if name.is_null() {
            return Err(crate::status::GRANBED_ERR_NULL_POINTER);
        }
        // A type name has two characters; read at most four bytes.
        let mut text = [0u8; 4];
        let mut len = 0;
        for slot in text.iter_mut() {
            // SAFETY: the string is NUL-terminated and we stop at the NUL.
            let b = unsafe { *name.add(len) } as u8;
            if b == 0 {
                break;
            }
            *slot = b;
            len += 1;
        }
        let name = text
            .get(..len)
            .and_then(|t| core::str::from_utf8(t).ok())
            .and_then(|t| t.parse::<GranuleType>().ok())
            .ok_or(GRANBED_ERR_INVALID_ARGUMENT)?;
        // SAFETY: the caller's contract.
        let out = unsafe { one_mut(out) }?;
        *out = name.params().into();
        Ok(GRANBED_OK)
    })())
}

/// Checks every field of `params` against its range (NaN always fails).
/// On failure returns `GRANBED_ERR_INVALID_PARAMETER` and, if `error` is
/// not NULL, writes the first rejected field, its value and the allowed
/// range there; `GRANBED_ERR_NULL_POINTER` if `params` is NULL.
///
/// # Safety
/// `params` is NULL or points to a `GranbedMaterialParams`; `error` is
/// NULL or points to a writable `GranbedParamError`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_material_check(
    params: *const GranbedMaterialParams,
    error: *mut GranbedParamError,
) -> i32 {
    status((|| {
        // SAFETY: the caller's contract.
        let params = unsafe { one(params) }?;
        // SAFETY: the caller's contract.
        let error = unsafe { error.as_mut() };
        validated(params, error).map(|_| GRANBED_OK)
    })())
}

/// The constants derived from validated material parameters, SI units:
/// what an explicit host needs beside the stresses, e.g. a stable time
/// step Δt ≤ h / `wave_speed_m_s` for an element of size h.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedMaterialDerived {
    /// Lamé's first parameter λ = Eν/((1+ν)(1−2ν)), Pa.
    pub lambda_pa: f64,
    /// Shear modulus μ = E/(2(1+ν)), Pa.
    pub mu_pa: f64,
    /// Bulk modulus K = λ + 2μ/3, Pa.
    pub bulk_pa: f64,
    /// P-wave modulus λ + 2μ, Pa (the hourglass stiffness is κ times it).
    pub p_wave_pa: f64,
    /// Reference density ρ0 = η0 ρ_true of the porous granule, kg/m³.
    pub density0_kg_m3: f64,
    /// Dilatational wave speed c_d = √((λ + 2μ)/ρ0), m/s.
    pub wave_speed_m_s: f64,
}

/// Writes the constants derived from `params` (checked as
/// `granbed_material_check` does) to `out`.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_NULL_POINTER`, or
/// `GRANBED_ERR_INVALID_PARAMETER` (the rejection written to `error` when
/// it is not NULL; `out` is then not written).
///
/// # Safety
/// `params` is NULL or points to a `GranbedMaterialParams`; `out` is NULL
/// or points to a writable `GranbedMaterialDerived`; `error` is NULL or
/// points to a writable `GranbedParamError`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_material_derived(
    params: *const GranbedMaterialParams,
    out: *mut GranbedMaterialDerived,
    error: *mut GranbedParamError,
) -> i32 {
    status((|| {
        // SAFETY (all three): the caller's contract.
        let params = unsafe { one(params) }?;
        let out = unsafe { one_mut(out) }?;
        let error = unsafe { error.as_mut() };
        let m = validated(params, error)?;
        *out = GranbedMaterialDerived {
            lambda_pa: m.lambda,
            mu_pa: m.mu,
            bulk_pa: m.bulk,
            p_wave_pa: m.p_wave_modulus(),
            density0_kg_m3: m.density0,
            wave_speed_m_s: granbed_kernel::math::sqrt(m.p_wave_modulus() / m.density0),
        };
        Ok(GRANBED_OK)
    })())
}

/// Writes the initial plastic state C_p⁻¹ = identity of `n` points to
/// `cp_inv` (n×6, Voigt xx yy zz yz xz xy).
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_NULL_POINTER` (`cp_inv` NULL with
/// n > 0) or `GRANBED_ERR_SIZE` (6n doubles overflow the address space).
///
/// # Safety
/// `cp_inv` points to 6n writable doubles (may be NULL if n = 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_state_init(n: usize, cp_inv: *mut f64) -> i32 {
    status((|| {
        // SAFETY: the caller's contract.
        let cp = unsafe { output(cp_inv, n, 6) }?;
        for point in cp.chunks_exact_mut(6) {
            point.copy_from_slice(&VOIGT_IDENTITY);
        }
        Ok(GRANBED_OK)
    })())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_field_name_is_truncated_and_terminated() {
        let mut dst = [1 as c_char; 4];
        copy_c_string(&mut dst, "abcdef");
        assert_eq!(dst, [b'a' as c_char, b'b' as c_char, b'c' as c_char, 0]);
    }
}
