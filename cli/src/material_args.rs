//! `--type` and the material-parameter overrides, shared by every command
//! that builds a [`Material`].
//!
//! The parameters start from the preset of the granule type; each override
//! flag replaces one field of [`MaterialParams`] (flag = field name in kebab
//! case). The result is checked with [`MaterialParams::validate`], and a
//! rejection names the flag as well as the field and its allowed range.

use clap::Args;
use granbed_kernel::Real;
use granbed_kernel::material::{GranuleType, Material, MaterialParams, ParamError};
use serde::Serialize;

use crate::error::InputError;

/// Granule type and parameter overrides.
#[derive(Args, Debug, Clone, Copy, PartialEq)]
#[command(next_help_heading = "Material (preset from --type, then overrides)")]
pub struct MaterialArgs {
    /// Standard granule type A1…C3 whose preset parameters the overrides
    /// start from.
    ///
    /// The letter sets the yield stress (A 10 kPa, B 30 kPa, C 100 kPa), the
    /// digit the initial relative density (1: 0.6, 2: 0.8, 3: 1.0). All
    /// presets have E = 1 MPa, ν = 0.3, cp = 0.3, ηc = 0.2, true density
    /// 1500 kg/m³ and friction 0.1. Case-insensitive.
    #[arg(long = "type", value_name = "TYPE", default_value = "B2")]
    pub granule_type: GranuleType,

    /// Young's modulus E of the granule skeleton, Pa (1e-3 ≤ E ≤ 1e13).
    #[arg(value_parser = crate::numbers::real, long, value_name = "PA", allow_negative_numbers = true)]
    pub youngs_modulus_pa: Option<f64>,

    /// Poisson's ratio ν, dimensionless (−1 < ν < 0.5).
    #[arg(value_parser = crate::numbers::real, long, value_name = "NU", allow_negative_numbers = true)]
    pub poisson_ratio: Option<f64>,

    /// Yield stress σy of the solid (Kirchhoff measure), Pa (≥ 1e-3 and
    /// ≥ 1e-6 E; `inf` makes the material purely elastic).
    #[arg(value_parser = crate::numbers::real, long, value_name = "PA", allow_negative_numbers = true)]
    pub yield_stress_pa: Option<f64>,

    /// Initial relative density η0 (solid fraction), dimensionless
    /// (ηc < η0 ≤ 1).
    #[arg(value_parser = crate::numbers::real, long, value_name = "ETA", allow_negative_numbers = true)]
    pub eta0: Option<f64>,

    /// Yield-surface pressure constant cp of a1(η) = cp(1 − η²),
    /// dimensionless (0 ≤ cp ≤ 1e3).
    #[arg(value_parser = crate::numbers::real, long, value_name = "CP", allow_negative_numbers = true)]
    pub cp: Option<f64>,

    /// Critical relative density ηc where the yield surface vanishes,
    /// dimensionless (0 ≤ ηc < 1, and below η0).
    #[arg(value_parser = crate::numbers::real, long, value_name = "ETA", allow_negative_numbers = true)]
    pub eta_c: Option<f64>,

    /// True (solid) density of the granule material, kg/m³
    /// (1e-3 ≤ ρ ≤ 1e5);
    /// the granule's density is η0 times this.
    #[arg(value_parser = crate::numbers::real, long, value_name = "KG_M3", allow_negative_numbers = true)]
    pub true_density_kg_m3: Option<f64>,

    /// Coulomb friction coefficient of the granule surface, dimensionless
    /// (0 ≤ μ ≤ 10).
    #[arg(value_parser = crate::numbers::real, long, value_name = "MU", allow_negative_numbers = true)]
    pub friction: Option<f64>,
}

impl MaterialArgs {
    /// The preset of `--type` with every given override applied (not
    /// validated).
    pub fn params(&self) -> MaterialParams {
        let mut p = self.granule_type.params();
        let overrides = [
            (&mut p.youngs_modulus_pa, self.youngs_modulus_pa),
            (&mut p.poisson_ratio, self.poisson_ratio),
            (&mut p.yield_stress_pa, self.yield_stress_pa),
            (&mut p.eta0, self.eta0),
            (&mut p.cp, self.cp),
            (&mut p.eta_c, self.eta_c),
            (&mut p.true_density_kg_m3, self.true_density_kg_m3),
            (&mut p.friction, self.friction),
        ];
        for (field, value) in overrides {
            if let Some(v) = value {
                *field = v;
            }
        }
        p
    }

