//! The work-precision study (issue #8): each numerical setting changed
//! alone from the default and compared with a reference run, for one
//! granule between platens (here) or a small bed ([`super::bed_small`]).
//!
//! * Error measures: the relative L2 distance of the load curve from the
//!   reference's — the platen force F(C) over 2 % ≤ C ≤ 40 % (granule), the
//!   upper-punch pressure P(C) over 2 % ≤ C ≤ the final strain (bed); both
//!   interpolated linearly onto a 0.5 % grid — and the relative errors of
//!   σ_est (granule) or of Kawakita's a and 1/b (bed).
//! * Cost: the wall time of the run (stepping and sampling; not the mesh
//!   generation or the pour) and its steps.
//! * A setting is on the Pareto front when no other run is faster with no
//!   error measure larger (the curve error and σ_est's, or Kawakita's a
//!   and 1/b: a user reads all of them, so a setting that is faster but
//!   moves σ_est more is another trade, not a better one).
//!
//! Mass scaling F multiplies the granule's masses (the octant scene has no
//! gravity), so the stable step grows by √F and the damping, a fraction of
//! the lowest mode's critical value, follows.

use std::path::Path;

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::granule::forces::ElementKind;
use granbed_kernel::material::{GranuleType, Material};
use granbed_kernel::scene::platens::{PlatenParams, PlatenSample, STANDARD_MASS_SCALING};
use plotters::prelude::*;

use super::{StudyScene, WorkPrecisionArgs};
use crate::csv::{CsvWriter, Field};
use crate::granule::GRANULE_RADIUS_M;
use crate::granule::run::run_platens;
use crate::material_args::MaterialArgs;
use crate::model::{MeshLevel, OwnedReference};
use crate::output::{Streams, create_file, finish_file, write_text};

/// The table of the study.
pub const CSV_FILE: &str = "work_precision.csv";
/// The diagram: wall time against each setting's largest error, log-log.
pub const SVG_FILE: &str = "work_precision.svg";

/// Columns of [`CSV_FILE`].
pub const COLUMNS: [&str; 26] = [
    "setting",
    "seed",
    "mesh_n",
    "mesh_m",
    "element",
    "hourglass_kappa",
    "time_step_safety",
    "mass_scaling",
    "selective_mass_scaling",
    "speed_factor",
    "sweep_tolerance",
    "hold_constraints",
    "contact_search_interval",
    "time_step_floor",
    "steps",
    "wall_time_s",
    "sigma_est_pa",
    "kawakita_a",
    "kawakita_inv_b_pa",
    "error_curve_l2",
    "error_sigma_est",
    "error_kawakita_a",
    "error_kawakita_inv_b",
    "reference",
    "pareto",
    "within_spread",
];

/// Strain window of the granule's force-curve error.
const GRANULE_ERROR_STRAINS: [Real; 2] = [0.02, 0.4];
/// Grid step of the force-curve error.
const ERROR_STEP: Real = 0.005;

/// One run's numerical settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    /// A short name (the CSV's first column).
    pub name: &'static str,
    /// Mesh level.
    pub mesh: MeshLevel,
    /// Element.
    pub element: ElementKind,
    /// Hourglass coefficient κ (one-point element).
    pub kappa: Real,
    /// Safety factor on the stable step.
    pub safety: Real,
    /// Mass scaling F ≥ 1.
    pub mass_scaling: Real,
    /// The mass scaling acts on the deformational modes only (bed; a
    /// granule between platens has no free rigid modes, so there it is
    /// uniform scaling either way).
    pub selective_mass: bool,
    /// Platen or punch speed as a multiple of the scene's.
    pub speed_factor: Real,
    /// Contact-sweep tolerance as a fraction of the element size (bed; a
    /// granule between platens has no granule–granule contact).
    pub sweep_tolerance: Real,
    /// Later contact sweeps re-measure the held constraints instead of
    /// searching (bed; the scene's `hold_constraints`).
    pub hold_constraints: bool,
    /// The contact search runs every this many steps (bed; the scene's
    /// `contact_search_interval`; more than 1 needs `hold_constraints`).
    pub contact_search_interval: u32,
    /// Variable mass scaling's floor on the granules' steps (bed; the
    /// scene's `time_step_floor`, 0 = off).
    pub time_step_floor: Real,
}

