//! The single-granule platen experiment behind the browser handle, in plain
//! Rust (no JavaScript types), so that it is tested natively: inputs and
//! their validation, stepping in chunks, the samples, σ_est / σ_y,eff0 (the
//! kernel's `analysis::granule`, as `granbed-cli granule`'s summary) and
//! the CSV (the CLI's `force_displacement.csv` format, byte for byte).

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use core::fmt::Write as _;

use granbed_host::OwnedReference;
use granbed_kernel::Real;
use granbed_kernel::analysis::fit::LineFit;
use granbed_kernel::analysis::granule::initial_effective_yield_stress;
use granbed_kernel::analysis::quasi_static::Certificate;
use granbed_kernel::material::{GranuleType, MaterialParams, ParamError};
use granbed_kernel::scene::platens::{
    PlatenParams, PlatenSample, PlatenScene, SAMPLE_COLUMNS, SceneError,
};

use crate::mesh::{give_back, octant_mesh, take_buffers};

pub use granbed_kernel::analysis::granule::FIT_STRAIN_RANGE;

/// The standard granule diameter, m (the CLI's 1 mm granule).
pub const STANDARD_DIAMETER_M: Real = 1.0e-3;

/// Allowed granule diameters, m.
pub const DIAMETER_RANGE_M: [Real; 2] = [1.0e-6, 1.0];

/// [`DIAMETER_RANGE_M`] as the page states it, in mm.
pub const DIAMETER_RANGE_MM_TEXT: &str = "0.001 <= d <= 1000 mm";

/// The granule diameter `d_mm`, given in mm (the page's unit), in m. Out of
/// [`DIAMETER_RANGE_M`] (NaN included) the error names `diameter_mm` and
/// the range in mm, so that a user who typed millimetres reads
/// millimetres.
pub fn diameter_m_of_mm(d_mm: Real) -> Result<Real, Error> {
    let d = d_mm * 1.0e-3;
    if (DIAMETER_RANGE_M[0]..=DIAMETER_RANGE_M[1]).contains(&d) {
        Ok(d)
    } else {
        Err(Error::invalid("diameter_mm", d_mm, DIAMETER_RANGE_MM_TEXT))
    }
}

/// The material fields a caller may override, in the names of
/// [`MaterialParams`].
pub const MATERIAL_FIELDS: [&str; 8] = [
    "yield_stress_pa",
    "eta0",
    "youngs_modulus_pa",
    "poisson_ratio",
    "cp",
    "eta_c",
    "friction",
    "true_density_kg_m3",
];

/// A human label of an input field, for error messages.
pub fn field_label(field: &str) -> &'static str {
    match field {
        "yield_stress_pa" => "yield stress σy (Pa)",
        "eta0" => "initial relative density η0",
        "youngs_modulus_pa" => "Young's modulus E (Pa)",
        "poisson_ratio" => "Poisson's ratio ν",
        "cp" => "yield-surface constant cp",
        "eta_c" => "critical relative density ηc",
        "friction" => "friction coefficient μ",
        "true_density_kg_m3" => "true density (kg/m³)",
        "diameter_m" => "granule diameter d (m)",
        "diameter_mm" => "granule diameter d (mm)",
        "mesh" => "mesh level",
        "type" => "granule type",
        _ => "parameter",
    }
}

/// What the caller asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// The preset the material starts from.
    pub granule_type: GranuleType,
    /// Overrides of [`MATERIAL_FIELDS`], in that order.
    pub overrides: [Option<Real>; 8],
    /// Granule diameter d, m.
    pub diameter_m: Real,
    /// Mesh level n×m of the full sphere (the octant is simulated).
    pub mesh: (u32, u32),
}

impl Inputs {
    /// The standard experiment of `granule_type`: the 1 mm granule, the
    /// 8x2 (1280-hex) sphere, no overrides.
    pub fn standard(granule_type: GranuleType) -> Self {
        Self {
            granule_type,
            overrides: [None; 8],
            diameter_m: STANDARD_DIAMETER_M,
            mesh: (8, 2),
        }
    }

