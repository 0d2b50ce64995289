//! Measures of a compressed granule bed (physics.md §7 items 1–6): applied
//! pressure and strain, the Kawakita fit (and the Heckel fit, which §7 does
//! not name), per-granule geometry (envelope
//! volume, surface area, relative density, Heywood coefficient) and the bed
//! aggregates (coordination number, mean relative density).
//!
//! Every routine works on caller-provided slices, never panics and reports
//! unusable input as `None` or a [`BedError`]; sums run in slice order.

use core::f64::consts::PI;
use core::fmt;

use crate::Real;
use crate::analysis::fit::linear_fit;
use crate::mesh::surface::area_and_volume;

/// Lower strain bound of the Kawakita fit, physics.md §7 item 3 (paper:
/// "C ≳ 0.25").
pub const KAWAKITA_MIN_STRAIN: Real = 0.25;

/// Fixed diameter of the second Heywood coefficient, m (the nominal granule
/// diameter 1 mm, physics.md §7 item 6).
pub const HEYWOOD_FIXED_DIAMETER: Real = 1e-3;

/// Invalid input to a bed measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BedError {
    /// Two per-granule buffers differ in length.
    BufferLength {
        /// The buffer with the wrong length.
        buffer: &'static str,
        /// Entries expected (the length of the first buffer).
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// A surface quad names a node beyond the position buffer.
    NodeOutOfRange {
        /// Quad index.
        quad: usize,
        /// The offending node id.
        node: u32,
    },
    /// No surface quads, or no granules.
    Empty {
        /// Which buffer is empty.
        buffer: &'static str,
    },
    /// A scalar parameter is not finite and positive.
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: Real,
    },
    /// The surface encloses no positive finite volume (open, inverted or
    /// non-finite surface).
    Degenerate {
        /// Surface area, m².
        area_m2: Real,
        /// Enclosed volume, m³.
        volume_m3: Real,
    },
}

impl fmt::Display for BedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferLength {
                buffer,
                expected,
                got,
            } => write!(
                f,
                "bed buffer `{buffer}` has {got} entries, expected {expected}"
            ),
            Self::NodeOutOfRange { quad, node } => {
                write!(
                    f,
                    "surface quad {quad} names node {node} beyond the positions"
                )
            }
            Self::Empty { buffer } => write!(f, "bed buffer `{buffer}` is empty"),
            Self::InvalidParameter { name, value } => {
                write!(f, "`{name}` = {value} must be finite and positive")
            }
            Self::Degenerate { area_m2, volume_m3 } => write!(
                f,
                "surface is degenerate: area {area_m2} m², enclosed volume {volume_m3} m³"
            ),
        }
    }
}

impl core::error::Error for BedError {}

fn positive(name: &'static str, value: Real) -> Result<Real, BedError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(BedError::InvalidParameter { name, value })
    }
}

// ---------------------------------------------------------------------------
// §7 items 1–2: pressure and strain

/// Applied pressure P = F/(πR_d²), Pa, from the (interval-averaged) punch
/// force `force_n` (N) and the die radius `die_radius_m` (m). `None` unless
/// the force is finite and the radius finite and positive.
pub fn applied_pressure(force_n: Real, die_radius_m: Real) -> Option<Real> {
    let ok = force_n.is_finite() && die_radius_m.is_finite() && die_radius_m > 0.0;
    ok.then(|| force_n / (PI * die_radius_m * die_radius_m))
}

/// Axial strain (degree of volume reduction) C = (H0 − H)/H0, dimensionless,
/// from the initial bed height `h0_m` and the current height `h_m` (m).
/// `None` unless H is finite and H0 finite and positive.
pub fn axial_strain(h0_m: Real, h_m: Real) -> Option<Real> {
    let ok = h_m.is_finite() && h0_m.is_finite() && h0_m > 0.0;
    ok.then(|| (h0_m - h_m) / h0_m)
}

// ---------------------------------------------------------------------------
// §7 item 3: Kawakita

