//! `granbed-cli point`: one material point driven along a deformation path
//! (the kernel's [`MaterialPoint`]), its history written as CSV, one row per
//! step: the tool to calibrate material parameters with.

use core::fmt;
use std::path::PathBuf;

use anyhow::Context as _;
use clap::{Args, ValueEnum};
use granbed_kernel::constitutive::UpdateOptions;
use granbed_kernel::material_point::{LoadPath, MaterialPoint, PointSample};
use granbed_kernel::tensor::{self, XX, XY, XZ, YY, YZ, ZZ};

use crate::csv::{CsvWriter, Field};
use crate::error::input_error;
use crate::material_args::MaterialArgs;
use crate::numbers::Shown as _;
use crate::output::{Output, Streams};

/// Largest `--steps`.
pub const MAX_STEPS: u32 = 10_000_000;

/// The CSV header of `point` (units in the names; stresses in Pa).
pub const COLUMNS: [&str; 24] = [
    "step",
    "strain",
    "f_xx",
    "f_yy",
    "f_zz",
    "f_xy",
    "j",
    "tau_xx",
    "tau_yy",
    "tau_zz",
    "tau_yz",
    "tau_xz",
    "tau_xy",
    "sigma_xx",
    "sigma_yy",
    "sigma_zz",
    "sigma_yz",
    "sigma_xz",
    "sigma_xy",
    "pressure_pa",
    "von_mises_pa",
    "eta",
    "plastic",
    "iterations",
];

/// The output description shown at the end of `point --help`.
const OUTPUT_HELP: &str = "\
Output: CSV with a header row and one row per step n = 0..=steps (row 0 is the
unloaded state), the point driven to strain·n/steps in one increment per step:
  step              step number n
  strain            path strain at the end of the step
  f_xx f_yy f_zz    diagonal of the deformation gradient F
  f_xy              shear component of F (γ on the shear path)
  j                 volume ratio J = det F
  tau_*             Kirchhoff stress τ, Pa (tension positive)
  sigma_*           Cauchy stress σ = τ/J, Pa
  pressure_pa       Kirchhoff pressure −tr τ/3, Pa (compression positive)
  von_mises_pa      von Mises stress of σ, Pa
  eta               relative density η = η0/J
  plastic           1 if the step was plastic, else 0
  iterations        return-map iterations of the step
Floats are written round-trip exact (shortest decimal that parses back to the
same f64). A summary line goes to stderr. If the kernel fails, the rows so far
are kept and the error names the step and strain.

Exit status: 0 success, 1 runtime failure (kernel or I/O error), 2 usage or
validation error.";

/// The deformation path of `--path` (see the kernel's
/// [`granbed_kernel::material_point`] docs).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathArg {
    /// Equal compression in all directions; strain = volume reduction 1 − J
    Hydrostatic,
    /// Axial (z) compression without lateral strain, F = diag(1, 1, 1 − strain)
    UniaxialStrain,
    /// Axial (z) compression with stress-free lateral faces, F = diag(λ, λ, 1 − strain), λ solved
    /// for τ_xx = τ_yy = 0
    UniaxialStress,
    /// Simple shear in the x–y plane, F = 1 + γ e_x ⊗ e_y; strain = γ
    Shear,
}

impl PathArg {
    /// The value as written on the command line, e.g. `uniaxial-strain`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hydrostatic => "hydrostatic",
            Self::UniaxialStrain => "uniaxial-strain",
            Self::UniaxialStress => "uniaxial-stress",
            Self::Shear => "shear",
        }
    }

    /// What `--strain` means on this path.
    pub fn strain_meaning(self) -> &'static str {
        match self {
            Self::Hydrostatic => "volume reduction 1 − J",
            Self::UniaxialStrain | Self::UniaxialStress => "axial nominal strain",
            Self::Shear => "shear strain γ",
        }
    }
}

impl fmt::Display for PathArg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl From<PathArg> for LoadPath {
    fn from(p: PathArg) -> Self {
        match p {
            PathArg::Hydrostatic => Self::Hydrostatic,
            PathArg::UniaxialStrain => Self::UniaxialStrain,
            PathArg::UniaxialStress => Self::UniaxialStress,
            PathArg::Shear => Self::Shear,
        }
    }
}

/// Options of `granbed-cli point`.
#[derive(Args, Debug, Clone, PartialEq)]
#[command(after_long_help = OUTPUT_HELP)]
pub struct PointArgs {
    /// Deformation path.
    #[arg(long, value_enum)]
    pub path: PathArg,

    /// Final strain, dimensionless, compression positive; its meaning depends
    /// on --path: hydrostatic = volume reduction 1 − J, uniaxial-* = axial
    /// nominal strain, shear = shear strain γ. Allowed open ranges:
    /// −10 < strain < 1 (hydrostatic, uniaxial-*), −10 < γ < 10 (shear).
    #[arg(value_parser = crate::numbers::real, long, default_value_t = 0.3, allow_negative_numbers = true)]
    pub strain: f64,

    /// Number of equal strain increments (1 to 10000000); the CSV has
    /// steps + 1 rows.
    #[arg(long, default_value_t = 1000, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u32>(1, MAX_STEPS as u64))]
    pub steps: u32,

    /// CSV output file; `-` or absent writes to stdout.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,

    /// Use the published return map literally, without the volume-drift fix
    /// (shows the spurious dilatation under shear).
    #[arg(long)]
    pub literal_return: bool,