    /// Sets the override of `field` (one of [`MATERIAL_FIELDS`]); false if
    /// there is no such field.
    pub fn set(&mut self, field: &str, value: Real) -> bool {
        match MATERIAL_FIELDS.iter().position(|f| *f == field) {
            Some(i) => {
                self.overrides[i] = Some(value);
                true
            }
            None => false,
        }
    }

    /// The preset with the overrides applied (not validated).
    pub fn material_params(&self) -> MaterialParams {
        let mut p = self.granule_type.params();
        let fields = [
            &mut p.yield_stress_pa,
            &mut p.eta0,
            &mut p.youngs_modulus_pa,
            &mut p.poisson_ratio,
            &mut p.cp,
            &mut p.eta_c,
            &mut p.friction,
            &mut p.true_density_kg_m3,
        ];
        for (field, value) in fields.into_iter().zip(self.overrides) {
            if let Some(v) = value {
                *field = v;
            }
        }
        p
    }
}

/// A range as the kernel writes it (`-1 < nu < 0.5`, `0 <= mu <= 10`) with
/// the symbols the page labels its fields with (`-1 < ν < 0.5`,
/// `0 ≤ μ ≤ 10`): word by word, so `E` and the numbers stay.
pub fn readable_range(allowed: &str) -> String {
    allowed
        .split(' ')
        .map(|word| match word {
            "<=" => "≤",
            ">=" => "≥",
            "nu" => "ν",
            "mu" => "μ",
            "eta_c" => "ηc",
            "eta0" => "η0",
            "rho" => "ρ",
            "kg/m3" => "kg/m³",
            other => other,
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// A rejected input or a failed run: a readable message and, for a rejected
/// parameter, the field, the value and the allowed range.
#[derive(Clone, Debug, PartialEq)]
pub struct Error {
    /// The whole message.
    pub message: String,
    /// The input field (a [`MATERIAL_FIELDS`] name, `diameter_m`, `mesh`,
    /// `type`, or a field of the experiment), if an input was rejected.
    pub field: Option<&'static str>,
    /// The rejected value, if numeric.
    pub value: Option<Real>,
    /// The allowed range.
    pub allowed: Option<&'static str>,
    /// Every refused input field, `field` first: more than one when
    /// several inputs were out of range at once ([`Error::all`]).
    pub fields: Vec<&'static str>,
}

impl Error {
    /// A rejected input `field` = `value`, allowed `allowed` (the kernel's
    /// ASCII text, kept as it is in [`Error::allowed`]; the message shows it
    /// with the page's symbols, [`readable_range`]).
    pub fn invalid(field: &'static str, value: Real, allowed: &'static str) -> Self {
        Self {
            message: format!(
                "{} = {} is not allowed: the allowed range is {}",
                field_label(field),
                granbed_host::text::short(value),
                readable_range(allowed)
            ),
            field: Some(field),
            value: Some(value),
            allowed: Some(allowed),
            fields: alloc::vec![field],
        }
    }

    /// The refusals `errors` as one error, `None` if there are none: their
    /// messages a line each, the first one's field, value and range, and
    /// every field in [`Error::fields`].
    pub fn all(errors: Vec<Error>) -> Option<Self> {
        let message = errors
            .iter()
            .map(|e| e.message.as_str())
            .collect::<Vec<_>>()
            .join("\n");
        let fields = errors
            .iter()
            .flat_map(|e| e.fields.iter().copied())
            .collect();
        let first = errors.into_iter().next()?;
        Some(Self {
            message,
            fields,
            ..first
        })
    }

    /// A message without a field.
    pub fn other(message: String) -> Self {
        Self {
            message,
            field: None,
            value: None,
            allowed: None,
            fields: Vec::new(),
        }
    }
}

impl From<ParamError> for Error {
    fn from(e: ParamError) -> Self {
        Self::invalid(e.field, e.value, e.allowed)
    }
}

impl From<SceneError> for Error {
    fn from(e: SceneError) -> Self {
        match e {
            SceneError::InvalidParameter {
                field,
                value,
                allowed,
            } => Self::invalid(field, value, allowed),
            other => Self::other(format!("the simulation stopped: {other}")),
        }
    }
}

/// Every input of `inputs` out of its range, each as [`Experiment::new`]
/// names it: the material's fields ([`MaterialParams::refusals`]) in the
/// order of [`MATERIAL_FIELDS`], the page's form, then the diameter. Empty
/// when all are in range. For a page that marks every bad field at once
/// and focuses the first.
pub fn refusals(inputs: &Inputs) -> Vec<Error> {
    let mut material = inputs.material_params().refusals();
    material.sort_unstable_by_key(|e| MATERIAL_FIELDS.iter().position(|f| *f == e.field));
    let mut out: Vec<Error> = material.into_iter().map(Error::from).collect();
    let d = inputs.diameter_m;
    if !(DIAMETER_RANGE_M[0]..=DIAMETER_RANGE_M[1]).contains(&d) {
        out.push(Error::invalid("diameter_m", d, "1e-6 <= d <= 1 m"));
    }
    out
}

/// σ_est and the fit behind it, σ_y,eff0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measures {
    /// σ_est = 4/(πd)·dF/dx over [`FIT_STRAIN_RANGE`] ([`PlatenSample::sigma_est`]), Pa (`None` with
    /// fewer than two samples there).
    pub sigma_est_pa: Option<Real>,
    /// The least-squares fit of F(x).
    pub fit: Option<LineFit>,
    /// σ_y,eff0 = √a2(η0)·σ_y, Pa.
    pub sigma_eff0_pa: Real,
    /// The quasi-static certificate over the second half of the samples
    /// (the CLI summary's `quasi_static`, without the rate check).
    pub quasi_static: Certificate,
}

/// A running (or finished) experiment.
pub struct Experiment {
    scene: Option<PlatenScene<'static>>,
    mesh: &'static OwnedReference,
    inputs: Inputs,
    params: PlatenParams,
    diameter: Real,
    samples: Vec<PlatenSample>,
    error: Option<Error>,
}

impl Experiment {
    /// Validates `inputs` and sets up the standard platen experiment
    /// (octant, 5 mm/s, ξ = 0.5, to 40 % strain: `PlatenParams::standard`,
    /// exactly what `granbed-cli granule` runs by default).
    pub fn new(inputs: Inputs) -> Result<Self, Error> {
        if let Some(e) = Error::all(refusals(&inputs)) {
            return Err(e);
        }
        let material = inputs.material_params().validate()?;
        let d = inputs.diameter_m;
        let (n, m) = inputs.mesh;
        let mesh = octant_mesh(0.5 * d, n, m).ok_or_else(|| {
            Error::other(format!(
                "mesh level {n}x{m} rejected: n must be even in 2..=64 and m in 1..=32 \
                 (field `mesh`)"
            ))
        })?;
        let params = PlatenParams::standard(material);
        let points = params.elements.points_per_element();
        let buffers = take_buffers(mesh, points);
        // On failure the scene has consumed the buffers: they are leaked,
        // which happens only for an unstable initial step.
        let mut scene = PlatenScene::new(params, mesh.view(), buffers)?;
        let first = scene.sample();
        Ok(Self {
            diameter: scene.diameter(),
            scene: Some(scene),
            mesh,
            inputs,
            params,
            samples: alloc::vec![first],
            error: None,
        })
    }

    /// Advances up to `max_steps` steps (fewer at the end or on an error).
    /// Returns the error that stopped the run, once; afterwards the run is
    /// finished and keeps its samples.
    pub fn step(&mut self, max_steps: u32) -> Result<(), Error> {
        let Some(scene) = self.scene.as_mut() else {
            return Ok(());
        };
        for _ in 0..max_steps {
            if scene.finished() {
                break;
            }
            match scene.step() {
                Ok(Some(sample)) => self.samples.push(sample),
                Ok(None) => {}
                Err(e) => {
                    let e = Error::from(e);
                    self.error = Some(e.clone());
                    self.release();
                    return Err(e);
                }
            }
        }
        Ok(())
    }

    fn release(&mut self) {
        if let Some(scene) = self.scene.take() {
            give_back(scene.into_buffers());
        }
    }

    /// True once the final strain is reached or an error stopped the run.
    pub fn finished(&self) -> bool {
        self.scene.as_ref().is_none_or(PlatenScene::finished)
    }

    /// The error that stopped the run, if any.
    pub fn error(&self) -> Option<&Error> {
        self.error.as_ref()
    }

    /// Current strain x/d (that of the last sample once stopped).
    pub fn strain(&self) -> Real {
        match &self.scene {
            Some(s) => s.strain(),
            None => self.samples.last().map_or(0.0, |s| s.strain),
        }
    }

    /// Fraction of the final strain reached, 0…1.
    pub fn progress(&self) -> Real {
        if self.finished() {
            return 1.0;
        }
        (self.strain() / self.params.final_strain).clamp(0.0, 1.0)
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        match &self.scene {
            Some(s) => s.steps(),
            None => self.samples.last().map_or(0, |s| s.steps),
        }
    }

    /// The samples so far: t = 0, then one per 0.5 % strain.
    pub fn samples(&self) -> &[PlatenSample] {
        &self.samples
    }

    /// The inputs.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// The experiment's parameters.
    pub fn params(&self) -> &PlatenParams {
        &self.params
    }

    /// The simulated octant mesh.
    pub fn mesh(&self) -> &'static OwnedReference {
        self.mesh
    }

    /// Current node positions (the reference positions once stopped), m.
    pub fn positions(&self) -> &[[Real; 3]] {
        match &self.scene {
            Some(s) => s.positions(),
            None => &self.mesh.positions,
        }
    }

    /// The granule diameter d that strains are measured against (the
    /// scene's: twice the mesh's top height), m.
    pub fn diameter(&self) -> Real {
        self.diameter
    }

    /// σ_est (fitted over the samples so far), σ_y,eff0 — what
    /// `granbed-cli granule` writes to `summary.json` as `sigma_est_pa`,
    /// `slope_n_per_m`, … and `sigma_eff0_pa`.
    pub fn measures(&self) -> Measures {
        let fit = PlatenSample::sigma_est(
            &self.samples,
            self.diameter(),
            self.params.output_strain_interval,
        );
        Measures {
            sigma_est_pa: fit.map(|s| s.sigma_pa),
            fit: fit.map(|s| s.fit),
            sigma_eff0_pa: initial_effective_yield_stress(&self.params.material.params),
            quasi_static: PlatenSample::certificate(&self.samples, self.params.symmetry, None),
        }
    }

    /// The samples as CSV, the CLI's `force_displacement.csv` byte for byte.
    pub fn csv(&self) -> String {
        let mut out = String::new();
        out.push_str(&SAMPLE_COLUMNS.map(|c| c.0).join(",")); // the CLI's header
        out.push('\n');
        for s in &self.samples {
            let reals = s.values();
            for x in reals {
                write_real(&mut out, x);
                out.push(',');
            }
            let _ = writeln!(out, "{}", s.steps);
        }
        out
    }
}

impl Drop for Experiment {
    fn drop(&mut self) {
        self.release();
    }
}

/// Writes `x` as the CLI's CSV does: the shortest round-trip decimal,
/// exponent form outside [1e-4, 1e15).
fn write_real(out: &mut String, x: Real) {
    let a = x.abs();
    let _ = if a == 0.0 || !a.is_finite() || (1.0e-4..1.0e15).contains(&a) {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    };
}