    /// The validated material; a rejected parameter becomes a usage error
    /// naming its flag (see [`MaterialArgs::param_error`]).
    pub fn material(&self) -> anyhow::Result<Material> {
        let params = self.params();
        params
            .validate()
            .map_err(|first| every_refusal(&params, first, |e| self.param_error(&params, e)))
    }

    /// Turns the kernel's `ParamError` into a usage error whose message names
    /// the flag, the value and where it came from (the flag or the preset),
    /// followed by the kernel's message with the allowed range.
    pub fn param_error(&self, params: &MaterialParams, err: ParamError) -> anyhow::Error {
        let flag = flag_for_field(err.field);
        let given = match err.field {
            "youngs_modulus_pa" => self.youngs_modulus_pa,
            "poisson_ratio" => self.poisson_ratio,
            "yield_stress_pa" => self.yield_stress_pa,
            "eta0" => self.eta0,
            "cp" => self.cp,
            "eta_c" => self.eta_c,
            "true_density_kg_m3" => self.true_density_kg_m3,
            "friction" => self.friction,
            _ => None,
        };
        let origin = if given.is_some() {
            format!("`{flag} {}`", err.value)
        } else {
            format!(
                "`{flag}` (preset {} value {})",
                self.granule_type, err.value
            )
        };
        let related = related_field(err.field, params, true);
        anyhow::Error::new(err).context(InputError(format!("{origin} rejected{related}")))
    }
}

/// One usage error for every field `params` refuses
/// ([`MaterialParams::refusals`]), each worded by `one`, one per line with
/// `validate`'s error `first` first: a user who gave two bad values reads
/// both at once. With one refused field, `one(first)` itself.
pub fn every_refusal(
    params: &MaterialParams,
    first: ParamError,
    one: impl Fn(ParamError) -> anyhow::Error,
) -> anyhow::Error {
    let refused = params.refusals();
    if refused.len() <= 1 {
        return one(first);
    }
    crate::error::input_error(
        refused
            .into_iter()
            .map(|e| format!("{:#}", one(e)))
            .collect::<Vec<_>>()
            .join("\n"),
    )
}

/// " (with …)": the other field a rejected `field`'s range depends on, as
/// `params` has it, and the bound that follows — η0's on ηc, σ_y's on E —
/// or nothing (also when that field is refused itself). `flags`: name the
/// command-line flag that sets it.
pub fn related_field(field: &str, params: &MaterialParams, flags: bool) -> String {
    let see = |flag: &str| {
        if flags {
            format!("; see `{flag}`")
        } else {
            String::new()
        }
    };
    // A related field itself out of range is refused on its own line, and
    // the bound was judged without it (`MaterialParams::refusals`).
    let refused = |related: &str| params.refusals().iter().any(|e| e.field == related);
    match field {
        "eta0" if !refused("eta_c") => {
            format!(" (with eta_c = {}{})", params.eta_c, see("--eta-c"))
        }
        "yield_stress_pa" if !refused("youngs_modulus_pa") => {
            format!(
                " (with youngs_modulus_pa = {}, i.e. at least {} Pa{})",
                crate::numbers::short(params.youngs_modulus_pa),
                crate::numbers::short(f64::max(
                    granbed_kernel::material::MIN_YIELD_STRESS_PA,
                    granbed_kernel::material::MIN_YIELD_TO_MODULUS * params.youngs_modulus_pa
                )),
                see("--youngs-modulus-pa")
            )
        }
        _ => String::new(),
    }
}

