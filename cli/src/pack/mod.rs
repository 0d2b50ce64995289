//! `granbed-cli pack`: rigid spheres poured into the die and settled under
//! gravity (the kernel's [`granbed_kernel::dem::pour`], physics.md §6); the
//! packing, a summary with the bed height, packing fractions and
//! coordination number, and a VTK view are written to an output directory.
//!
//! * [`run`](mod@run): owned buffers and the pour driven to rest;
//! * [`measures`]: bed height, packing fractions, contacts (plain geometry);
//! * [`summary`]: the fields of `summary.json`;
//! * [`outputs`]: the packing CSV (and its reader [`read_packing`], for the
//!   bed compression), the JSON and the VTU writers;
//! * [`progress`]: the progress line on stderr.

use core::fmt;
use core::str::FromStr;
use std::path::PathBuf;

use clap::Args;
use granbed_kernel::dem::pour::{PourError, PourParams};
use granbed_kernel::material::{GranuleType, Material, MaterialParams, ParamError};

use crate::error::{InputError, input_error};
use crate::material_args::MaterialArgs;
use crate::output::Streams;

pub mod measures;
pub mod outputs;
pub mod progress;
pub mod run;
pub mod summary;

pub use outputs::{Sphere, read_packing};

/// Highest initial lattice accepted, m: the spheres are inserted as a
/// stacked lattice, and a taller stack means the die cannot take them.
pub const MAX_INSERTION_HEIGHT_M: f64 = 1.0;

/// The contact stiffness accepted, MPa. Softer, the resting overlaps
/// grow as E^(-2/3) (measured with the default 1000 granules of 1 mm:
/// 7.8 µm, 0.8 % of a diameter, at 1 MPa; 31 µm at 0.1 MPa); stiffer, the
/// pour's steps grow
/// (200 granules: 0.26 M steps at 100 MPa, 3.7 M at 1e5 MPa, 34 s; at 1e9
/// MPa it ran for hours).
pub const YOUNGS_MODULUS_RANGE_MPA: [f64; 2] = [1.0, 1.0e5];

/// The largest granule diameter accepted, mm (the bed scene's limit).
pub const MAX_DIAMETER_MM: f64 = 2000.0;

/// Largest neighbour grid accepted (cells of one diameter plus the skin
/// over the die's bounding square and the lattice height; 4 bytes each).
pub const MAX_GRID_CELLS: usize = 1 << 24;

/// The output description shown at the end of `pack --help`.
const OUTPUT_HELP: &str = "\
Output, in --out DIR (created if missing):
  packing.csv   one row per granule, in granule order: the hand-over to the bed
                compression (floats round-trip exact)
    x_m,y_m,z_m   centre, m (die axis along z, floor at z = 0)
    radius_m      radius, m
  summary.json  every input; bed_height_m = max(z + r); packing_fraction =
                N (4/3) pi r^3 / (pi R_die^2 H); interior_packing_fraction (sphere
                volume inside the cylinder of radius R_die - 2d between z = 2d
                and H - 2d, over its volume; null if there is none);
                coordination_number = 2 x overlapping sphere pairs / N; floor
                and die contacts; max_overlap_m; force_balance_rel = (floor
                force + wall friction)/(N m g) - 1; settle_time_s, steps, dt_s,
                wall_time_s; and \"error\" if the spheres did not come to rest
  packing.vtu   VTK XML unstructured grid: one vertex per granule with point
                data radius and id (ParaView: Glyph, sphere, scale by radius x 2)

The sphere density is eta0 x true density of the granule type. The spheres start
on a jittered square lattice (spacing 1.15 d) with random velocities from --seed;
the same seed gives the same packing.csv, byte for byte. A progress line goes to
stderr when it is a terminal, then one summary line. If the spheres do not come
to rest within --max-time-s, the outputs are still written (summary.json with
\"settled\": false and its \"error\") and the command fails.

Exit status: 0 success, 1 runtime failure (not at rest, kernel or I/O error),
2 usage or validation error.";

/// A quantity typed in a scaled unit (mm, MPa): the number as given and its
/// SI value `given × 10^EXP`, rounded once from the decimal text (so
/// `11.3` mm is exactly the `f64` nearest 0.0113 m, as a literal `11.3e-3`
/// would be).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scaled<const EXP: i32> {
    /// The value in the unit of the flag.
    pub given: f64,
    /// The value in SI units.
    pub si: f64,
}

