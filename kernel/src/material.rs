//! Material parameters of a porous granule, their validation, and the nine
//! standard granule types A1…C3.
//!
//! A granule is a porous, plastically deforming solid: compressible
//! neo-Hookean elasticity (E, ν) and a density-dependent elliptic yield
//! surface (σ_y, c_p, η_c) whose size depends on the relative density
//! η = η0/J (physics.md §0–§1).

use core::fmt;
use core::str::FromStr;

use crate::Real;

/// User-facing material parameters, in SI units.
///
/// Build one from a preset with [`GranuleType::params`], edit fields, then call
/// [`MaterialParams::validate`] to obtain the [`Material`] the kernel uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialParams {
    /// Young's modulus E of the granule skeleton, Pa. Range:
    /// [`YOUNGS_MODULUS_RANGE_PA`], 1e-3 ≤ E ≤ 1e13.
    pub youngs_modulus_pa: Real,
    /// Poisson's ratio ν. Range: −1 < ν < 0.5.
    pub poisson_ratio: Real,
    /// Yield stress σ_y of the solid (Kirchhoff measure), Pa.
    /// Range: ≥ [`MIN_YIELD_STRESS_PA`] (1e-3) and ≥
    /// [`MIN_YIELD_TO_MODULUS`] × E (1e-6 E); `+∞` makes the material
    /// purely elastic.
    pub yield_stress_pa: Real,
    /// Initial relative density η0 (solid fraction). Range: η_c < η0 ≤ 1.
    pub eta0: Real,
    /// Yield-surface constant c_p of a1(η) = c_p(1 − η²). Range:
    /// 0 ≤ c_p ≤ [`MAX_CP`] (1e3).
    pub cp: Real,
    /// Critical relative density η_c where the yield surface vanishes.
    /// Range: 0 ≤ η_c < 1.
    pub eta_c: Real,
    /// True (solid) density, kg/m³; the granule's density is η0 times this.
    /// Range: [`DENSITY_RANGE_KG_M3`], 1e-3 ≤ ρ ≤ 1e5.
    pub true_density_kg_m3: Real,
    /// Coulomb friction coefficient of the granule surface. Range:
    /// 0 ≤ μ ≤ [`MAX_FRICTION`] (10).
    pub friction: Real,
}

/// A rejected material parameter: which field, the value given and the
/// allowed range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamError {
    /// Field name as in [`MaterialParams`].
    pub field: &'static str,
    /// The rejected value.
    pub value: Real,
    /// The allowed range, human readable.
    pub allowed: &'static str,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "invalid material parameter `{}` = {}: allowed range is {}",
            self.field, self.value, self.allowed
        )
    }
}

impl core::error::Error for ParamError {}

/// Validated parameters with the derived constants the update needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// The parameters this was built from.
    pub params: MaterialParams,
    /// Lamé's first parameter λ = Eν/((1+ν)(1−2ν)), Pa.
    pub lambda: Real,
    /// Shear modulus μ = E/(2(1+ν)), Pa.
    pub mu: Real,
    /// Bulk modulus K = λ + 2μ/3, Pa.
    pub bulk: Real,
    /// Reference density ρ0 = η0·ρ_true, kg/m³.
    pub density0: Real,
}

impl Material {
    /// P-wave modulus λ + 2μ, Pa (sets the dilatational wave speed).
    pub fn p_wave_modulus(&self) -> Real {
        self.lambda + 2.0 * self.mu
    }
}

fn check(
    ok: bool,
    field: &'static str,
    value: Real,
    allowed: &'static str,
) -> Result<(), ParamError> {
    if ok {
        Ok(())
    } else {
        Err(ParamError {
            field,
            value,
            allowed,
        })
    }
}

/// Allowed Young's modulus, Pa: from a gel to ten times diamond's; beyond
/// these the elastic constants, the wave speed and the stable time step
/// leave the range of `f64` arithmetic this code is tested in.
pub const YOUNGS_MODULUS_RANGE_PA: [Real; 2] = [1e-3, 1e13];
/// [`YOUNGS_MODULUS_RANGE_PA`] as an error names it (a test holds the two
/// together: a `no_std` constant cannot format a float).
const YOUNGS_MODULUS_ALLOWED: &str = "1e-3 <= E <= 1e13 Pa";