impl Setting {
    /// `granbed-cli granule`'s defaults on mesh `mesh`.
    pub const fn default_on(mesh: MeshLevel) -> Self {
        Self {
            name: "default",
            mesh,
            element: ElementKind::OnePoint,
            kappa: 0.05,
            safety: 0.9,
            mass_scaling: STANDARD_MASS_SCALING,
            selective_mass: false,
            speed_factor: 1.0,
            sweep_tolerance: crate::bed::run::SWEEP_TOLERANCE_REL,
            hold_constraints: false,
            contact_search_interval: 1,
            time_step_floor: 0.0,
        }
    }

    /// The setting with another name.
    pub const fn named(mut self, name: &'static str) -> Self {
        self.name = name;
        self
    }

    /// The element's name as the CSV and the bed scene spell it.
    pub fn element_name(&self) -> &'static str {
        crate::bed::scene::element_name(self.element)
    }
    /// This setting renamed `name` and changed by `f`.
    pub fn with(self, name: &'static str, f: &dyn Fn(&mut Setting)) -> Setting {
        let mut s = self.named(name);
        f(&mut s);
        s
    }
}

/// The reference and the settings of the granule study: the full grid on
/// the standard 8x2 mesh, or the quick one on 4x1.
pub fn granule_grid(quick: bool) -> (Setting, Vec<Setting>) {
    let base = Setting::default_on(if quick {
        MeshLevel::new(4, 1)
    } else {
        MeshLevel::STANDARD
    });
    let with = |name, f: &dyn Fn(&mut Setting)| base.with(name, f);
    let reference = with("reference", &|s| {
        s.mesh = if quick {
            MeshLevel::new(4, 1)
        } else {
            MeshLevel::new(16, 4)
        };
        s.element = ElementKind::FBar;
        s.speed_factor = 0.5;
        s.mass_scaling = 1.0;
    });
    let mut grid = vec![base];
    if !quick {
        grid.extend([
            with("mesh 4x1", &|s| s.mesh = MeshLevel::new(4, 1)),
            with("mesh 12x3", &|s| s.mesh = MeshLevel::new(12, 3)),
            with("mesh 16x4", &|s| s.mesh = MeshLevel::new(16, 4)),
            with("kappa 0.02", &|s| s.kappa = 0.02),
            with("safety 0.5", &|s| s.safety = 0.5),
            with("mass x100", &|s| s.mass_scaling = 100.0),
            with("speed x0.5", &|s| s.speed_factor = 0.5),
            with("fbar", &|s| s.element = ElementKind::FBar),
        ]);
    }
    grid.extend([
        with("kappa 0.1", &|s| s.kappa = 0.1),
        with("safety 0.7", &|s| s.safety = 0.7),
        with("mass x1", &|s| s.mass_scaling = 1.0),
        with("mass x10", &|s| s.mass_scaling = 10.0),
        with("speed x2", &|s| s.speed_factor = 2.0),
    ]);
    (reference, distinct(grid))
}

/// `grid` without the settings equal to an earlier one but for the name
/// (e.g. "mass x10" when the default is ×10: a second run of the same
/// thing).
pub fn distinct(grid: Vec<Setting>) -> Vec<Setting> {
    let mut kept: Vec<Setting> = Vec::with_capacity(grid.len());
    for s in grid {
        if !kept.iter().any(|k| k.named("") == s.named("")) {
            kept.push(s);
        }
    }
    kept
}

/// What one run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The settings.
    pub setting: Setting,
    /// Seed of the pour (bed; 0 for a granule).
    pub seed: u64,
    /// Steps.
    pub steps: u64,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// σ_est, Pa (granule; None if the fit had too few samples).
    pub sigma_est_pa: Option<Real>,
    /// Kawakita a and 1/b in Pa (bed; None without a fit).
    pub kawakita: Option<(Real, Real)>,
    /// The load curve: (strain, mean platen force in N) for a granule,
    /// (strain, upper-punch pressure in Pa) for a bed.
    pub curve: Vec<(Real, Real)>,
    /// Strain window of the curve error.
    pub error_strains: [Real; 2],
}

