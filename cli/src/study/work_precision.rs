//! The work-precision study of the single-granule scene (issue #8): each
//! numerical setting changed alone from the default, run to 40 % strain,
//! and compared with a reference run.
//!
//! * Error measures: the relative L2 distance of the platen force curve
//!   F(C) from the reference's over 2 % ≤ C ≤ 40 % (both interpolated
//!   linearly onto a 0.5 % grid), and the relative error of σ_est.
//! * Cost: the wall time of the run (stepping and sampling, one thread; the
//!   mesh generation not included) and its steps.
//! * A setting is on the Pareto front when no other run is both faster and
//!   more accurate.
//!
//! Mass scaling F multiplies the granule's density (its inertia; the
//! octant scene has no gravity), so the stable step grows by √F and the
//! damping, a fraction of the lowest mode's critical value, follows.

use std::path::Path;

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::analysis::granule::yield_stress_estimate;
use granbed_kernel::granule::forces::ElementKind;
use granbed_kernel::material::Material;
use granbed_kernel::scene::platens::PlatenParams;
use plotters::prelude::*;

use super::{StudyScene, WorkPrecisionArgs};
use crate::csv::{CsvWriter, Field};
use crate::granule::GRANULE_RADIUS_M;
use crate::granule::run::{mean_force, run_platens};
use crate::granule::summary::FIT_STRAIN_RANGE;
use crate::model::{MeshLevel, OwnedReference};
use crate::output::{Streams, create_file, finish_file, write_text};

/// The table of the study.
pub const CSV_FILE: &str = "work_precision.csv";
/// The diagram: wall time against the force-curve error, log-log.
pub const SVG_FILE: &str = "work_precision.svg";

/// Columns of [`CSV_FILE`].
pub const COLUMNS: [&str; 15] = [
    "setting",
    "mesh_n",
    "mesh_m",
    "element",
    "hourglass_kappa",
    "time_step_safety",
    "mass_scaling",
    "speed_factor",
    "steps",
    "wall_time_s",
    "sigma_est_pa",
    "error_force_l2",
    "error_sigma_est",
    "reference",
    "pareto",
];

/// Strain window of the force-curve error.
const ERROR_STRAINS: [Real; 2] = [0.02, 0.4];
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
    /// Platen speed as a multiple of the standard 5 mm/s.
    pub speed_factor: Real,
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
            mass_scaling: 1.0,
            speed_factor: 1.0,
        }
    }

    fn element_name(&self) -> &'static str {
        match self.element {
            ElementKind::OnePoint => "one-point",
            ElementKind::FBar => "fbar",
        }
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
    let with = |name, f: &dyn Fn(&mut Setting)| {
        let mut s = base;
        s.name = name;
        f(&mut s);
        s
    };
    let reference = with("reference", &|s| {
        s.mesh = if quick {
            MeshLevel::new(4, 1)
        } else {
            MeshLevel::new(16, 4)
        };
        s.element = ElementKind::FBar;
        s.speed_factor = 0.5;
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
        with("mass x10", &|s| s.mass_scaling = 10.0),
        with("speed x2", &|s| s.speed_factor = 2.0),
    ]);
    (reference, grid)
}

/// What one run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The settings.
    pub setting: Setting,
    /// Steps.
    pub steps: u64,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// σ_est, Pa (None if the fit had too few samples).
    pub sigma_est_pa: Option<Real>,
    /// The force curve: (strain, mean platen force in N).
    pub curve: Vec<(Real, Real)>,
}