/// Kawakita parameters of a compaction curve, P/C = P/a + 1/(ab).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KawakitaFit {
    /// a = 1/slope: the limiting strain, dimensionless.
    pub a: Real,
    /// 1/b = intercept/slope, Pa (the pressure at which C = a/2).
    pub inv_b_pa: Real,
    /// Coefficient of determination R² of the line P/C against P.
    pub r_squared: Real,
    /// Points used (those with C ≥ the threshold).
    pub points: usize,
}

/// Kawakita fit (physics.md §7 item 3): ordinary least squares of y = P/C
/// (Pa) against x = P (Pa) over the samples `(P [Pa], C)` with
/// C ≥ `min_strain` (usually [`KAWAKITA_MIN_STRAIN`]), C > 0 and both finite;
/// then a = 1/slope and 1/b = intercept/slope. The line is
/// [`linear_fit`]; the iterator is cloned for its two passes.
///
/// `None` with fewer than two usable points, when all usable P are equal, or
/// when the slope is zero or a or 1/b would not be finite.
pub fn kawakita_fit<I>(samples: I, min_strain: Real) -> Option<KawakitaFit>
where
    I: Iterator<Item = (Real, Real)> + Clone,
{
    let line = linear_fit(
        samples
            .filter(move |&(p, c)| c >= min_strain && c > 0.0 && c.is_finite() && p.is_finite())
            .map(|(p, c)| (p, p / c)),
    )?;
    let a = 1.0 / line.slope;
    let inv_b_pa = line.intercept / line.slope;
    if line.slope == 0.0 || !a.is_finite() || !inv_b_pa.is_finite() {
        return None;
    }
    Some(KawakitaFit {
        a,
        inv_b_pa,
        r_squared: line.r_squared,
        points: line.points,
    })
}

/// [`kawakita_fit`] over two parallel slices: pressures (Pa) and strains.
/// `Err` if the lengths differ, `Ok(None)` if the data allow no fit.
pub fn kawakita_fit_slices(
    pressures_pa: &[Real],
    strains: &[Real],
    min_strain: Real,
) -> Result<Option<KawakitaFit>, BedError> {
    if strains.len() != pressures_pa.len() {
        return Err(BedError::BufferLength {
            buffer: "strains",
            expected: pressures_pa.len(),
            got: strains.len(),
        });
    }
    Ok(kawakita_fit(
        pressures_pa.iter().copied().zip(strains.iter().copied()),
        min_strain,
    ))
}

// ---------------------------------------------------------------------------
// Heckel (not in physics.md §7: the pharmaceutical scientist's other law)

/// Heckel parameters of a compaction curve, ln(1/(1 − D)) = K·P + A, D the
/// compact's solid fraction (relative density) at punch pressure P.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeckelFit {
    /// K = slope, 1/Pa.
    pub k_per_pa: Real,
    /// A = intercept, dimensionless.
    pub a: Real,
    /// The mean yield pressure P_y = 1/K, Pa.
    pub yield_pressure_pa: Real,
    /// D_A = 1 − exp(−A): the solid fraction the line gives at P = 0.
    pub d_a: Real,
    /// Coefficient of determination R² of the line.
    pub r_squared: Real,
    /// Points used.
    pub points: usize,
}