/// Runs `setting` for `material`.
pub fn run_granule(setting: &Setting, material: &Material) -> anyhow::Result<Measured> {
    let material = *material;
    let mesh = OwnedReference::sphere(GRANULE_RADIUS_M, setting.mesh, true)?;
    let mut p = PlatenParams::standard(material);
    p.elements.kind = setting.element;
    p.elements.hourglass_kappa = setting.kappa;
    p.time_step_safety = setting.safety;
    p.approach_speed_m_s *= setting.speed_factor;
    p.mass_scaling = setting.mass_scaling;
    let result = run_platens(p, &mesh, &mut |_, _| {})
        .map_err(anyhow::Error::new)
        .with_context(|| format!("setting `{}`", setting.name))?;
    if let Some(e) = result.error {
        anyhow::bail!("setting `{}`: the run failed: {e}", setting.name);
    }
    let curve: Vec<(Real, Real)> = result
        .samples
        .iter()
        .map(|s| (s.strain, s.mean_force()))
        .collect();
    let sigma_est_pa =
        PlatenSample::sigma_est(&result.samples, result.diameter_m, p.output_strain_interval)
            .map(|s| s.sigma_pa);
    Ok(Measured {
        setting: *setting,
        seed: 0,
        steps: result.steps,
        wall_time_s: result.wall_time_s,
        sigma_est_pa,
        kawakita: None,
        curve,
        error_strains: GRANULE_ERROR_STRAINS,
    })
}

/// `curve` (sorted by strain) at strain `c`, linearly interpolated; None
/// outside its range.
fn at(curve: &[(Real, Real)], c: Real) -> Option<Real> {
    let k = curve.partition_point(|p| p.0 < c);
    let hi = curve.get(k)?;
    if hi.0 == c || k == 0 {
        return (hi.0 == c).then_some(hi.1);
    }
    let lo = curve[k - 1];
    Some(lo.1 + (hi.1 - lo.1) * (c - lo.0) / (hi.0 - lo.0))
}

/// Relative L2 distance of `curve` from `reference` on the error grid over
/// `window` (strains); None if either does not cover it.
pub fn curve_error(
    curve: &[(Real, Real)],
    reference: &[(Real, Real)],
    window: [Real; 2],
) -> Option<Real> {
    let n = ((window[1] - window[0]) / ERROR_STEP).round() as usize;
    let (mut diff, mut norm) = (0.0, 0.0);
    for i in 0..=n {
        // The last point is the window's end itself (0.02 + 56 × 0.005
        // rounds above 0.3).
        let c = (window[0] + ERROR_STEP * i as Real).min(window[1]);
        let (f, r) = (at(curve, c)?, at(reference, c)?);
        diff += (f - r) * (f - r);
        norm += r * r;
    }
    (norm > 0.0).then(|| (diff / norm).sqrt())
}

/// The errors of one run against another (NaN where a figure is missing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Relative L2 distance of the load curves.
    pub curve: Real,
    /// Relative error of σ_est.
    pub sigma: Real,
    /// Relative error of Kawakita's a.
    pub kawakita_a: Real,
    /// Relative error of Kawakita's 1/b.
    pub kawakita_inv_b: Real,
}

/// |x − r|/|r| (NaN if either is missing; ∞ for r = 0 and x ≠ 0).
pub fn relative_error(x: Option<Real>, r: Option<Real>) -> Real {
    match (x, r) {
        (Some(x), Some(r)) => (x - r).abs() / r.abs(),
        _ => Real::NAN,
    }
}

impl Errors {
    /// The errors of `m` against `reference`.
    pub fn of(m: &Measured, reference: &Measured) -> Self {
        let rel = relative_error;
        let (a, inv_b) = (m.kawakita.map(|k| k.0), m.kawakita.map(|k| k.1));
        let (ra, rinv_b) = (
            reference.kawakita.map(|k| k.0),
            reference.kawakita.map(|k| k.1),
        );
        Self {
            curve: curve_error(&m.curve, &reference.curve, reference.error_strains)
                .unwrap_or(Real::NAN),
            sigma: rel(m.sigma_est_pa, reference.sigma_est_pa),
            kawakita_a: rel(a, ra),
            kawakita_inv_b: rel(inv_b, rinv_b),
        }
    }

    /// The four figures in a fixed order: curve, σ_est, Kawakita a, 1/b.
    fn figures(&self) -> [Real; 4] {
        [self.curve, self.sigma, self.kawakita_a, self.kawakita_inv_b]
    }

    /// Errors from figures in the order of [`Errors::figures`].
    fn from_figures([curve, sigma, kawakita_a, kawakita_inv_b]: [Real; 4]) -> Self {
        Self {
            curve,
            sigma,
            kawakita_a,
            kawakita_inv_b,
        }
    }

    /// Figure by figure, `f` of this run's and `other`'s.
    fn combine(&self, other: &Self, f: impl Fn(Real, Real) -> Real) -> Self {
        let (x, o) = (self.figures(), other.figures());
        Self::from_figures(core::array::from_fn(|k| f(x[k], o[k])))
    }