    /// Granule type and parameter overrides.
    #[command(flatten)]
    pub material: MaterialArgs,
}

/// Tallies of a run for the stderr summary.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Summary {
    /// Steps taken after the unloaded row 0.
    steps: u32,
    /// Plastic steps.
    plastic: u32,
    /// Largest return-map iteration count of a step.
    max_iterations: u32,
    /// Kirchhoff pressure of the last row, Pa.
    pressure_pa: f64,
    /// Relative density of the last row.
    eta: f64,
    /// The first step and path strain at which η reached 1 (the pores
    /// closed: from there the solid itself is compressed).
    dense_from: Option<(u32, f64)>,
}

impl Summary {
    fn add(&mut self, n: u32, strain: f64, s: &PointSample) {
        self.steps = n;
        if s.info.eta >= 1.0 && self.dense_from.is_none() {
            self.dense_from = Some((n, strain));
        }
        self.plastic += u32::from(s.info.plastic);
        self.max_iterations = self.max_iterations.max(s.info.iterations);
        self.pressure_pa = tensor::pressure(&s.tau);
        self.eta = s.info.eta;
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} steps, {} plastic, max {} iterations, final pressure {:.6e} Pa, final eta {:.6}",
            self.steps,
            self.plastic,
            self.max_iterations,
            // + 0.0: a pressure of -0 (no stress) is said as 0.
            self.pressure_pa + 0.0,
            self.eta
        )
    }
}

/// The CSV cells of one sample (order of [`COLUMNS`]).
fn row(n: u32, s: &PointSample) -> [Field; COLUMNS.len()] {
    let f = &s.f;
    let tau = &s.tau;
    let j = tensor::det_mat(f);
    let sigma = tensor::cauchy_from_kirchhoff(tau, j);
    let r = Field::Real;
    [
        Field::from(n),
        r(s.strain),
        r(f[(0, 0)]),
        r(f[(1, 1)]),
        r(f[(2, 2)]),
        r(f[(0, 1)]),
        r(j),
        r(tau[XX]),
        r(tau[YY]),
        r(tau[ZZ]),
        r(tau[YZ]),
        r(tau[XZ]),
        r(tau[XY]),
        r(sigma[XX]),
        r(sigma[YY]),
        r(sigma[ZZ]),
        r(sigma[YZ]),
        r(sigma[XZ]),
        r(sigma[XY]),
        r(tensor::pressure(tau)),
        r(tensor::von_mises(&sigma)),
        r(s.info.eta),
        Field::from(s.info.plastic),
        Field::from(s.info.iterations),
    ]
}

impl PointArgs {
    /// Rejects a `--strain` outside the open range of the path.
    pub fn check_strain(&self) -> anyhow::Result<()> {
        let (lo, hi) = LoadPath::from(self.path).strain_range();
        if self.strain > lo && self.strain < hi {
            Ok(())
        } else {
            Err(input_error(format!(
                "`--strain {}` is outside the range of `--path {}`: allowed is the open range \
                 {lo} < strain < {hi} (strain = {})",
                self.strain,
                self.path,
                self.path.strain_meaning()
            )))
        }
    }

    /// Path strain at the end of step `n` of `--steps` (exactly `--strain`
    /// at the last step).
    fn strain_at(&self, n: u32) -> f64 {
        if n == self.steps {
            self.strain
        } else {
            self.strain * f64::from(n) / f64::from(self.steps)
        }
    }

    /// Validates the options, drives the point and writes the CSV, then the
    /// summary line to stderr.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        let mat = self.material.material()?;
        self.check_strain()?;
        let opts = UpdateOptions {
            volume_fix: !self.literal_return,
            ..UpdateOptions::default()
        };
        let mut point = MaterialPoint::new(mat, opts, self.path.into());
        let out = Output::open(self.out.as_deref(), &mut *streams.stdout)?;
        let dest = out.name().to_owned();
        let write_err = || format!("cannot write to {dest}");
        let mut csv = CsvWriter::new(out, &COLUMNS).with_context(write_err)?;
        let mut summary = Summary::default();
        for n in 0..=self.steps {
            let strain = self.strain_at(n);
            match point.step_to(strain) {
                Ok(sample) => {
                    csv.write_row(&row(n, &sample)).with_context(write_err)?;
                    summary.add(n, strain, &sample);
                }
                Err(e) => {
                    let rows = csv.rows();
                    csv.into_inner().finish()?;
                    writeln!(streams.stderr, "point: stopped: {summary}")?;
                    return Err(anyhow::Error::new(e).context(format!(
                        "kernel failed at step {n} of {} (strain {strain}); the {rows} rows \
                         before it (steps 0 to {}) were written to {dest}",
                        self.steps,
                        i64::from(n) - 1
                    )));
                }
            }
        }
        csv.into_inner().finish()?;
        writeln!(
            streams.stderr,
            "point: type {} on {} to strain {}: {summary}",
            self.material.granule_type,
            self.path,
            self.strain.shown()
        )?;
        if let Some((n, strain)) = summary.dense_from {
            writeln!(
                streams.stderr,
                "note: eta reached 1 at step {n} (strain {}): the pores are closed and \
                 from there the solid itself is compressed (eta = eta0/J counts its elastic \
                 volume change; the yield surface is von Mises's)",
                strain.shown()
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_names_are_the_command_line_values() {
        for p in PathArg::value_variants() {
            assert_eq!(PathArg::from_str(p.name(), false), Ok(*p));
        }
    }
}