/// The smallest yield stress, Pa: the yield function scales with σ_y², which
/// must stay a normal `f64` (a σ_y of 1e-300 made the first step's motion
/// non-finite).
pub const MIN_YIELD_STRESS_PA: Real = 1e-3;
/// The smallest ratio σ_y/E, a measured margin rather than a guarantee:
/// B2's granule stopped with "no convergence" within a few per cent of
/// strain at σ_y/E = 1e-7 (σ_y = 0.1 Pa) and 3e-9 (E = 1e13 Pa), where the
/// trial stress exceeds the yield scale by more than the digits of a
/// double, and ran at 1e-6 (session 56). The yield scale is √a2 σ_y, so
/// a granule whose η0 lies just above η_c (a2 → 0) has less margin.
pub const MIN_YIELD_TO_MODULUS: Real = 1e-6;
/// [`MIN_YIELD_STRESS_PA`] and [`MIN_YIELD_TO_MODULUS`] as an error names
/// them.
const YIELD_STRESS_ALLOWED: &str = ">= 1e-3 Pa and >= 1e-6 E (+inf for a purely elastic material)";

/// The largest compaction coefficient c_p (a1 = c_p(1 − η²); the standard
/// types use 0.3).
pub const MAX_CP: Real = 1e3;
/// [`MAX_CP`] as an error names it.
const CP_ALLOWED: &str = "0 <= cp <= 1e3";

/// Allowed true density, kg/m³ (osmium is 22 600).
pub const DENSITY_RANGE_KG_M3: [Real; 2] = [1e-3, 1e5];
/// [`DENSITY_RANGE_KG_M3`] as an error names it.
const DENSITY_ALLOWED: &str = "1e-3 <= rho <= 1e5 kg/m3";

/// The largest Coulomb friction coefficient (the standard types use 0.1).
/// The platen experiment's own friction has the same range, so that the
/// browser, which gives it the granule's, names one range for μ.
pub const MAX_FRICTION: Real = 10.0;
/// [`MAX_FRICTION`] as an error names it.
pub(crate) const FRICTION_ALLOWED: &str = "0 <= mu <= 10";

impl MaterialParams {
    /// Checks every field against its documented range (NaN is always
    /// rejected) and derives the elastic constants.
    pub fn validate(&self) -> Result<Material, ParamError> {
        let p = self;
        check(
            (YOUNGS_MODULUS_RANGE_PA[0]..=YOUNGS_MODULUS_RANGE_PA[1])
                .contains(&p.youngs_modulus_pa),
            "youngs_modulus_pa",
            p.youngs_modulus_pa,
            YOUNGS_MODULUS_ALLOWED,
        )?;
        check(
            p.poisson_ratio > -1.0 && p.poisson_ratio < 0.5,
            "poisson_ratio",
            p.poisson_ratio,
            "-1 < nu < 0.5",
        )?;
        check(
            p.yield_stress_pa >= MIN_YIELD_STRESS_PA
                && p.yield_stress_pa >= MIN_YIELD_TO_MODULUS * p.youngs_modulus_pa,
            "yield_stress_pa",
            p.yield_stress_pa,
            YIELD_STRESS_ALLOWED,
        )?;
        check(
            p.eta_c >= 0.0 && p.eta_c < 1.0,
            "eta_c",
            p.eta_c,
            "0 <= eta_c < 1",
        )?;
        check(
            p.eta0 > p.eta_c && p.eta0 <= 1.0,
            "eta0",
            p.eta0,
            "eta_c < eta0 <= 1",
        )?;
        check((0.0..=MAX_CP).contains(&p.cp), "cp", p.cp, CP_ALLOWED)?;
        check(
            (DENSITY_RANGE_KG_M3[0]..=DENSITY_RANGE_KG_M3[1]).contains(&p.true_density_kg_m3),
            "true_density_kg_m3",
            p.true_density_kg_m3,
            DENSITY_ALLOWED,
        )?;
        check(
            (0.0..=MAX_FRICTION).contains(&p.friction),
            "friction",
            p.friction,
            FRICTION_ALLOWED,
        )?;
        let (e, nu) = (p.youngs_modulus_pa, p.poisson_ratio);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        Ok(Material {
            params: *p,
            lambda,
            mu,
            bulk: lambda + 2.0 * mu / 3.0,
            density0: p.eta0 * p.true_density_kg_m3,
        })
    }