    /// Whether `test` holds for every pair of this run's and `other`'s
    /// figures.
    fn all_pairs(&self, other: &Self, test: impl Fn(Real, Real) -> bool) -> bool {
        self.figures()
            .into_iter()
            .zip(other.figures())
            .all(|(x, o)| test(x, o))
    }

    /// No figure larger than `other`'s, a figure `other` lacks (NaN)
    /// excepted; a figure only `other` has counts against `self`.
    pub fn no_worse_than(&self, other: &Self) -> bool {
        self.all_pairs(other, |x, o| x <= o || o.is_nan())
    }

    /// The larger of each figure, NaN if either lacks it (the largest
    /// error over granule types: a figure missing on one type is missing).
    pub fn max_over(self, o: Self) -> Self {
        self.combine(&o, |a, b| {
            if a.is_nan() || b.is_nan() {
                Real::NAN
            } else {
                a.max(b)
            }
        })
    }

    /// The largest figure this run has (NaN if it has none): the
    /// diagram's abscissa. Of two runs with the same figures, one that the
    /// other is no worse than ([`Errors::no_worse_than`]) never plots left
    /// of it (a figure only one run lacks can break that).
    pub fn largest(&self) -> Real {
        self.figures()
            .into_iter()
            .filter(|x| !x.is_nan())
            .reduce(Real::max)
            .unwrap_or(Real::NAN)
    }

    /// Every figure within `spread`'s; a figure either lacks (NaN) is not
    /// judged — unlike [`Errors::no_worse_than`], where a figure only the
    /// other run has counts against this one.
    pub fn within(&self, spread: &Self) -> bool {
        self.all_pairs(spread, |x, s| x <= s || x.is_nan() || s.is_nan())
    }

    /// The larger of each figure (NaN-ignoring).
    pub fn max(self, o: Self) -> Self {
        self.combine(&o, Real::max)
    }
}

/// One row of the table.
pub struct Row<'a> {
    /// The run.
    pub m: &'a Measured,
    /// Its errors against the reference.
    pub errors: Errors,
    /// This is the reference run.
    pub reference: bool,
    /// On the Pareto front of wall time against the errors: no other run
    /// is faster with no error larger ([`Errors::no_worse_than`]).
    pub pareto: bool,
    /// Every error is within the run-to-run spread of the default over
    /// poured beds (bed study; None for a granule): [`Errors::within`].
    pub within_spread: Option<bool>,
}

/// The errors of `reference` (zero) and of each of `runs` against it.
pub fn errors_against(reference: &Measured, runs: &[Measured]) -> Vec<Errors> {
    core::iter::once(reference)
        .chain(runs)
        .map(|m| Errors::of(m, reference))
        .collect()
}

/// The rows of `reference` and `runs` with their `errors` (one per row,
/// the reference's first; see [`errors_against`]) and the Pareto flags;
/// `spread` (bed) marks the settings whose errors all stay within it.
pub fn rows<'a>(
    reference: &'a Measured,
    runs: &'a [Measured],
    errors: &[Errors],
    spread: Option<Errors>,
) -> Vec<Row<'a>> {
    let mut rows: Vec<Row<'a>> = core::iter::once(reference)
        .chain(runs)
        .zip(errors)
        .enumerate()
        .map(|(i, (m, &errors))| Row {
            m,
            errors,
            reference: i == 0,
            pareto: false,
            within_spread: spread.map(|s| errors.within(&s)),
        })
        .collect();
    let front: Vec<bool> = rows
        .iter()
        .map(|r| {
            !rows
                .iter()
                .any(|o| o.m.wall_time_s < r.m.wall_time_s && o.errors.no_worse_than(&r.errors))
        })
        .collect();
    for (r, f) in rows.iter_mut().zip(front) {
        r.pareto = f;
    }
    rows
}