/// Heckel fit: ordinary least squares of y = ln(1/(1 − D)) against x = P
/// (Pa) over the samples `(P [Pa], D)` with P finite and 0 < D < 1 (beyond
/// D = 1 the law is undefined); then P_y = 1/K and D_A = 1 − e^(−A). Which
/// rows form the law's linear stretch is the caller's choice (the CLI takes
/// those past a strain, as for [`kawakita_fit`]). The line is
/// [`linear_fit`]; the iterator is cloned for its two passes.
///
/// `None` with fewer than two usable points, when all usable P are equal, or
/// when K is not positive (ln(1/(1 − D)) does not rise with P over the rows:
/// the pressure fell while the bed densified, say, as in a rearranging bed
/// of few granules) or P_y would not be finite.
pub fn heckel_fit<I>(samples: I) -> Option<HeckelFit>
where
    I: Iterator<Item = (Real, Real)> + Clone,
{
    let line = linear_fit(
        samples
            .filter(|&(p, d)| heckel_usable(p, d))
            .map(|(p, d)| (p, -crate::math::ln_1p(-d))),
    )?;
    let yield_pressure_pa = 1.0 / line.slope;
    if !(line.slope > 0.0 && yield_pressure_pa.is_finite()) {
        return None;
    }
    Some(HeckelFit {
        k_per_pa: line.slope,
        a: line.intercept,
        yield_pressure_pa,
        d_a: -crate::math::exp_m1(-line.intercept),
        r_squared: line.r_squared,
        points: line.points,
    })
}

/// Whether a row (P in Pa, D) enters the Heckel fit: P finite and
/// 0 < D < 1, where ln(1/(1 − D)) is defined.
pub fn heckel_usable(p: Real, d: Real) -> bool {
    p.is_finite() && d > 0.0 && d < 1.0
}

/// [`heckel_fit`] over two parallel slices: pressures (Pa) and solid
/// fractions. `Err` if the lengths differ, `Ok(None)` if the data allow no
/// fit.
pub fn heckel_fit_slices(
    pressures_pa: &[Real],
    solid_fractions: &[Real],
) -> Result<Option<HeckelFit>, BedError> {
    if solid_fractions.len() != pressures_pa.len() {
        return Err(BedError::BufferLength {
            buffer: "solid_fractions",
            expected: pressures_pa.len(),
            got: solid_fractions.len(),
        });
    }
    Ok(heckel_fit(
        pressures_pa
            .iter()
            .copied()
            .zip(solid_fractions.iter().copied()),
    ))
}

// ---------------------------------------------------------------------------
// §7 items 5–6: one granule

/// Relative density of a granule η_g = η0·V0/V: the solid volume η0·V0 over
/// the current envelope volume V (V0, V in m³). `None` unless all three are
/// finite and positive.
pub fn relative_density(eta0: Real, v0_m3: Real, v_m3: Real) -> Option<Real> {
    if [eta0, v0_m3, v_m3]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0)
    {
        Some(eta0 * v0_m3 / v_m3)
    } else {
        None
    }
}

/// Volume-equivalent diameter d_V = (6V/π)^{1/3}, m, of a volume V (m³).
/// `None` unless V is finite and positive.
pub fn volume_equivalent_diameter(v_m3: Real) -> Option<Real> {
    if v_m3.is_finite() && v_m3 > 0.0 {
        Some(crate::math::cbrt(6.0 * v_m3 / PI))
    } else {
        None
    }
}

/// Heywood surface-volume coefficient α_SV = d·S/V, dimensionless (6 for a
/// sphere of diameter d), from a diameter d (m), area S (m²) and volume V
/// (m³). `None` unless all three are finite and positive.
pub fn heywood_coefficient(d_m: Real, area_m2: Real, v_m3: Real) -> Option<Real> {
    if [d_m, area_m2, v_m3]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0)
    {
        Some(d_m * area_m2 / v_m3)
    } else {
        None
    }
}

/// Checked surface geometry: area S (m²) and enclosed volume V (m³) of the
/// closed surface `quads` (node ids into `positions`, m, counter-clockwise
/// seen from outside), by [`area_and_volume`]. Errors for an empty surface,
/// a node id beyond `positions`, or a result that is not finite and positive
/// (e.g. an inverted surface, whose volume is negative).
pub fn surface_geometry(
    positions: &[[Real; 3]],
    quads: &[[u32; 4]],
) -> Result<(Real, Real), BedError> {
    if quads.is_empty() {
        return Err(BedError::Empty { buffer: "quads" });
    }
    let Some((area_m2, volume_m3)) = area_and_volume(positions, quads) else {
        // A quad names a node beyond `positions`: say which.
        let (quad, node) = quads
            .iter()
            .enumerate()
            .find_map(|(k, q)| {
                q.iter()
                    .find(|&&n| n as usize >= positions.len())
                    .map(|&n| (k, n))
            })
            .unwrap_or((0, u32::MAX));
        return Err(BedError::NodeOutOfRange { quad, node });
    };
    if area_m2.is_finite() && area_m2 > 0.0 && volume_m3.is_finite() && volume_m3 > 0.0 {
        Ok((area_m2, volume_m3))
    } else {
        Err(BedError::Degenerate { area_m2, volume_m3 })
    }
}