/// A length in millimetres.
pub type Millimetres = Scaled<-3>;
/// A stress in megapascals.
pub type Megapascals = Scaled<6>;

impl<const EXP: i32> FromStr for Scaled<EXP> {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let text = s.trim();
        // The number flags' parser: `1e400` refused rather than read as
        // infinity, hints for a unit or a comma.
        let given = crate::numbers::real(text)?;
        // Shift the decimal exponent of the text itself, then parse once.
        let (mantissa, exp) = match text.find(['e', 'E']) {
            Some(at) => (&text[..at], text[at + 1..].parse::<i32>().ok()),
            None => (text, Some(0)),
        };
        let si = exp
            .and_then(|e| e.checked_add(EXP))
            .and_then(|e| format!("{mantissa}e{e}").parse::<f64>().ok())
            .unwrap_or(given * 10f64.powi(EXP));
        Ok(Self { given, si })
    }
}

impl<const EXP: i32> fmt::Display for Scaled<EXP> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&crate::numbers::short(self.given))
    }
}

/// The granule material of a pour: `--type` and the overrides that matter
/// to rigid spheres (the rest of [`MaterialArgs`] only matters to the
/// deforming granules of the bed compression).
#[derive(Args, Debug, Clone, Copy, PartialEq)]
#[command(next_help_heading = "Granule material (preset from --type, then overrides)")]
pub struct PackMaterialArgs {
    /// Standard granule type A1…C3 whose preset the overrides start from.
    ///
    /// For the pour only the density and the friction matter: the digit
    /// sets the initial relative density η0 (1: 0.6, 2: 0.8, 3: 1.0); all
    /// presets have true density 1500 kg/m³ and friction 0.1. The letter
    /// (yield stress) does not change the pour but is recorded.
    /// Case-insensitive.
    #[arg(long = "type", value_name = "TYPE", default_value = "B2")]
    pub granule_type: GranuleType,

    /// Initial relative density η0 (solid fraction) of the granules,
    /// dimensionless (ηc < η0 ≤ 1, ηc = 0.2 in every preset).
    #[arg(value_parser = crate::numbers::real, long, value_name = "ETA", allow_negative_numbers = true)]
    pub eta0: Option<f64>,

    /// True (solid) density of the granule material, kg/m³
    /// (1e-3 ≤ ρ ≤ 1e5);
    /// the spheres' density is η0 times this.
    #[arg(value_parser = crate::numbers::real, long, value_name = "KG_M3", allow_negative_numbers = true)]
    pub true_density_kg_m3: Option<f64>,

    /// Coulomb friction coefficient of the sphere–sphere and the
    /// sphere–wall (floor and die) contacts, dimensionless (0 ≤ μ ≤ 10).
    #[arg(value_parser = crate::numbers::real, long, value_name = "MU", allow_negative_numbers = true)]
    pub friction: Option<f64>,
}

impl PackMaterialArgs {
    /// The same choice as material-parameter arguments (the overrides not
    /// offered here left at the preset).
    pub fn material_args(&self) -> MaterialArgs {
        MaterialArgs {
            granule_type: self.granule_type,
            youngs_modulus_pa: None,
            poisson_ratio: None,
            yield_stress_pa: None,
            eta0: self.eta0,
            cp: None,
            eta_c: None,
            true_density_kg_m3: self.true_density_kg_m3,
            friction: self.friction,
        }
    }

    /// The validated material; a rejected parameter is a usage error
    /// naming its flag.
    pub fn material(&self) -> anyhow::Result<Material> {
        let args = self.material_args();
        let params = args.params();
        params.validate().map_err(|first| {
            crate::material_args::every_refusal(&params, first, |e| param_error(&args, &params, e))
        })
    }
}

/// One refused material parameter of `pack` as a usage error naming its
/// flag.
fn param_error(args: &MaterialArgs, params: &MaterialParams, e: ParamError) -> anyhow::Error {
    if e.field == "eta0" {
        // MaterialArgs would point at `--eta-c`, which pack lacks.
        let message = format!(
            "`--eta0 {}` rejected (the type's critical density eta_c is {})",
            e.value, params.eta_c
        );
        anyhow::Error::new(e).context(InputError(message))
    } else {
        args.param_error(params, e)
    }
}