/// Writes the table.
pub fn write_csv(path: &Path, rows: &[Row<'_>]) -> anyhow::Result<()> {
    let file = create_file(path)?;
    let mut csv = CsvWriter::new(file, &COLUMNS)?;
    let opt = |x: Option<Real>| Field::Real(x.unwrap_or(Real::NAN));
    for r in rows {
        let s = &r.m.setting;
        csv.write_row(&[
            Field::Text(s.name),
            Field::Int(r.m.seed),
            Field::from(s.mesh.n),
            Field::from(s.mesh.m),
            Field::Text(s.element_name()),
            Field::Real(s.kappa),
            Field::Real(s.safety),
            Field::Real(s.mass_scaling),
            Field::from(s.selective_mass),
            Field::Real(s.speed_factor),
            Field::Real(s.sweep_tolerance),
            Field::from(s.hold_constraints),
            Field::from(s.contact_search_interval),
            Field::Real(s.time_step_floor),
            Field::Int(r.m.steps),
            Field::Real(r.m.wall_time_s),
            opt(r.m.sigma_est_pa),
            opt(r.m.kawakita.map(|k| k.0)),
            opt(r.m.kawakita.map(|k| k.1)),
            Field::Real(r.errors.curve),
            Field::Real(r.errors.sigma),
            Field::Real(r.errors.kawakita_a),
            Field::Real(r.errors.kawakita_inv_b),
            Field::from(r.reference),
            Field::from(r.pareto),
            r.within_spread.map_or(Field::Text(""), Field::from),
        ])
        .with_context(|| format!("cannot write `{}`", path.display()))?;
    }
    finish_file(csv.into_inner(), path)
}

/// The log-log diagram: wall time against each setting's largest error
/// ([`Errors::largest`]: the load curve's, σ_est's, Kawakita's — the
/// measures the Pareto front weighs), one labelled point per setting (the
/// reference, error 0, is left out; red: on the front), and with `spread`
/// (bed) a vertical line at the spread's largest error.
pub fn diagram(
    rows: &[Row<'_>],
    title: &str,
    x_desc: &str,
    spread: Option<Real>,
) -> anyhow::Result<String> {
    let pts: Vec<(&str, f64, f64, bool)> = rows
        .iter()
        .filter(|r| !r.reference && r.errors.largest().is_finite() && r.errors.largest() > 0.0)
        .map(|r| {
            (
                r.m.setting.name,
                r.errors.largest(),
                r.m.wall_time_s.max(1e-3),
                r.pareto,
            )
        })
        .collect();
    let bounds = |v: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = v.fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
        if lo.is_finite() && hi > 0.0 {
            (lo / 2.0)..(hi * 2.0)
        } else {
            1e-4..1.0
        }
    };
    let xr = bounds(&mut pts.iter().map(|p| p.1).chain(spread));
    let yr = bounds(&mut pts.iter().map(|p| p.2));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(xr.log_scale(), yr.clone().log_scale())?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc("wall time, s")
            .draw()?;
        if let Some(x) = spread.filter(|x| *x > 0.0) {
            chart
                .draw_series(LineSeries::new([(x, yr.start), (x, yr.end)], BLACK))?
                .label("run-to-run spread over pours, largest error (within_spread judges each)");
            chart.configure_series_labels().border_style(BLACK).draw()?;
        }
        for (name, x, y, front) in &pts {
            let colour = if *front { RED } else { BLUE };
            chart.draw_series(core::iter::once(Circle::new((*x, *y), 5, colour.filled())))?;
            chart.draw_series(core::iter::once(Text::new(
                name.to_string(),
                (*x, *y),
                ("sans-serif", 14).into_font(),
            )))?;
        }
        root.present()?;
    }
    Ok(svg)
}

/// The study of several types as one: per setting (and for the
/// reference) the summed steps and wall time, and the largest of each
/// error over the types. The title, axis and spread are left empty.
fn over_types(per_type: &[(GranuleType, Measured, Vec<Measured>)]) -> StudyRuns {
    let combine = |ms: &[&Measured]| Measured {
        steps: ms.iter().map(|m| m.steps).sum(),
        wall_time_s: ms.iter().map(|m| m.wall_time_s).sum(),
        sigma_est_pa: None,
        kawakita: None,
        curve: Vec::new(),
        ..ms[0].clone()
    };
    let largest = |es: &mut dyn Iterator<Item = Errors>| {
        es.reduce(Errors::max_over)
            .expect("a study of several types has at least one")
    };
    let references: Vec<&Measured> = per_type.iter().map(|(_, r, _)| r).collect();
    let settings = per_type.first().map_or(0, |(_, _, runs)| runs.len());
    let runs: Vec<Measured> = (0..settings)
        .map(|i| combine(&per_type.iter().map(|(_, _, r)| &r[i]).collect::<Vec<_>>()))
        .collect();
    let mut errors = vec![Errors::of(references[0], references[0])];
    errors.extend((0..settings).map(|i| {
        largest(
            &mut per_type
                .iter()
                .map(|(_, reference, r)| Errors::of(&r[i], reference)),
        )
    }));
    StudyRuns {
        reference: combine(&references),
        runs,
        errors,
        spread: None,
        title: String::new(),
        x_desc: "",
    }
}