/// The command-line flag of a [`MaterialParams`] field: `--` and the field
/// name in kebab case (`eta_c` → `--eta-c`).
pub fn flag_for_field(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

/// What material overrides do to a comparison of `types` (`--types`): the
/// types differ in their yield stress (the letter) and η0 (the digit), and
/// an override given for one of them replaces it in every type.
/// `overrides` are the yield stress, Pa, and η0 given, each with how the
/// user spelt it (a flag or a scene field). Two listed types left with the
/// same yield stress and η0 would be one material under two names: `Err`,
/// a usage error. An override of a parameter in which the listed types
/// differ, the types still distinct: a warning to show. Otherwise `None`.
pub fn check_type_overrides(
    types: &[GranuleType],
    [(yield_stress, yield_name), (eta0, eta0_name)]: [(Option<f64>, &str); 2],
) -> anyhow::Result<Option<String>> {
    let own = |t: &GranuleType| (t.yield_stress_pa(), t.eta0());
    let effective = |t: &GranuleType| {
        let (y, e) = own(t);
        (yield_stress.unwrap_or(y), eta0.unwrap_or(e))
    };
    for (i, a) in types.iter().enumerate() {
        if let Some(b) = types[i + 1..].iter().find(|b| effective(b) == effective(a)) {
            let (y, e) = effective(a);
            let given: Vec<&str> = [(yield_stress, yield_name), (eta0, eta0_name)]
                .iter()
                .filter(|(v, _)| v.is_some())
                .map(|&(_, name)| name)
                .collect();
            return Err(InputError(format!(
                "{} applies to every listed type: {a} and {b} would run the same material (yield \
                 stress {y} Pa, eta0 {e}) under two names; leave it out to compare the types",
                given.join(" and ")
            ))
            .into());
        }
    }
    let differ = |f: fn(&(f64, f64)) -> f64| {
        types
            .windows(2)
            .any(|w| f(&own(&w[0])).to_bits() != f(&own(&w[1])).to_bits())
    };
    let replaced: Vec<String> = [
        (yield_stress, yield_name, "yield stresses", differ(|p| p.0)),
        (eta0, eta0_name, "eta0", differ(|p| p.1)),
    ]
    .iter()
    .filter_map(|&(v, name, what, differ)| {
        v.filter(|_| differ)
            .map(|v| format!("{name} = {v} replaces the listed types' own {what}"))
    })
    .collect();
    Ok((!replaced.is_empty()).then(|| {
        format!(
            "{}: the types compared differ only in what is left",
            replaced.join("; ")
        )
    }))
}

/// The granule material of a run as a `summary.json` records it (`bed`'s
/// as `material`, `granule`'s flattened into its fields): every parameter,
/// the type's preset with the overrides applied (what a methods section
/// needs).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MaterialSummary {
    /// Young's modulus E, Pa.
    pub youngs_modulus_pa: Real,
    /// Poisson's ratio ν.
    pub poisson_ratio: Real,
    /// Yield stress σ_y, Pa (`null`: ∞, purely elastic).
    pub yield_stress_pa: Real,
    /// Initial relative density η0.
    pub eta0: Real,
    /// Yield-surface constant c_p.
    pub cp: Real,
    /// Critical relative density η_c.
    pub eta_c: Real,
    /// True (solid) density, kg/m³.
    pub true_density_kg_m3: Real,
    /// Friction coefficient μ of the contacts (`granule`: of the
    /// granule–platen contact).
    pub friction: Real,
}