/// Options of `granbed-cli pack`.
#[derive(Args, Debug, Clone, PartialEq)]
#[command(after_long_help = OUTPUT_HELP)]
pub struct PackArgs {
    /// Output directory, created if missing; existing files of the same
    /// names are replaced.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Number of granules poured (a whole number, 1 ≤ N ≤ 100000).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1000,
        allow_negative_numbers = true,
        value_parser = crate::numbers::whole::<usize>(1, crate::bed::scene::MAX_GRANULES as u64)
    )]
    pub granules: usize,

    /// Random seed of the lattice jitter and the initial velocities (a
    /// whole number, 0 ≤ SEED < 2^64).
    #[arg(
        long,
        value_name = "SEED",
        default_value_t = 1,
        allow_negative_numbers = true,
        value_parser = crate::numbers::whole::<u64>(0, u64::MAX)
    )]
    pub seed: u64,

    /// Inner diameter of the die, mm (more than 4 granule diameters).
    #[arg(
        long,
        value_name = "MM",
        default_value = "11.3",
        allow_negative_numbers = true
    )]
    pub die_diameter_mm: Millimetres,

    /// Granule diameter d, mm (0.001 ≤ d < 2000). The initial lattice spacing,
    /// jitter and neighbour-list skin scale with it.
    #[arg(
        long,
        value_name = "MM",
        default_value = "1",
        allow_negative_numbers = true
    )]
    pub diameter_mm: Millimetres,

    /// Young's modulus E_DE of the Hertz–Mindlin contacts, MPa
    /// (1 ≤ E ≤ 1e5): the default 100 MPa is stiffer than the granule so
    /// that resting overlaps stay below 0.3 µm (about 8 µm at 1 MPa). The
    /// time step scales as E_DE^(−2/5).
    #[arg(
        long,
        value_name = "MPA",
        default_value = "100",
        allow_negative_numbers = true
    )]
    pub youngs_modulus_mpa: Megapascals,

    /// Give up (exit status 1, outputs still written) if the spheres are not
    /// at rest after this simulated time, s (finite, after the end of the
    /// dissipation ramp at 0.30 s).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "S",
        default_value_t = 3.0,
        allow_negative_numbers = true
    )]
    pub max_time_s: f64,

    /// No progress line and no summary line on stderr (errors are still
    /// reported).
    #[arg(short, long)]
    pub quiet: bool,

    /// Granule type and overrides.
    #[command(flatten)]
    pub material: PackMaterialArgs,
}

/// The number of cells of the kernel's neighbour grid over the die up to
/// `height` (cells of one diameter plus the skin), or a little more, in
/// floating point so a degenerate input cannot overflow.
fn grid_cells(params: &PourParams, height: f64) -> f64 {
    let range = 2.0 * params.radius + params.skin;
    let across = (2.0 * params.die_radius / range).floor().max(1.0);
    let up = (height / range).ceil().max(1.0);
    across * across * up
}

impl PackArgs {
    /// The pour's parameters for `material`: the kernel's standard pour
    /// ([`PourParams::standard`] with the density η0 × true density and the
    /// seed) with every option applied.
    pub fn params(&self, material: &Material) -> PourParams {
        let mut p = PourParams::standard(material.density0, self.seed);
        p.granules = self.granules;
        let radius = 0.5 * self.diameter_mm.si;
        let scale = radius / p.radius;
        p.radius = radius;
        p.lattice_spacing *= scale;
        p.jitter *= scale;
        p.skin *= scale;
        p.die_radius = 0.5 * self.die_diameter_mm.si;
        p.youngs_modulus_pa = self.youngs_modulus_mpa.si;
        p.friction_particle = material.params.friction;
        p.friction_wall = material.params.friction;
        p.max_time = self.max_time_s;
        p
    }

