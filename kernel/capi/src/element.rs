//! The one-point hex element for a batch of elements: reference data once,
//! then nodal forces per step.

use granbed_kernel::constitutive::update::check_state;
use granbed_kernel::element::force::hex_forces;
use granbed_kernel::element::reference::{HexReference, hex_reference};

use crate::buffers::{input, one, optional_output, output, status};
use crate::material::{GranbedMaterialParams, validated};
use crate::status::{
    GRANBED_ERR_DEGENERATE, GRANBED_ERR_INVALID_ARGUMENT, GRANBED_ERR_NON_FINITE,
    GRANBED_ERR_POINT_FAILED, GRANBED_OK, update_status,
};
use crate::update::{GranbedPointInfo, options};

/// Doubles per element in the reference array of `granbed_hex_reference`,
/// in this order: V0 (m³, 1), B0, the mean gradients (1/V0)∫∇N_I dV (1/m, 24 as
/// `[node][xyz]`), γ0, the hourglass shape vectors (dimensionless, 32 as
/// `[mode][node]`), the hourglass geometry factor V0 Σ|B0_I|²/3 (m, 1),
/// the lumped node volumes (m³, 8 as `[node]`).
pub const GRANBED_HEX_REFERENCE_LEN: usize = 66;

/// Default hourglass coefficient κ of the kernel.
pub const GRANBED_DEFAULT_HOURGLASS_KAPPA: f64 = 0.05;
const _: () = assert!(
    GRANBED_DEFAULT_HOURGLASS_KAPPA == granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA
);

fn encode(r: &HexReference, out: &mut [f64; GRANBED_HEX_REFERENCE_LEN]) {
    let values = core::iter::once(r.volume)
        .chain(r.b0.iter().flatten().copied())
        .chain(r.gamma0.iter().flatten().copied())
        .chain(core::iter::once(r.hourglass_geometry))
        .chain(r.node_volume.iter().copied());
    for (o, v) in out.iter_mut().zip(values) {
        *o = v;
    }
}

/// True if `v` can be a reference record of `granbed_hex_reference`:
/// the kernel's [`HexReference::usable`] (every entry finite, V0 > 0,
/// every node volume > 0, a hourglass geometry factor > 0 whose
/// stiffening stays finite; B0 and γ0 only finite: their ranges depend on
/// the shape).
fn reference_ok(v: &[f64; GRANBED_HEX_REFERENCE_LEN]) -> bool {
    decode(v).usable()
}

fn decode(v: &[f64; GRANBED_HEX_REFERENCE_LEN]) -> HexReference {
    let mut it = v.iter().copied();
    let mut next = || it.next().unwrap_or(0.0);
    let volume = next();
    let b0 = core::array::from_fn(|_| core::array::from_fn(|_| next()));
    let gamma0 = core::array::from_fn(|_| core::array::from_fn(|_| next()));
    let hourglass_geometry = next();
    let node_volume = core::array::from_fn(|_| next());
    HexReference {
        volume,
        b0,
        gamma0,
        hourglass_geometry,
        node_volume,
    }
}

/// Node coordinates of one hex, `[node][xyz]`, from 24 doubles.
fn coords(x: &[f64; 24]) -> [[f64; 3]; 8] {
    core::array::from_fn(|i| core::array::from_fn(|a| x.get(3 * i + a).copied().unwrap_or(0.0)))
}