/// What a study ran: the reference, the settings, their errors, and (bed)
/// the spread.
pub struct StudyRuns {
    /// The reference run.
    pub reference: Measured,
    /// The settings' runs.
    pub runs: Vec<Measured>,
    /// The errors of the reference (zero) and of each run, in that order.
    pub errors: Vec<Errors>,
    /// The run-to-run spread of the default over poured beds (bed).
    pub spread: Option<Errors>,
    /// The diagram's title.
    pub title: String,
    /// The diagram's x axis.
    pub x_desc: &'static str,
}

/// Prints one finished run of a study.
pub fn say(quiet: bool, what: &str, m: &Measured, streams: &mut Streams<'_>) -> anyhow::Result<()> {
    if !quiet {
        writeln!(
            streams.stderr,
            "study: {what} `{}` (seed {}): {} steps in {:.2} s",
            m.setting.name, m.seed, m.steps, m.wall_time_s
        )?;
    }
    Ok(())
}

impl WorkPrecisionArgs {
    /// Runs the study and writes the table and the diagram.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        if self.types.is_some() && self.scene != StudyScene::Granule {
            return Err(crate::error::InputError(
                "`--types` is for `--scene granule` (the bed study runs --type)".to_owned(),
            )
            .into());
        }
        if self.scene == StudyScene::Granule {
            let bed_only = [
                ("--granules", self.granules.is_some()),
                ("--die-diameter-mm", self.die_diameter_mm.is_some()),
                ("--strain", self.strain.is_some()),
                ("--mesh", self.mesh.is_some()),
                ("--pours", self.pours.is_some()),
            ];
            if let Some((flag, _)) = bed_only.iter().find(|(_, given)| *given) {
                return Err(crate::error::input_error(format!(
                    "`{flag}` is for `--scene bed-small` (the granule study has its own grid)"
                )));
            }
        }
        // Every type's material first: an override one type rejects stops
        // the study before anything runs or is written.
        let types = match &self.types {
            Some(list) => list.0.clone(),
            None => vec![self.material.granule_type],
        };
        let materials = types
            .iter()
            .map(|&granule_type| {
                MaterialArgs {
                    granule_type,
                    ..self.material
                }
                .material()
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        crate::output::create_out_dir(&self.out)?;
        let study = match self.scene {
            StudyScene::Granule => self.granule_study(&types, &materials, streams)?,
            StudyScene::BedSmall => super::bed_small::study(self, streams)?,
        };
        let rows = rows(&study.reference, &study.runs, &study.errors, study.spread);
        write_csv(&self.out.join(CSV_FILE), &rows)?;
        let svg_path = self.out.join(SVG_FILE);
        let svg = diagram(
            &rows,
            &study.title,
            study.x_desc,
            study.spread.map(|s| s.largest()),
        )?;
        write_text(&svg_path, &svg)?;
        if let Some(d) = rows.iter().find(|r| r.m.setting.name == "default") {
            writeln!(
                streams.stderr,
                "study: default: curve error {:.3e}, largest error {:.3e}, {:.2} s; on the \
                 Pareto front: {}{}",
                d.errors.curve,
                d.errors.largest(),
                d.m.wall_time_s,
                if d.pareto { "yes" } else { "no" },
                study.spread.map_or(String::new(), |s| format!(
                    "; run-to-run spread over pours: curve {:.3e}, largest {:.3e}",
                    s.curve,
                    s.largest()
                )),
            )?;
        }
        Ok(())
    }

    /// The single-granule study of `types` (one, or several with
    /// `--types`), each with its validated material.
    fn granule_study(
        &self,
        types: &[GranuleType],
        materials: &[Material],
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<StudyRuns> {
        let (reference_setting, grid) = granule_grid(self.quick);
        let mut per_type = Vec::with_capacity(types.len());
        for (&granule_type, material) in types.iter().zip(materials) {
            let material = *material;
            let reference = run_granule(&reference_setting, &material)?;
            say(self.quiet, "reference", &reference, streams)?;
            let mut runs = Vec::with_capacity(grid.len());
            for s in &grid {
                let m = run_granule(s, &material)?;
                say(self.quiet, "setting", &m, streams)?;
                runs.push(m);
            }
            per_type.push((granule_type, reference, runs));
        }
        let reference_name = format!(
            "{} {}, half speed",
            reference_setting.mesh,
            reference_setting.element_name()
        );
        if let [(t, reference, runs)] = &per_type[..] {
            return Ok(StudyRuns {
                errors: errors_against(reference, runs),
                reference: reference.clone(),
                runs: runs.clone(),
                spread: None,
                title: format!("work-precision, granule {t} (reference: {reference_name})"),
                x_desc: "largest relative error against the reference (F(C) L2, σ_est)",
            });
        }
        for (t, reference, runs) in &per_type {
            let dir = self.out.join(t.name());
            std::fs::create_dir_all(&dir)
                .with_context(|| format!("cannot create `{}`", dir.display()))?;
            let errors = errors_against(reference, runs);
            write_csv(&dir.join(CSV_FILE), &rows(reference, runs, &errors, None))?;
        }
        let names: Vec<&str> = types.iter().map(|t| t.name()).collect();
        Ok(StudyRuns {
            title: format!(
                "work-precision, granule types {} (largest error over the types; reference: \
                 {reference_name})",
                names.join(",")
            ),
            x_desc: "largest relative error over the types (F(C) L2, σ_est)",
            spread: None,
            ..over_types(&per_type)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curve_error_of_a_scaled_curve_is_the_scale() {
        let r: Vec<(Real, Real)> = (0..=100).map(|i| (i as Real * 0.005, i as Real)).collect();
        let c: Vec<(Real, Real)> = r.iter().map(|&(x, y)| (x, 1.1 * y)).collect();
        let e = curve_error(&c, &r, GRANULE_ERROR_STRAINS).unwrap();
        assert!((e - 0.1).abs() < 1e-12, "{e}");
        assert_eq!(curve_error(&r, &r, GRANULE_ERROR_STRAINS), Some(0.0));
        // A curve that stops early does not cover the window.
        assert_eq!(curve_error(&c[..50], &r, GRANULE_ERROR_STRAINS), None);
    }

    fn measured(curve: Vec<(Real, Real)>, kawakita: Option<(Real, Real)>) -> Measured {
        Measured {
            setting: Setting::default_on(MeshLevel::new(4, 1)),
            seed: 1,
            steps: 1,
            wall_time_s: 1.0,
            sigma_est_pa: None,
            kawakita,
            curve,
            error_strains: [0.02, 0.3],
        }
    }

    #[test]
    fn bed_errors_are_relative_to_the_reference_and_spread_takes_the_larger() {
        let r: Vec<(Real, Real)> = (0..=60).map(|i| (i as Real * 0.005, i as Real)).collect();
        let reference = measured(r.clone(), Some((0.5, 2000.0)));
        let off = measured(
            r.iter().map(|&(x, y)| (x, 0.95 * y)).collect(),
            Some((0.55, 1500.0)),
        );
        let e = Errors::of(&off, &reference);
        assert!((e.curve - 0.05).abs() < 1e-12, "{e:?}");
        assert!((e.kawakita_a - 0.1).abs() < 1e-12, "{e:?}");
        assert!((e.kawakita_inv_b - 0.25).abs() < 1e-12, "{e:?}");
        assert!(e.sigma.is_nan());
        // No fit: NaN, and the larger of two errors ignores it.
        let unfit = Errors::of(&measured(r.clone(), None), &reference);
        assert!(unfit.kawakita_a.is_nan() && unfit.curve == 0.0);
        let m = unfit.max(e);
        assert_eq!((m.curve, m.kawakita_a), (e.curve, e.kawakita_a));
        // The spread marks the rows: the reference (0) is within, `off`
        // (5 %) is within a 6 % spread and not within a 4 % one.
        let runs = [off];
        for (spread, within) in [(0.06, true), (0.04, false)] {
            let s = Errors { curve: spread, ..e };
            let rows = rows(
                &reference,
                &runs,
                &errors_against(&reference, &runs),
                Some(s),
            );
            assert_eq!(rows[0].within_spread, Some(true));
            assert_eq!(rows[1].within_spread, Some(within), "spread {spread}");
        }
        // Within the spread means every error: the curve inside, a (10 %)
        // outside a spread of 8 %, is not within; a figure the spread
        // lacks is not judged.
        let a_out = Errors {
            curve: 0.06,
            kawakita_a: 0.08,
            ..e
        };
        let no_fit = Errors {
            curve: 0.06,
            kawakita_a: Real::NAN,
            kawakita_inv_b: Real::NAN,
            ..e
        };
        // A figure the row lacks is not judged either: a run without a
        // Kawakita fit is within a spread whose curve it stays inside.
        let unfit = Errors::of(&measured(r.clone(), None), &reference);
        assert!(unfit.within(&a_out) && !e.within(&a_out));
        for (s, within) in [(a_out, false), (no_fit, true)] {
            let rows = rows(
                &reference,
                &runs,
                &errors_against(&reference, &runs),
                Some(s),
            );
            assert_eq!(rows[1].within_spread, Some(within), "{s:?}");
        }
        // The diagram's abscissa: the largest figure, NaN ones skipped.
        assert_eq!(e.largest(), 0.25);
        assert_eq!(no_fit.largest(), 0.06);
        let none = Errors {
            curve: Real::NAN,
            ..no_fit
        };
        assert!(none.largest().is_nan());
    }

    #[test]
    fn the_front_weighs_every_error_measure() {
        // Granule runs: (wall s, curve error, σ_est error) against a
        // reference with σ_est 100 and the curve y = x.
        let r: Vec<(Real, Real)> = (0..=80)
            .map(|i| (i as Real * 0.005, 1.0 + i as Real))
            .collect();
        let run = |wall: Real, curve_scale: Real, sigma: Real| Measured {
            wall_time_s: wall,
            sigma_est_pa: Some(sigma),
            error_strains: GRANULE_ERROR_STRAINS,
            curve: r.iter().map(|&(x, y)| (x, curve_scale * y)).collect(),
            ..measured(Vec::new(), None)
        };
        let reference = Measured {
            wall_time_s: 100.0,
            ..run(100.0, 1.0, 100.0)
        };
        let runs = [
            run(3.0, 1.035, 101.4), // slow, worse in both: dominated by the next
            run(1.0, 1.032, 100.6), // fast and accurate
            run(0.3, 1.026, 102.0), // faster, better curve, worse σ_est: on the front too
            run(0.5, 1.030, 102.5), // dominated by the run above
        ];
        let rows = rows(&reference, &runs, &errors_against(&reference, &runs), None);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        assert_eq!(front, [true, false, true, true, false]);
        // A figure only the faster run lacks does not let it dominate.
        let a = Errors {
            curve: 0.01,
            sigma: Real::NAN,
            kawakita_a: Real::NAN,
            kawakita_inv_b: Real::NAN,
        };
        let b = Errors { sigma: 0.02, ..a };
        assert!(b.no_worse_than(&a) && !a.no_worse_than(&b));
    }

    #[test]
    fn over_types_takes_each_largest_error_and_keeps_a_missing_one() {
        let r: Vec<(Real, Real)> = (0..=80)
            .map(|i| (i as Real * 0.005, 1.0 + i as Real))
            .collect();
        let run = |wall: Real, scale: Real, sigma: Option<Real>| Measured {
            wall_time_s: wall,
            sigma_est_pa: sigma,
            error_strains: GRANULE_ERROR_STRAINS,
            curve: r.iter().map(|&(x, y)| (x, scale * y)).collect(),
            ..measured(Vec::new(), None)
        };
        let reference = run(10.0, 1.0, Some(100.0));
        // Setting 0: type X is off by 2 % in F, type Y by 5 %; setting 1
        // the other way round, and type Y has no σ_est there.
        let x = (
            GranuleType::A3,
            reference.clone(),
            vec![run(1.0, 1.02, Some(101.0)), run(2.0, 1.05, Some(103.0))],
        );
        let y = (
            GranuleType::C3,
            reference.clone(),
            vec![run(3.0, 1.05, Some(102.0)), run(4.0, 1.02, None)],
        );
        let study = over_types(&[x, y]);
        assert_eq!(study.reference.wall_time_s, 20.0);
        assert_eq!(
            study.runs.iter().map(|m| m.wall_time_s).collect::<Vec<_>>(),
            [4.0, 6.0]
        );
        let e = &study.errors;
        assert_eq!(e[0].curve, 0.0);
        assert!((e[1].curve - 0.05).abs() < 1e-12 && (e[1].sigma - 0.02).abs() < 1e-12);
        assert!((e[2].curve - 0.05).abs() < 1e-12, "{:?}", e[2]);
        assert!(
            e[2].sigma.is_nan(),
            "a σ_est missing on one type is missing"
        );
    }
}