    /// Turns a kernel parameter rejection into a usage error naming the
    /// command-line flag and its allowed range in the flag's own units
    /// (the kernel's field, a radius in metres, is left out); other setup
    /// errors stay runtime errors.
    pub fn pour_error(&self, err: PourError) -> anyhow::Error {
        let PourError::InvalidParameter {
            field,
            value,
            allowed,
        } = err
        else {
            return anyhow::Error::new(err).context("cannot set up the pour");
        };
        let d = self.diameter_mm;
        let message = match field {
            "granules" => format!(
                "`--granules {}` is out of range (allowed: whole numbers 1..=100000)",
                self.granules
            ),
            "radius" => return self.diameter_range_error(),
            "die_radius" => format!(
                "`--die-diameter-mm {}` is out of range (allowed: more than 4 granule \
                 diameters, here more than {} mm for `--diameter-mm {d}`)",
                self.die_diameter_mm,
                4.0 * d.given
            ),
            "youngs_modulus_pa" => return self.youngs_modulus_range_error(),
            "density" => format!(
                "the sphere density {value} kg/m^3 (`--eta0` x `--true-density-kg-m3`) is out \
                 of range (allowed: {allowed})"
            ),
            "friction" => format!("`--friction {value}` is out of range (allowed: {allowed})"),
            "ramp" | "max_time" => format!(
                "`--max-time-s {}` is out of range (allowed: finite and after the end of the \
                 dissipation ramp at {} s)",
                self.max_time_s,
                PourParams::standard(1.0, 0).ramp.1
            ),
            other => {
                let message = format!("pour parameter `{other}` = {value} rejected");
                return anyhow::Error::new(err).context(InputError(message));
            }
        };
        input_error(message)
    }

    /// The usage error of a `--diameter-mm` outside 0.001 ≤ d <
    /// [`MAX_DIAMETER_MM`].
    fn diameter_range_error(&self) -> anyhow::Error {
        input_error(format!(
            "`--diameter-mm {}` is out of range (allowed: {} <= d < {MAX_DIAMETER_MM} mm)",
            self.diameter_mm,
            crate::granule::DIAMETER_RANGE_MM[0]
        ))
    }

    /// The usage error of a `--youngs-modulus-mpa` outside
    /// [`YOUNGS_MODULUS_RANGE_MPA`].
    fn youngs_modulus_range_error(&self) -> anyhow::Error {
        let [lo, hi] = YOUNGS_MODULUS_RANGE_MPA;
        input_error(format!(
            "`--youngs-modulus-mpa {}` is out of range (allowed: {lo} <= E <= {hi:e} MPa)",
            self.youngs_modulus_mpa
        ))
    }

    /// Checks `params` before anything is allocated or written: the
    /// kernel's parameter validation (errors naming the flag), then whether
    /// the granules fit in the die at the insertion lattice and the
    /// neighbour grid stays reasonable.
    pub fn check(&self, params: &PourParams) -> anyhow::Result<()> {
        // The kernel accepts an infinite time limit or die (and would run or
        // walk lattice sites without end).
        if !self.max_time_s.is_finite() {
            return Err(input_error(format!(
                "`--max-time-s {}` rejected: the time limit must be finite",
                self.max_time_s
            )));
        }
        let [lo, hi] = YOUNGS_MODULUS_RANGE_MPA;
        if !(lo..=hi).contains(&self.youngs_modulus_mpa.given) {
            return Err(self.youngs_modulus_range_error());
        }
        let d = self.diameter_mm.given;
        if !(crate::granule::DIAMETER_RANGE_MM[0]..MAX_DIAMETER_MM).contains(&d) {
            return Err(self.diameter_range_error());
        }
        if !self.die_diameter_mm.si.is_finite() {
            return Err(input_error(format!(
                "`--die-diameter-mm {}` rejected: the die diameter must be finite",
                self.die_diameter_mm
            )));
        }
        // One layer of the grid first: the kernel's checks walk the lattice
        // sites of a layer, which takes long in a vast die (a count that
        // overflowed to infinity, from a die of 1e200 mm, is too wide too).
        let layer = grid_cells(params, 0.0);
        if layer.is_nan() || layer > MAX_GRID_CELLS as f64 {
            return Err(self.too_wide(layer));
        }
        run::check(*params).map_err(|e| self.pour_error(e))?;
        let fill = params.fill_height();
        if fill > MAX_INSERTION_HEIGHT_M || fill.is_nan() {
            return Err(input_error(format!(
                "{} granules do not fit in the die: on the insertion lattice (spacing {} mm) in \
                 the `--die-diameter-mm {}` die they stand {:.3} m tall, more than {} m; pour \
                 fewer `--granules`, or widen `--die-diameter-mm` or reduce `--diameter-mm`",
                self.granules,
                params.lattice_spacing * 1e3,
                self.die_diameter_mm,
                fill,
                MAX_INSERTION_HEIGHT_M
            )));
        }
        let cells = grid_cells(params, fill + 2.0 * params.radius);
        if cells > MAX_GRID_CELLS as f64 || cells.is_nan() {
            return Err(self.too_wide(cells));
        }
        Ok(())
    }