    /// Every field [`Self::validate`] refuses, in the order it checks them,
    /// each at most once; empty when it accepts them all. After each
    /// refusal the field is given its most permissive valid value (the
    /// smallest E, ν = 0, σ_y = +∞, η_c = 0, η0 = 1, c_p = 0, μ = 0, water's
    /// density), so that a later refusal never comes from a value put in
    /// for an earlier one: with η_c = 2 and η0 = 0.5 only η_c is refused,
    /// with E = 1e13 and σ_y = 1 Pa σ_y is (it is below 10⁻⁶ E). For a
    /// caller that names every bad input at once; the first entry is
    /// `validate`'s error.
    pub fn refusals(&self) -> heapless::Vec<ParamError, 8> {
        let mut p = *self;
        let mut out = heapless::Vec::new();
        while let Err(e) = p.validate() {
            // One entry per field, and at most one per field of the
            // struct (the capacity): a field refused again after its
            // permissive value would be a check that no value passes.
            if out.iter().any(|seen: &ParamError| seen.field == e.field) || out.push(e).is_err() {
                break;
            }
            match (p.field_mut(e.field), permissive_value(e.field)) {
                (Some(field), Some(value)) => *field = value,
                _ => break,
            }
        }
        out
    }
}

impl MaterialParams {
    /// The field named `field` (a name of this struct), if there is one.
    fn field_mut(&mut self, field: &str) -> Option<&mut Real> {
        Some(match field {
            "youngs_modulus_pa" => &mut self.youngs_modulus_pa,
            "poisson_ratio" => &mut self.poisson_ratio,
            "yield_stress_pa" => &mut self.yield_stress_pa,
            "eta_c" => &mut self.eta_c,
            "eta0" => &mut self.eta0,
            "cp" => &mut self.cp,
            "true_density_kg_m3" => &mut self.true_density_kg_m3,
            "friction" => &mut self.friction,
            _ => return None,
        })
    }
}

/// The value [`MaterialParams::refusals`] gives a refused field: valid
/// whatever the other fields hold, and the one that widens the ranges
/// depending on it most (σ_y's lower bound grows with E, η0's with η_c).
fn permissive_value(field: &str) -> Option<Real> {
    Some(match field {
        "youngs_modulus_pa" => YOUNGS_MODULUS_RANGE_PA[0],
        "yield_stress_pa" => Real::INFINITY,
        "eta0" => 1.0,
        "true_density_kg_m3" => 1000.0,
        "poisson_ratio" | "eta_c" | "cp" | "friction" => 0.0,
        _ => return None,
    })
}

/// The nine standard granule types of the published study: the letter sets
/// the yield stress (A 10 kPa, B 30 kPa, C 100 kPa), the digit the initial
/// relative density (1: 0.6, 2: 0.8, 3: 1.0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)]
pub enum GranuleType {
    A1,
    A2,
    A3,
    B1,
    B2,
    B3,
    C1,
    C2,
    C3,
}

impl GranuleType {
    /// All nine types in the order A1, A2, …, C3.
    pub const ALL: [GranuleType; 9] = [
        GranuleType::A1,
        GranuleType::A2,
        GranuleType::A3,
        GranuleType::B1,
        GranuleType::B2,
        GranuleType::B3,
        GranuleType::C1,
        GranuleType::C2,
        GranuleType::C3,
    ];