/// Runs `setting` for `material`.
pub fn run_granule(setting: &Setting, material: &Material) -> anyhow::Result<Measured> {
    let mut params = material.params;
    params.true_density_kg_m3 *= setting.mass_scaling;
    let material = params.validate().context("mass-scaled material")?;
    let mesh = OwnedReference::sphere(GRANULE_RADIUS_M, setting.mesh, true)?;
    let mut p = PlatenParams::standard(material);
    p.elements.kind = setting.element;
    p.elements.hourglass_kappa = setting.kappa;
    p.time_step_safety = setting.safety;
    p.approach_speed_m_s *= setting.speed_factor;
    let result = run_platens(p, &mesh, &mut |_, _| {})
        .map_err(anyhow::Error::new)
        .with_context(|| format!("setting `{}`", setting.name))?;
    if let Some(e) = result.error {
        anyhow::bail!("setting `{}`: the run failed: {e}", setting.name);
    }
    let curve: Vec<(Real, Real)> = result
        .samples
        .iter()
        .map(|s| (s.strain, mean_force(s)))
        .collect();
    let [lo, hi] = FIT_STRAIN_RANGE;
    let sigma_est_pa = yield_stress_estimate(
        result.samples.iter().map(|s| (s.approach_m, mean_force(s))),
        result.diameter_m,
        lo,
        hi,
    )
    .map(|(sigma, _)| sigma);
    Ok(Measured {
        setting: *setting,
        steps: result.steps,
        wall_time_s: result.wall_time_s,
        sigma_est_pa,
        curve,
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

/// Relative L2 distance of `curve` from `reference` on the error grid;
/// None if either does not cover it.
pub fn curve_error(curve: &[(Real, Real)], reference: &[(Real, Real)]) -> Option<Real> {
    let n = ((ERROR_STRAINS[1] - ERROR_STRAINS[0]) / ERROR_STEP).round() as usize;
    let (mut diff, mut norm) = (0.0, 0.0);
    for i in 0..=n {
        let c = ERROR_STRAINS[0] + ERROR_STEP * i as Real;
        let (f, r) = (at(curve, c)?, at(reference, c)?);
        diff += (f - r) * (f - r);
        norm += r * r;
    }
    (norm > 0.0).then(|| (diff / norm).sqrt())
}

/// One row of the table.
struct Row<'a> {
    m: &'a Measured,
    error_force: Real,
    error_sigma: Real,
    reference: bool,
    pareto: bool,
}

/// The rows with their errors against `reference` and the Pareto flags.
fn rows<'a>(reference: &'a Measured, runs: &'a [Measured]) -> Vec<Row<'a>> {
    let sigma_ref = reference.sigma_est_pa.unwrap_or(Real::NAN);
    let mut rows: Vec<Row<'a>> = core::iter::once(reference)
        .chain(runs)
        .enumerate()
        .map(|(i, m)| Row {
            m,
            error_force: curve_error(&m.curve, &reference.curve).unwrap_or(Real::NAN),
            error_sigma: m
                .sigma_est_pa
                .map_or(Real::NAN, |s| (s - sigma_ref).abs() / sigma_ref),
            reference: i == 0,
            pareto: false,
        })
        .collect();
    let front: Vec<bool> = rows
        .iter()
        .map(|r| {
            !rows
                .iter()
                .any(|o| o.m.wall_time_s < r.m.wall_time_s && o.error_force < r.error_force)
        })
        .collect();
    for (r, f) in rows.iter_mut().zip(front) {
        r.pareto = f;
    }
    rows
}

fn write_csv(path: &Path, rows: &[Row<'_>]) -> anyhow::Result<()> {
    let file = create_file(path)?;
    let mut csv = CsvWriter::new(file, &COLUMNS)?;
    for r in rows {
        let s = &r.m.setting;
        csv.write_row(&[
            Field::Text(s.name),
            Field::from(s.mesh.n),
            Field::from(s.mesh.m),
            Field::Text(s.element_name()),
            Field::Real(s.kappa),
            Field::Real(s.safety),
            Field::Real(s.mass_scaling),
            Field::Real(s.speed_factor),
            Field::Int(r.m.steps),
            Field::Real(r.m.wall_time_s),
            Field::Real(r.m.sigma_est_pa.unwrap_or(Real::NAN)),
            Field::Real(r.error_force),
            Field::Real(r.error_sigma),
            Field::from(r.reference),
            Field::from(r.pareto),
        ])
        .with_context(|| format!("cannot write `{}`", path.display()))?;
    }
    finish_file(csv.into_inner(), path)
}

/// The log-log diagram: wall time against the force-curve error, one
/// labelled point per setting (the reference, error 0, is left out).
fn diagram(rows: &[Row<'_>], title: &str) -> anyhow::Result<String> {
    let pts: Vec<(&str, f64, f64, bool)> = rows
        .iter()
        .filter(|r| !r.reference && r.error_force.is_finite() && r.error_force > 0.0)
        .map(|r| {
            (
                r.m.setting.name,
                r.error_force,
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
    let xr = bounds(&mut pts.iter().map(|p| p.1));
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
            .build_cartesian_2d(xr.log_scale(), yr.log_scale())?;
        chart
            .configure_mesh()
            .x_desc("relative L2 error of F(C) against the reference")
            .y_desc("wall time, s")
            .draw()?;
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

impl WorkPrecisionArgs {
    /// Runs the study and writes the table and the diagram.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        let material = self.material.material()?;
        let (reference, grid) = match self.scene {
            StudyScene::Granule => granule_grid(self.quick),
        };
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("cannot create output directory `{}`", self.out.display()))?;
        let say = |what: &str, m: &Measured, streams: &mut Streams<'_>| -> anyhow::Result<()> {
            if !self.quiet {
                writeln!(
                    streams.stderr,
                    "study: {what} `{}`: {} steps in {:.2} s",
                    m.setting.name, m.steps, m.wall_time_s
                )?;
            }
            Ok(())
        };
        let reference = run_granule(&reference, &material)?;
        say("reference", &reference, streams)?;
        let mut runs = Vec::with_capacity(grid.len());
        for s in &grid {
            let m = run_granule(s, &material)?;
            say("setting", &m, streams)?;
            runs.push(m);
        }
        let rows = rows(&reference, &runs);
        write_csv(&self.out.join(CSV_FILE), &rows)?;
        let title = format!(
            "work-precision, granule {} (reference: {} {}, half speed)",
            self.material.granule_type,
            reference.setting.mesh,
            reference.setting.element_name()
        );
        let svg_path = self.out.join(SVG_FILE);
        write_text(&svg_path, &diagram(&rows, &title)?)?;
        if let Some(d) = rows.iter().find(|r| r.m.setting.name == "default") {
            writeln!(
                streams.stderr,
                "study: default: force error {:.3e}, sigma_est error {:.3e}, {:.2} s; on the \
                 Pareto front: {}",
                d.error_force,
                d.error_sigma,
                d.m.wall_time_s,
                if d.pareto { "yes" } else { "no" }
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curve_error_of_a_scaled_curve_is_the_scale() {
        let r: Vec<(Real, Real)> = (0..=100).map(|i| (i as Real * 0.005, i as Real)).collect();
        let c: Vec<(Real, Real)> = r.iter().map(|&(x, y)| (x, 1.1 * y)).collect();
        let e = curve_error(&c, &r).unwrap();
        assert!((e - 0.1).abs() < 1e-12, "{e}");
        assert_eq!(curve_error(&r, &r), Some(0.0));
        // A curve that stops early does not cover the window.
        assert_eq!(curve_error(&c[..50], &r), None);
    }
}