/// Geometry of one granule in its current configuration (physics.md §7
/// items 5–6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GranuleShape {
    /// Envelope volume V = ⅓∮x·n dA of the surface quads, m³.
    pub volume_m3: Real,
    /// Surface area S (2×2 Gauss on the bilinear quads), m².
    pub area_m2: Real,
    /// Relative density η_g = η0·V0/V, dimensionless.
    pub relative_density: Real,
    /// Heywood coefficient with the volume-equivalent diameter,
    /// α_SV = d_V·S/V, d_V = (6V/π)^{1/3}: pure shape (6 for a sphere,
    /// 6.0175 for the undeformed standard mesh, unchanged by uniform scaling).
    pub heywood_dv: Real,
    /// Heywood coefficient with the fixed diameter `d_fixed`, α_SV = d·S/V
    /// (6.0514 for the undeformed standard mesh with d = 1 mm).
    pub heywood_fixed: Real,
}

/// Geometry of one granule from its current node `positions` (m) and outer
/// `quads` (counter-clockwise seen from outside): area S, envelope volume V,
/// relative density η_g = η0·V0/V (`eta0` the solid fraction of the
/// reference granule, `v0_m3` its enclosed reference volume, m³), and the
/// Heywood coefficients with d_V and with `d_fixed_m` (m; usually
/// [`HEYWOOD_FIXED_DIAMETER`]).
///
/// Errors as [`surface_geometry`], or [`BedError::InvalidParameter`] when
/// `eta0`, `v0_m3` or `d_fixed_m` is not finite and positive.
pub fn granule_shape(
    positions: &[[Real; 3]],
    quads: &[[u32; 4]],
    eta0: Real,
    v0_m3: Real,
    d_fixed_m: Real,
) -> Result<GranuleShape, BedError> {
    positive("eta0", eta0)?;
    positive("v0_m3", v0_m3)?;
    positive("d_fixed_m", d_fixed_m)?;
    let (area_m2, volume_m3) = surface_geometry(positions, quads)?;
    // All inputs are finite and positive here, so the helpers succeed; the
    // fallback keeps the routine panic-free regardless (overflow).
    let degenerate = BedError::Degenerate { area_m2, volume_m3 };
    let relative_density = relative_density(eta0, v0_m3, volume_m3).ok_or(degenerate)?;
    let d_v = volume_equivalent_diameter(volume_m3).ok_or(degenerate)?;
    let heywood_dv = heywood_coefficient(d_v, area_m2, volume_m3).ok_or(degenerate)?;
    let heywood_fixed = heywood_coefficient(d_fixed_m, area_m2, volume_m3).ok_or(degenerate)?;
    Ok(GranuleShape {
        volume_m3,
        area_m2,
        relative_density,
        heywood_dv,
        heywood_fixed,
    })
}

// ---------------------------------------------------------------------------
// §7 items 4–5: the bed

/// Coordination number Z = 2·N_pp/N (physics.md §7 item 4, the reported
/// value): `pair_contacts` = N_pp, the number of distinct granule pairs with
/// at least one active constraint (a single step's count, or its mean over
/// the output interval, which gives the interval mean of Z), and
/// `granules` = N. Wall contacts are excluded. `None` for N = 0 or a count
/// that is negative or not finite.
pub fn coordination_number(pair_contacts: Real, granules: usize) -> Option<Real> {
    coordination_number_with_walls(pair_contacts, 0.0, granules)
}