    /// The type's name, e.g. `"B2"`.
    pub fn name(self) -> &'static str {
        const NAMES: [&str; 9] = ["A1", "A2", "A3", "B1", "B2", "B3", "C1", "C2", "C3"];
        NAMES[self as usize]
    }

    /// Yield stress σ_y of the type, Pa.
    pub fn yield_stress_pa(self) -> Real {
        [10.0e3, 30.0e3, 100.0e3][self as usize / 3]
    }

    /// Initial relative density η0 of the type.
    pub fn eta0(self) -> Real {
        [0.6, 0.8, 1.0][self as usize % 3]
    }

    /// The preset parameters: σ_y and η0 of the type; E = 1 MPa, ν = 0.3,
    /// c_p = 0.3, η_c = 0.2, ρ_true = 1500 kg/m³, friction 0.1.
    pub fn params(self) -> MaterialParams {
        MaterialParams {
            youngs_modulus_pa: 1.0e6,
            poisson_ratio: 0.3,
            yield_stress_pa: self.yield_stress_pa(),
            eta0: self.eta0(),
            cp: 0.3,
            eta_c: 0.2,
            true_density_kg_m3: 1500.0,
            friction: 0.1,
        }
    }
}

impl fmt::Display for GranuleType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown granule type name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownGranuleType;

impl fmt::Display for UnknownGranuleType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("unknown granule type: expected one of A1, A2, A3, B1, B2, B3, C1, C2, C3")
    }
}

impl core::error::Error for UnknownGranuleType {}

impl FromStr for GranuleType {
    type Err = UnknownGranuleType;

    /// Parses `"A1"` … `"C3"` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        GranuleType::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(s))
            .ok_or(UnknownGranuleType)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::format;

    /// Each range an error names is the range the check applies: the
    /// texts hold the constants' values as `{:e}` writes them.
    #[test]
    fn the_range_texts_name_the_constants() {
        let texts: [(&str, &[Real]); 4] = [
            (YOUNGS_MODULUS_ALLOWED, &YOUNGS_MODULUS_RANGE_PA),
            (
                YIELD_STRESS_ALLOWED,
                &[MIN_YIELD_STRESS_PA, MIN_YIELD_TO_MODULUS],
            ),
            (CP_ALLOWED, &[MAX_CP]),
            (DENSITY_ALLOWED, &DENSITY_RANGE_KG_M3),
        ];
        for (text, bounds) in texts {
            for b in bounds {
                let written = format!("{b:e}");
                assert!(
                    text.split_whitespace().any(|t| t == written),
                    "`{text}` does not name {written}"
                );
            }
        }
    }

    use super::*;

    #[test]
    fn presets_give_the_published_elastic_constants() {
        let m = GranuleType::B2.params().validate().unwrap();
        assert!((m.lambda - 576.923e3).abs() < 1.0);
        assert!((m.mu - 384.615e3).abs() < 1.0);
        assert!((m.bulk - 833.333e3).abs() < 1.0);
        assert_eq!(m.density0, 1200.0);
        assert_eq!("c3".parse::<GranuleType>(), Ok(GranuleType::C3));
        assert_eq!(GranuleType::A2.yield_stress_pa(), 10.0e3);
        assert_eq!(GranuleType::A2.eta0(), 0.8);
    }

    #[test]
    fn bad_fields_are_named() {
        let base = GranuleType::A1.params();
        let cases: [(MaterialParams, &str); 11] = [
            // Extremes that used to pass and then made the first step's
            // motion non-finite (λ = ∞, σ_y² = 0, zero masses).
            (
                MaterialParams {
                    youngs_modulus_pa: 1e300,
                    ..base
                },
                "youngs_modulus_pa",
            ),
            (
                MaterialParams {
                    youngs_modulus_pa: 5e-324,
                    ..base
                },
                "youngs_modulus_pa",
            ),
            (
                MaterialParams {
                    yield_stress_pa: 1e-300,
                    ..base
                },
                "yield_stress_pa",
            ),
            (
                MaterialParams {
                    true_density_kg_m3: 1e-300,
                    ..base
                },
                "true_density_kg_m3",
            ),
            (MaterialParams { cp: 1e300, ..base }, "cp"),
            (MaterialParams { eta0: 0.2, ..base }, "eta0"),
            (
                MaterialParams {
                    poisson_ratio: 0.5,
                    ..base
                },
                "poisson_ratio",
            ),
            (
                MaterialParams {
                    youngs_modulus_pa: 0.0,
                    ..base
                },
                "youngs_modulus_pa",
            ),
            (
                MaterialParams {
                    yield_stress_pa: Real::NAN,
                    ..base
                },
                "yield_stress_pa",
            ),
            (MaterialParams { eta0: 1.01, ..base }, "eta0"),
            (MaterialParams { cp: -0.1, ..base }, "cp"),
        ];
        for (p, field) in cases {
            assert_eq!(p.validate().unwrap_err().field, field);
        }
        assert_eq!("D1".parse::<GranuleType>(), Err(UnknownGranuleType));
    }