/// Computes the reference data of `n` hexes.
///
/// * `x_ref`: in, n×24, reference node coordinates (m), node-major
///   `[element][node][xyz]`, nodes in the usual trilinear order (0 at
///   (−,−,−), 1 (+,−,−), 2 (+,+,−), 3 (−,+,−), then 4–7 the same at +ζ).
/// * `reference`: out, n×`GRANBED_HEX_REFERENCE_LEN`.
/// * `element_status`: out, n codes (`GRANBED_ERR_DEGENERATE` for a hex
///   with a non-positive Gauss-point Jacobian, `GRANBED_ERR_NON_FINITE`
///   for a non-finite coordinate or a record that would overflow, e.g. a
///   hex so large that its volume does; a failed hex's record is zeroed).
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_POINT_FAILED` (some hex failed: see
/// its `element_status`) or an argument error.
///
/// # Safety
/// Pointers to arrays of the documented lengths, outputs not overlapping.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_hex_reference(
    n: usize,
    x_ref: *const f64,
    reference: *mut f64,
    element_status: *mut i32,
) -> i32 {
    status((|| {
        // SAFETY (all three): the caller's contract.
        let x = unsafe { input(x_ref, n, 24) }?;
        let out = unsafe { output(reference, n, GRANBED_HEX_REFERENCE_LEN) }?;
        let codes = unsafe { output(element_status, n, 1) }?;
        let (x, _) = x.as_chunks::<24>();
        let (out, _) = out.as_chunks_mut::<GRANBED_HEX_REFERENCE_LEN>();
        let mut failed = false;
        for ((x, o), code) in x.iter().zip(out.iter_mut()).zip(codes.iter_mut()) {
            *code = if !x.iter().all(|v| v.is_finite()) {
                GRANBED_ERR_NON_FINITE
            } else {
                match hex_reference(&coords(x)) {
                    Some(r) if r.usable() => {
                        encode(&r, o);
                        GRANBED_OK
                    }
                    // Finite coordinates whose volume or geometry factor
                    // overflows (a side of 1e103 m): no record the forces
                    // could use.
                    Some(_) => GRANBED_ERR_NON_FINITE,
                    None => GRANBED_ERR_DEGENERATE,
                }
            };
            if *code != GRANBED_OK {
                *o = [0.0; GRANBED_HEX_REFERENCE_LEN];
                failed = true;
            }
        }
        Ok(if failed {
            GRANBED_ERR_POINT_FAILED
        } else {
            GRANBED_OK
        })
    })())
}

/// Internal plus hourglass nodal forces of `n` one-point hexes
/// (physics.md §2.1–§2.2): F̄ = Σ x_I ⊗ B0_I, the constitutive update,
/// f_I = V0 τ F̄⁻ᵀ B0_I plus the Flanagan–Belytschko hourglass force with
/// k = κ (λ + 2μ) × the geometry factor. The nodal equation of motion
/// subtracts `f` (m a = f_ext − f).
///
/// * `kappa`: hourglass coefficient κ, 0 ≤ κ ≤ 1
///   (`GRANBED_DEFAULT_HOURGLASS_KAPPA` = 0.05).
/// * `reference`: in, n×66 from `granbed_hex_reference`. An element whose
///   record has a non-finite entry, V0 ≤ 0, a hourglass geometry factor
///   ≤ 0 (or below about 1e-153 m, where its stiffening overflows) or a
///   node volume ≤ 0 fails with `GRANBED_ERR_INVALID_ARGUMENT` (a corrupt
///   record: what `granbed_hex_reference` writes with `GRANBED_OK`
///   passes).
/// * `x`: in, n×24, current node coordinates, `[element][node][xyz]`, m.
/// * `cp_inv`: in/out, n×6, the element's C_p⁻¹ (kept on failure).
/// * `f`: out, n×24, nodal forces `[element][node][xyz]`, N (zero on
///   failure).
/// * `tau`: out, n×6 Kirchhoff stress, Pa, or NULL.
/// * `info`: out, n records, or NULL.
/// * `element_status`: out, n codes (`GRANBED_ERR_INVALID_ARGUMENT` for a
///   corrupt reference record, else the constitutive update's code, as
///   `granbed_update_points` writes them).
///
/// Only det F̄ of the element's mean deformation gradient is checked
/// (`GRANBED_ERR_INVERTED` when ≤ 0): a tangled hex whose Jacobian changes
/// sign at a corner while det F̄ stays positive passes. A host whose mesh
/// can tangle checks its corner Jacobians itself.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_POINT_FAILED`,
/// `GRANBED_ERR_INVALID_PARAMETER` (`params` fails
/// `granbed_material_check`), `GRANBED_ERR_INVALID_ARGUMENT` (`volume_fix`
/// not 0 or 1, κ outside [0, 1]) or an argument error.
///
/// # Safety
/// Pointers to arrays of the documented lengths, outputs not overlapping.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn granbed_hex_forces(
    params: *const GranbedMaterialParams,
    volume_fix: i32,
    kappa: f64,
    n: usize,
    reference: *const f64,
    x: *const f64,
    cp_inv: *mut f64,
    f: *mut f64,
    tau: *mut f64,
    info: *mut GranbedPointInfo,
    element_status: *mut i32,
) -> i32 {
    status((|| {
        // SAFETY (all): the caller's contract on lengths and aliasing.
        let mat = validated(unsafe { one(params) }?, None)?;
        let opts = options(volume_fix)?;
        if !(0.0..=1.0).contains(&kappa) {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        }
        let reference = unsafe { input(reference, n, GRANBED_HEX_REFERENCE_LEN) }?;
        let x = unsafe { input(x, n, 24) }?;
        let cp = unsafe { output(cp_inv, n, 6) }?;
        let f = unsafe { output(f, n, 24) }?;
        let mut tau = unsafe { optional_output(tau, n, 6) }?;
        let mut info = unsafe { optional_output(info, n, 1) }?;
        let codes = unsafe { output(element_status, n, 1) }?;
        let (reference, _) = reference.as_chunks::<GRANBED_HEX_REFERENCE_LEN>();
        let (x, _) = x.as_chunks::<24>();
        let (cp, _) = cp.as_chunks_mut::<6>();
        let (f, _) = f.as_chunks_mut::<24>();
        let mut failed = false;
        for (k, ((((r, x), c), fe), code)) in reference
            .iter()
            .zip(x.iter())
            .zip(cp.iter_mut())
            .zip(f.iter_mut())
            .zip(codes.iter_mut())
            .enumerate()
        {
            let t = tau.as_deref_mut().and_then(|t| t.get_mut(6 * k..6 * k + 6));
            let record = info.as_deref_mut().and_then(|i| i.get_mut(k));
            let result = if reference_ok(r) {
                // The element tests only det C_p⁻¹; a caller's state is
                // checked in full first.
                check_state(c)
                    .and_then(|()| hex_forces(&mat, &opts, kappa, &decode(r), &coords(x), c))
                    .map_err(|e| update_status(&e))
            } else {
                Err(GRANBED_ERR_INVALID_ARGUMENT)
            };
            match result {
                Ok(out) => {
                    for (dst, v) in fe.iter_mut().zip(out.f.iter().flatten()) {
                        *dst = *v;
                    }
                    if let Some(t) = t {
                        t.copy_from_slice(&out.tau);
                    }
                    if let Some(rec) = record {
                        *rec = GranbedPointInfo {
                            j: out.j,
                            eta: out.info.eta,
                            dissipation_density: out.plastic_dissipation / r[0],
                            hourglass_energy: out.hourglass_energy,
                            plastic: i32::from(out.info.plastic),
                            iterations: i32::try_from(out.info.iterations).unwrap_or(i32::MAX),
                        };
                    }
                    *code = GRANBED_OK;
                }
                Err(e) => {
                    *fe = [0.0; 24];
                    if let Some(t) = t {
                        t.fill(0.0);
                    }
                    if let Some(rec) = record {
                        *rec = GranbedPointInfo::default();
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

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE: [f64; 24] = [
        0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., 0., 0., 1., 1., 0., 1., 1., 1., 1., 0., 1.,
        1.,
    ];

    #[test]
    fn a_corrupt_reference_record_fails_its_element() {
        let mut good = [0.0; GRANBED_HEX_REFERENCE_LEN];
        let mut st = [0i32; 1];
        // SAFETY (both calls): arrays of the documented lengths.
        let code =
            unsafe { granbed_hex_reference(1, CUBE.as_ptr(), good.as_mut_ptr(), st.as_mut_ptr()) };
        assert_eq!(code, GRANBED_OK);
        assert!(reference_ok(&good));
        let mut p = GranbedMaterialParams::default();
        // SAFETY: valid name and output.
        assert_eq!(
            unsafe { crate::granbed_material_preset(c"B2".as_ptr(), &mut p) },
            GRANBED_OK
        );
        let mut x = CUBE;
        x[18] += 0.01;
        // V0, the hourglass factor (57), a γ0 entry (30), a node volume (60).
        for (at, v) in [
            (0, f64::NAN),
            (0, -1.0),
            (57, f64::NAN),
            (57, -1.0),
            // A factor of 0, or one whose stiffening 1/(32 (0.1 hg)²)
            // overflows: the forces were NaN with GRANBED_OK.
            (57, 0.0),
            (57, 1e-160),
            (30, f64::INFINITY),
            (60, 0.0),
        ] {
            let mut r = good;
            r[at] = v;
            let mut cp = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
            let mut f = [1.0; 24];
            let code = unsafe {
                granbed_hex_forces(
                    &p,
                    1,
                    0.05,
                    1,
                    r.as_ptr(),
                    x.as_ptr(),
                    cp.as_mut_ptr(),
                    f.as_mut_ptr(),
                    core::ptr::null_mut(),
                    core::ptr::null_mut(),
                    st.as_mut_ptr(),
                )
            };
            assert_eq!(
                (code, st[0]),
                (GRANBED_ERR_POINT_FAILED, GRANBED_ERR_INVALID_ARGUMENT),
                "[{at}] = {v}"
            );
            assert_eq!(f, [0.0; 24]);
        }
    }

    /// A hex of finite coordinates whose volume overflows gets
    /// `GRANBED_ERR_NON_FINITE` and a zeroed record, not `GRANBED_OK` with
    /// a record `granbed_hex_forces` refuses.
    #[test]
    fn a_hex_whose_volume_overflows_is_non_finite() {
        let huge = CUBE.map(|c| c * 1e103);
        let mut r = [1.0; GRANBED_HEX_REFERENCE_LEN];
        let mut st = [0i32; 1];
        // SAFETY: arrays of the documented lengths.
        let code =
            unsafe { granbed_hex_reference(1, huge.as_ptr(), r.as_mut_ptr(), st.as_mut_ptr()) };
        assert_eq!(
            (code, st[0]),
            (GRANBED_ERR_POINT_FAILED, GRANBED_ERR_NON_FINITE)
        );
        assert_eq!(r, [0.0; GRANBED_HEX_REFERENCE_LEN]);
    }
}