    /// The usage error of a neighbour grid of about `cells` cells, more
    /// than [`MAX_GRID_CELLS`].
    fn too_wide(&self, cells: f64) -> anyhow::Error {
        let count = if cells.is_finite() {
            format!("about {cells:.3e}")
        } else {
            "more than a float counts".to_owned()
        };
        input_error(format!(
            "`--die-diameter-mm {}` is too wide for granules of `--diameter-mm {}`: the \
             neighbour grid would need {count} cells (at most {MAX_GRID_CELLS})",
            self.die_diameter_mm, self.diameter_mm
        ))
    }

    /// Validates the options, pours, writes the outputs and the summary
    /// line. Fails (after writing the outputs) if the spheres did not come
    /// to rest.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        let material = self.material.material()?;
        let params = self.params(&material);
        self.check(&params)?;
        crate::bed::refuse_unfinished(&self.out, "pack")?;
        crate::output::create_out_dir(&self.out)?;
        let bar = progress::Progress::new(self.quiet, params.granules, params.max_time);
        // No stop: `pack` keeps the default SIGINT handling (it has no
        // finished work to save before its outputs).
        let result = run::run_pour(params, &mut |s, t| {
            bar.update(s, t);
            core::ops::ControlFlow::Continue(())
        });
        bar.finish();
        let result = result.map_err(|e| self.pour_error(e))?;
        let setup = summary::PackSetup {
            granule_type: self.material.granule_type.name(),
            eta0: material.params.eta0,
            true_density_kg_m3: material.params.true_density_kg_m3,
            params: &params,
        };
        let summary = summary::Summary::new(&setup, &result);
        let dir = &self.out;
        let (csv, json, vtu) = (
            dir.join(outputs::PACKING_CSV),
            dir.join(outputs::SUMMARY_JSON),
            dir.join(outputs::PACKING_VTU),
        );
        outputs::write_packing(&csv, &result.positions, params.radius)?;
        outputs::write_summary_json(&json, &summary)?;
        outputs::write_packing_vtu(&vtu, &result.positions, params.radius)?;
        if !self.quiet {
            writeln!(streams.stderr, "{}", summary.line())?;
        }
        match result.error {
            None => Ok(()),
            Some(e) => Err(anyhow::Error::new(e).context(format!(
                "pack: the pour stopped before the spheres came to rest; the last state is in \
                 `{}` and the summary (with its \"error\") in `{}`",
                csv.display(),
                json.display()
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Wrapper {
        #[command(flatten)]
        pack: PackArgs,
    }

    fn parse(args: &[&str]) -> PackArgs {
        let argv = ["test", "--out", "x"]
            .into_iter()
            .chain(args.iter().copied());
        Wrapper::try_parse_from(argv).unwrap().pack
    }

    #[test]
    fn defaults_are_the_kernels_standard_pour() {
        let args = parse(&[]);
        let material = args.material.material().unwrap();
        assert_eq!(material.density0, 1200.0);
        assert_eq!(args.params(&material), PourParams::standard(1200.0, 1));
        let args = parse(&["--seed", "7", "--type", "a3", "--friction", "0.3"]);
        let material = args.material.material().unwrap();
        let p = args.params(&material);
        assert_eq!((p.seed, p.density), (7, 1500.0));
        assert_eq!((p.friction_particle, p.friction_wall), (0.3, 0.3));
    }

    #[test]
    fn scaled_units_round_once() {
        let mm: Millimetres = "11.3".parse().unwrap();
        assert_eq!((mm.given, mm.si), (11.3, 11.3e-3));
        let mm: Millimetres = "1.13E1".parse().unwrap();
        assert_eq!(mm.si, 11.3e-3);
        let mpa: Megapascals = "0.1".parse().unwrap();
        assert_eq!(mpa.si, 1e5);
        let inf: Millimetres = "inf".parse().unwrap();
        assert_eq!(inf.si, f64::INFINITY);
        assert!("abc".parse::<Millimetres>().is_err());
        assert_eq!(mm.to_string(), "11.3");
        // A number a double cannot hold is refused, not read as 0 or ∞
        // (the number flags' parser), with a hint for a unit.
        for text in ["1e-2147483648", "1e2147483647", "1e400"] {
            assert!(text.parse::<Megapascals>().is_err(), "{text}");
        }
        let e = "1mm".parse::<Millimetres>().unwrap_err();
        assert!(e.contains("the number alone (`1`)"), "{e}");
        // An exponent at the end of i32's range is shifted without
        // overflow (the test profile checks overflow): the value is then
        // scaled in floating point.
        let zero: Megapascals = "0e2147483647".parse().unwrap();
        assert_eq!(zero.si, 0.0);
    }

    #[test]
    fn diameter_scales_the_lattice() {
        let args = parse(&["--diameter-mm", "2", "--die-diameter-mm", "20"]);
        let material = args.material.material().unwrap();
        let p = args.params(&material);
        let s = PourParams::standard(1200.0, 1);
        assert_eq!(p.radius, 1e-3);
        assert_eq!(p.die_radius, 10e-3);
        assert_eq!(p.lattice_spacing, 2.0 * s.lattice_spacing);
        assert_eq!(p.skin, 2.0 * s.skin);
        args.check(&p).unwrap();
        let kernel = p.grid().cells() as f64;
        let estimate = grid_cells(&p, p.fill_height() + 2.0 * p.radius);
        assert!(
            estimate >= kernel && estimate < 1.5 * kernel,
            "{estimate} vs {kernel}"
        );
    }

    #[test]
    fn rejections_name_the_flag() {
        let err = |args: &[&str]| {
            let a = parse(args);
            let e = a
                .material
                .material()
                .and_then(|m| a.check(&a.params(&m)))
                .unwrap_err();
            assert!(crate::error::is_usage_error(&e), "{e:#}");
            format!("{e:#}")
        };
        // Whole-number flags are checked as they are parsed, with the range.
        for bad in ["0", "-3", "1e3", "1.5", "100001"] {
            let argv = ["test", "--out", "x", "--granules", bad];
            let e = Wrapper::try_parse_from(argv).err().unwrap().to_string();
            assert!(e.contains("--granules") && e.contains("1..=100000"), "{e}");
        }
        let e = Wrapper::try_parse_from(["test", "--out", "x", "--seed", "-1"])
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("--seed") && e.contains("0..=18446744073709551615"),
            "{e}"
        );
        assert!(err(&["--die-diameter-mm", "1.5"]).starts_with("`--die-diameter-mm 1.5`"));
        assert!(err(&["--diameter-mm", "-1"]).starts_with("`--diameter-mm -1`"));
        assert!(err(&["--diameter-mm", "0"]).starts_with("`--diameter-mm 0`"));
        assert!(err(&["--diameter-mm", "NaN"]).starts_with("`--diameter-mm NaN`"));
        assert!(err(&["--die-diameter-mm", "inf"]).starts_with("`--die-diameter-mm inf`"));
        assert!(err(&["--youngs-modulus-mpa", "0"]).starts_with("`--youngs-modulus-mpa 0`"));
        assert!(err(&["--max-time-s", "0.1"]).starts_with("`--max-time-s 0.1`"));
        assert!(err(&["--max-time-s", "inf"]).starts_with("`--max-time-s inf`"));
        assert!(err(&["--friction", "-0.1"]).starts_with("`--friction -0.1`"));
        assert!(err(&["--eta0", "0.1"]).starts_with("`--eta0 0.1` rejected"));
        assert!(err(&["--true-density-kg-m3", "0"]).starts_with("`--true-density-kg-m3 0`"));
        let tall = err(&["--granules", "100000"]);
        assert!(
            tall.contains("do not fit") && tall.contains("`--granules`"),
            "{tall}"
        );
        let wide = err(&["--die-diameter-mm", "1e5"]);
        assert!(wide.contains("too wide"), "{wide}");
    }
}