    /// σ_y below 1e-6 E is refused, naming σ_y, whatever E is (the
    /// return map loses the yield surface in round-off below about 1e-7);
    /// 1e-6 E itself and a purely elastic material pass.
    #[test]
    fn a_yield_stress_too_small_for_the_modulus_is_refused() {
        let stiff = |e: Real, sy: Real| MaterialParams {
            youngs_modulus_pa: e,
            yield_stress_pa: sy,
            ..GranuleType::B2.params()
        };
        for (e, sy) in [(1e13, 30e3), (1e6, 0.5), (1e6, 1e-3)] {
            let err = stiff(e, sy).validate().unwrap_err();
            assert_eq!(err.field, "yield_stress_pa", "E {e}, sigma_y {sy}");
        }
        for (e, sy) in [(1e13, 1e7), (1e6, 1.0), (1e13, Real::INFINITY)] {
            assert!(stiff(e, sy).validate().is_ok(), "E {e}, sigma_y {sy}");
        }
    }

    /// `refusals` names every bad field once, in `validate`'s order, with
    /// the first entry `validate`'s error; a field whose range depends on
    /// one already refused is judged against that one's permissive value,
    /// so it is not blamed for it.
    #[test]
    fn refusals_name_every_bad_field_once() {
        let b2 = GranuleType::B2.params();
        assert!(b2.refusals().is_empty());
        let fields = |p: MaterialParams| {
            p.refusals()
                .iter()
                .map(|e| e.field)
                .collect::<std::vec::Vec<_>>()
        };
        let all_bad = MaterialParams {
            youngs_modulus_pa: -1.0,
            poisson_ratio: 0.7,
            yield_stress_pa: Real::NAN,
            eta0: 2.0,
            cp: -1.0,
            eta_c: 1.5,
            true_density_kg_m3: 0.0,
            friction: 11.0,
        };
        // Every field, in the order `validate` checks them.
        const CHECKED: [&str; 8] = [
            "youngs_modulus_pa",
            "poisson_ratio",
            "yield_stress_pa",
            "eta_c",
            "eta0",
            "cp",
            "true_density_kg_m3",
            "friction",
        ];
        assert_eq!(fields(all_bad), CHECKED);
        assert_eq!(all_bad.refusals()[0], all_bad.validate().unwrap_err());
        assert_eq!(all_bad.refusals()[4].value, 2.0);
        // η0 = 0.5 is refused only for η_c = 0.9, and not for η_c = 1.5,
        // which is refused itself.
        assert_eq!(
            fields(MaterialParams {
                eta_c: 0.9,
                eta0: 0.5,
                ..b2
            }),
            ["eta0"]
        );
        assert_eq!(
            fields(MaterialParams {
                eta_c: 1.5,
                eta0: 0.5,
                ..b2
            }),
            ["eta_c"]
        );
        // σ_y = 0.5 Pa is too small for E = 1 MPa, not for a refused E.
        let soft = MaterialParams {
            yield_stress_pa: 0.5,
            ..b2
        };
        assert_eq!(fields(soft), ["yield_stress_pa"]);
        assert_eq!(
            fields(MaterialParams {
                youngs_modulus_pa: -1.0,
                ..soft
            }),
            ["youngs_modulus_pa"]
        );
        assert_eq!(
            fields(MaterialParams {
                friction: -0.1,
                cp: 2e3,
                ..b2
            }),
            ["cp", "friction"]
        );
        // Every permissive value is valid with every other one (so none can
        // be refused again and end the list early).
        let mut permissive = b2;
        for field in CHECKED {
            *permissive.field_mut(field).unwrap() = permissive_value(field).unwrap();
        }
        assert!(permissive.validate().is_ok(), "{permissive:?}");
        assert!(permissive.refusals().is_empty());
    }
}