impl From<MaterialParams> for MaterialSummary {
    fn from(m: MaterialParams) -> Self {
        Self {
            youngs_modulus_pa: m.youngs_modulus_pa,
            poisson_ratio: m.poisson_ratio,
            yield_stress_pa: m.yield_stress_pa,
            eta0: m.eta0,
            cp: m.cp,
            eta_c: m.eta_c,
            true_density_kg_m3: m.true_density_kg_m3,
            friction: m.friction,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_that_merge_types_are_refused_and_those_that_replace_warned() {
        use GranuleType::{A2, A3, C2};
        let names = |y, e| [(y, "--yield-stress-pa"), (e, "--eta0")];
        // Nothing given, or a parameter the types share: nothing to say.
        assert!(
            check_type_overrides(&[A2, C2], names(None, None))
                .unwrap()
                .is_none()
        );
        assert!(
            check_type_overrides(&[A2, C2], names(None, Some(0.7)))
                .unwrap()
                .is_none()
        );
        // A2 and C2 differ in their yield stress only.
        let e = check_type_overrides(&[A2, C2], names(Some(5e4), None)).unwrap_err();
        let e = e.to_string();
        assert!(
            e.contains("--yield-stress-pa") && e.contains("A2 and C2"),
            "{e}"
        );
        // A2, A3 and C2: η0 replaced, A2/A3 merge.
        let e = check_type_overrides(&[A2, A3, C2], names(None, Some(0.7))).unwrap_err();
        assert!(e.to_string().contains("A2 and A3"), "{e}");
        // A3 and C2 differ in both: replacing one leaves them distinct.
        let w = check_type_overrides(&[A3, C2], names(Some(5e4), None))
            .unwrap()
            .unwrap();
        assert!(w.contains("--yield-stress-pa = 50000"), "{w}");
        // A single type compares nothing.
        assert!(
            check_type_overrides(&[A2], names(Some(5e4), Some(0.7)))
                .unwrap()
                .is_none()
        );
    }
    use clap::Parser;

    #[derive(Parser)]
    struct Wrapper {
        #[command(flatten)]
        material: MaterialArgs,
    }

    fn parse(args: &[&str]) -> MaterialArgs {
        let argv = core::iter::once("test").chain(args.iter().copied());
        Wrapper::try_parse_from(argv).unwrap().material
    }

    #[test]
    fn overrides_apply_over_the_preset() {
        let all = [
            "--type",
            "a1",
            "--youngs-modulus-pa",
            "2e6",
            "--poisson-ratio",
            "-0.25",
            "--yield-stress-pa",
            "5e3",
            "--eta0",
            "0.7",
            "--cp",
            "0.4",
            "--eta-c",
            "0.1",
            "--true-density-kg-m3",
            "1000",
            "--friction",
            "0.25",
        ];
        let expected = MaterialParams {
            youngs_modulus_pa: 2.0e6,
            poisson_ratio: -0.25,
            yield_stress_pa: 5.0e3,
            eta0: 0.7,
            cp: 0.4,
            eta_c: 0.1,
            true_density_kg_m3: 1000.0,
            friction: 0.25,
        };
        assert_eq!(parse(&all).params(), expected);
        let p = parse(&["--type", "a1", "--eta0", "0.7"]).params();
        assert_eq!((p.eta0, p.yield_stress_pa), (0.7, 10.0e3));
        assert_eq!(parse(&[]).params(), GranuleType::B2.params());
    }

    #[test]
    fn errors_name_the_flag() {
        let e = parse(&["--eta-c", "0.9"]).material().unwrap_err();
        let msg = format!("{e:#}");
        assert!(msg.contains("`--eta0` (preset B2 value 0.8)"), "{msg}");
        assert!(msg.contains("eta_c = 0.9"), "{msg}");
        let e = parse(&["--poisson-ratio", "-1.5"]).material().unwrap_err();
        assert!(format!("{e:#}").starts_with("`--poisson-ratio -1.5` rejected"));
        // Every bad value at once, a line each, in the kernel's order.
        let e = parse(&["--friction", "11", "--poisson-ratio", "0.6"])
            .material()
            .unwrap_err();
        let msg = format!("{e:#}");
        let lines: Vec<&str> = msg.lines().collect();
        assert_eq!(lines.len(), 2, "{msg}");
        assert!(
            lines[0].starts_with("`--poisson-ratio 0.6` rejected"),
            "{msg}"
        );
        assert!(lines[1].starts_with("`--friction 11` rejected"), "{msg}");
        assert!(lines[1].contains("0 <= mu <= 10"), "{msg}");
        assert!(crate::error::is_usage_error(&e));
        // σ_y's bound is not given from an E that is refused itself.
        let e = parse(&["--youngs-modulus-pa", "1e14", "--yield-stress-pa", "1e-4"])
            .material()
            .unwrap_err();
        let msg = format!("{e:#}");
        assert_eq!(msg.lines().count(), 2, "{msg}");
        assert!(!msg.contains("i.e. at least"), "{msg}");
        assert_eq!(flag_for_field("true_density_kg_m3"), "--true-density-kg-m3");
    }
}