/// Coordination number with wall contacts, Z_w = (2·N_pp + N_pw)/N: each
/// granule–granule contact counts for both granules, each granule–wall
/// contact (`wall_contacts` = N_pw, distinct (granule, wall) pairs with an
/// active constraint; the punches and the die are walls) for its one granule,
/// so Z_w is the mean number of touching partners per granule, walls
/// included. A 3×3×3 simple-cubic stack pressed in a box gives Z = 4 and
/// Z_w = 6. `None` for N = 0 or a count that is negative or not finite.
pub fn coordination_number_with_walls(
    pair_contacts: Real,
    wall_contacts: Real,
    granules: usize,
) -> Option<Real> {
    let count = |x: Real| x.is_finite() && x >= 0.0;
    if granules == 0 || !count(pair_contacts) || !count(wall_contacts) {
        return None;
    }
    Some((2.0 * pair_contacts + wall_contacts) / granules as Real)
}

/// Bed relative density as the arithmetic mean of the per-granule η_g
/// (physics.md §7 item 5, the reported value), summed in slice order.
/// `None` for an empty slice or a value that is not finite.
pub fn mean_relative_density(etas: &[Real]) -> Option<Real> {
    if etas.is_empty() || etas.iter().any(|x| !x.is_finite()) {
        return None;
    }
    Some(etas.iter().sum::<Real>() / etas.len() as Real)
}

/// Bed relative density as total solid over total envelope volume,
/// Σ solid / Σ V (physics.md §7 item 5, the logged alternative), from the
/// per-granule solid volumes η0·V0 (m³) and current envelope volumes V (m³),
/// summed in slice order. It is the V-weighted mean of η_g and differs from
/// [`mean_relative_density`] only slightly when all granules hold the same
/// solid. Errors for unequal lengths, empty slices, or a total volume that
/// is not finite and positive.
pub fn solid_over_volume(solid_m3: &[Real], volumes_m3: &[Real]) -> Result<Real, BedError> {
    if volumes_m3.len() != solid_m3.len() {
        return Err(BedError::BufferLength {
            buffer: "volumes_m3",
            expected: solid_m3.len(),
            got: volumes_m3.len(),
        });
    }
    if solid_m3.is_empty() {
        return Err(BedError::Empty { buffer: "solid_m3" });
    }
    let solid: Real = solid_m3.iter().sum();
    let volume = positive("sum of volumes_m3", volumes_m3.iter().sum())?;
    if !solid.is_finite() {
        return Err(BedError::InvalidParameter {
            name: "sum of solid_m3",
            value: solid,
        });
    }
    Ok(solid / volume)
}

/// Both bed relative densities from per-granule shapes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BedDensity {
    /// Arithmetic mean of η_g (the reported value).
    pub arithmetic: Real,
    /// Σ solid / Σ V with solid_g = η_g·V_g (the logged alternative).
    pub solid_over_volume: Real,
}

/// [`mean_relative_density`] and [`solid_over_volume`] of the granules'
/// [`GranuleShape`]s (solid volume η_g·V_g = η0·V0 up to round-off), summed
/// in slice order. `None` for an empty slice or non-finite values.
pub fn bed_density(shapes: &[GranuleShape]) -> Option<BedDensity> {
    if shapes.is_empty() {
        return None;
    }
    let n = shapes.len() as Real;
    let (mut eta, mut solid, mut volume) = (0.0, 0.0, 0.0);
    for s in shapes {
        eta += s.relative_density;
        solid += s.relative_density * s.volume_m3;
        volume += s.volume_m3;
    }
    let out = BedDensity {
        arithmetic: eta / n,
        solid_over_volume: solid / volume,
    };
    (out.arithmetic.is_finite() && out.solid_over_volume.is_finite() && volume > 0.0).then_some(out)
}
