//! The work-precision study of a small bed (issue #8): the published scene
//! shrunk to a few dozen coarse granules, each numerical setting changed
//! alone from the default and compared with a reference run (F-bar at half
//! the punch speed, no mass scaling) on the same poured bed; the default
//! is also run on further pours (seeds 2…N), and the largest distance of
//! those runs from the first pour's is the run-to-run **spread**. A faster
//! setting is acceptable when its errors (P(C), a, 1/b) all stay within the
//! spread. The mesh level is one of the settings (the other of 4x1 and
//! 8x2), but the reference stays on the study's mesh: the mesh's row is its
//! distance from that, not from a finer reference.
//!
//! All runs of one seed start from one pour (the packing is poured once and
//! handed to every run), so a setting's error holds no pour-to-pour noise.

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::granule::forces::ElementKind;

use super::WorkPrecisionArgs;
use super::stability::Silent;
use super::work_precision::{Errors, Measured, Setting, StudyRuns, say};
use crate::bed::outputs::kawakita;
use crate::bed::run::{Packing, RunControl, pour, run_bed};
use crate::bed::scene::{MaterialOverrides, Scene};
use crate::model::MeshLevel;
use crate::numbers::Shown;
use crate::output::Streams;

/// The small bed's size: granules, die diameter in mm, final strain,
/// pours — (full study, `--quick`).
struct Size {
    granules: usize,
    die_diameter_mm: f64,
    strain: f64,
    pours: u64,
}

/// The full study's bed: 125 granules in a die scaled from the published
/// one by (125/1000)^⅓, to 30 %, three pours.
const FULL: Size = Size {
    granules: 125,
    die_diameter_mm: 5.65,
    strain: 0.3,
    pours: 3,
};

/// `--quick`: 15 granules to 30 %, two pours (checks the machinery).
const QUICK: Size = Size {
    granules: 15,
    die_diameter_mm: 4.2,
    strain: 0.3,
    pours: 2,
};

/// The reference and the settings of the bed study on mesh `mesh`.
pub fn bed_grid(mesh: MeshLevel, quick: bool) -> (Setting, Vec<Setting>) {
    let base = Setting {
        kappa: granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA,
        safety: Scene::published().time_step_safety,
        mass_scaling: Scene::published().mass_scaling,
        selective_mass: Scene::published().selective_mass_scaling,
        sweep_tolerance: Scene::published().sweep_tolerance,
        hold_constraints: Scene::published().hold_constraints,
        contact_search_interval: Scene::published().contact_search_interval,
        time_step_floor: Scene::published().time_step_floor,
        ..Setting::default_on(mesh)
    };
    let with = |name, f: &dyn Fn(&mut Setting)| base.with(name, f);
    // Uniform mass scaling by `f`: every mode of a granule f times heavier
    // and no variable scaling on top (f = 1: the physical masses).
    let uniform = |f: Real| {
        move |s: &mut Setting| {
            s.mass_scaling = f;
            s.selective_mass = false;
            s.time_step_floor = 0.0;
        }
    };
    // Every sweep of every step searches (needs no held constraints).
    let search_always = |s: &mut Setting| {
        s.hold_constraints = false;
        s.contact_search_interval = 1;
    };
    // The most exact of each: every sweep searches.
    let reference = with("reference", &|s| {
        s.element = ElementKind::FBar;
        s.speed_factor = 0.5;
        search_always(s);
        uniform(1.0)(s);
    });
    let mut grid = vec![
        base,
        with("mass x1", &uniform(1.0)),
        with("speed x2", &|s| s.speed_factor = 2.0),
    ];
    if !quick {
        grid.extend([
            with("speed x0.5", &|s| s.speed_factor = 0.5),
            with("mass x4", &uniform(4.0)),
            with("mass x10", &uniform(10.0)),
            with("mass x100", &uniform(100.0)),
            // Selective with the published scene's ratio limit F/G ≤ 10:
            // ×10 (the default until session 18) keeps the rigid modes
            // physical, ×30 makes them 3× heavier, ×100 10×.
            with("selective x10", &|s| {
                s.mass_scaling = 10.0;
                s.selective_mass = true;
            }),
            with("selective x30", &|s| {
                s.mass_scaling = 30.0;
                s.selective_mass = true;
            }),
            with("selective x100", &|s| {
                s.mass_scaling = 100.0;
                s.selective_mass = true;
            }),
            // Variable mass scaling off: the published scene before
            // session 27.
            with("floor off", &|s| s.time_step_floor = 0.0),
            with("safety 0.7", &|s| s.safety = 0.7),
            with("sweep tol 0.005", &|s| s.sweep_tolerance = 0.005),
            with("sweep tol 0.02", &|s| s.sweep_tolerance = 0.02),
            // The published scene before session 30: the contact search
            // every step.
            with("search every step", &|s| s.contact_search_interval = 1),
            // The published scene before session 19: every sweep searches.
            with("search sweeps", &search_always),
            with("kappa 0.02", &|s| s.kappa = 0.02),
            with("kappa 0.1", &|s| s.kappa = 0.1),
            with("fbar", &|s| s.element = ElementKind::FBar),
        ]);
        // The mesh level: the standard mesh on the coarse study's pour (or
        // the coarse one on the standard's). The reference stays on the
        // study's mesh: an F-bar bed at half speed on the standard mesh
        // would take hours; this row gives the mesh's distance against the
        // spread instead (BENCHMARKS.md, session 57).
        let (name, other) = if mesh == MeshLevel::STANDARD {
            ("mesh 4x1", MeshLevel::new(4, 1))
        } else {
            ("mesh 8x2", MeshLevel::STANDARD)
        };
        grid.push(with(name, &|s| s.mesh = other));
    }
    (reference, super::work_precision::distinct(grid))
}

/// The study's scene for `setting` on pour `seed`.
fn scene_for(args: &WorkPrecisionArgs, size: &Size, setting: &Setting, seed: u64) -> Scene {
    let published = Scene::published();
    let m = &args.material;
    Scene {
        granule_type: m.granule_type.name().to_string(),
        granules: args.granules.unwrap_or(size.granules),
        mesh: setting.mesh.to_string(),
        seed,
        die_diameter_mm: args.die_diameter_mm.unwrap_or(size.die_diameter_mm),
        punch_speed_m_s: published.punch_speed_m_s * setting.speed_factor,
        final_strain: args.strain.unwrap_or(size.strain),
        snapshot_strains: Vec::new(),
        // The study measures the loading.
        unload: false,
        checkpoint_interval_minutes: 1e9,
        checkpoint_strain_interval: 1e9,
        element: setting.element_name().to_string(),
        hourglass_kappa: setting.kappa,
        mass_scaling: setting.mass_scaling,
        selective_mass_scaling: setting.selective_mass,
        time_step_safety: setting.safety,
        sweep_tolerance: setting.sweep_tolerance,
        hold_constraints: setting.hold_constraints,
        contact_search_interval: setting.contact_search_interval,
        time_step_floor: setting.time_step_floor,
        material: MaterialOverrides {
            youngs_modulus_pa: m.youngs_modulus_pa,
            poisson_ratio: m.poisson_ratio,
            yield_stress_pa: m.yield_stress_pa,
            eta0: m.eta0,
            cp: m.cp,
            eta_c: m.eta_c,
            true_density_kg_m3: m.true_density_kg_m3,
            friction: m.friction.or(published.material.friction),
        },
        ..published
    }
}

/// Runs `setting` on the poured bed `packing` (seed `seed`).
fn run_setting(
    args: &WorkPrecisionArgs,
    size: &Size,
    setting: &Setting,
    seed: u64,
    packing: &Packing,
    pool: &rayon::ThreadPool,
) -> anyhow::Result<Measured> {
    let scene = scene_for(args, size, setting, seed);
    scene
        .validate()
        .with_context(|| format!("setting `{}`", setting.name))?;
    let control = RunControl {
        packing: Some(packing.clone()),
        ..RunControl::default()
    };
    let run = pool
        .install(|| run_bed(&scene, &control, &mut Silent))
        .with_context(|| format!("setting `{}` seed {seed}", setting.name))?;
    if let Some(e) = run.error {
        anyhow::bail!(
            "setting `{}` seed {seed}: the run failed: {e}",
            setting.name
        );
    }
    let k = kawakita(&run.samples, scene.kawakita_min_strain);
    Ok(Measured {
        setting: *setting,
        seed,
        steps: run.steps,
        wall_time_s: run.wall_time_s,
        sigma_est_pa: None,
        kawakita: k.a.zip(k.inv_b_pa),
        curve: run
            .samples
            .iter()
            .map(|s| (s.strain, s.upper_pressure_pa))
            .collect(),
        error_strains: [ERROR_FROM_STRAIN, scene.final_strain],
    })
}

/// The bed's curve error starts here (below, the pressure is the noise of
/// the rearrangement).
const ERROR_FROM_STRAIN: Real = 0.02;

/// Runs the bed study: the reference and the settings on the first pour,
/// the default on the further pours.
pub fn study(args: &WorkPrecisionArgs, streams: &mut Streams<'_>) -> anyhow::Result<StudyRuns> {
    let size = if args.quick { &QUICK } else { &FULL };
    let pours = args.pours.unwrap_or(size.pours);
    if !(2..=10).contains(&pours) {
        return Err(anyhow::Error::new(crate::error::InputError(format!(
            "`--pours {pours}` is out of range (allowed: 2..=10)"
        ))));
    }
    let mesh = args.mesh.unwrap_or(MeshLevel::new(4, 1));
    let (reference, grid) = bed_grid(mesh, args.quick);
    // The material and the bed before anything runs, errors naming the
    // flags (the material's overrides, then the bed's size).
    args.material.material()?;
    let given: Vec<(&'static str, String)> = [
        ("--granules", args.granules.map(|n| n.shown())),
        ("--die-diameter-mm", args.die_diameter_mm.map(|d| d.shown())),
        ("--strain", args.strain.map(|c| c.shown())),
    ]
    .into_iter()
    .filter_map(|(flag, v)| v.map(|v| (flag, v)))
    .collect();
    scene_for(args, size, &grid[0], 1)
        .validate()
        .map_err(|e| crate::bed::flag_error(e, &given))
        .context("the study's bed")?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the worker threads")?;
    let poured = |seed: u64| -> anyhow::Result<Packing> {
        let scene = scene_for(args, size, &grid[0], seed);
        scene.validate().context("the study's bed")?;
        pool.install(|| pour(&scene, None, &mut |_, _| {}))
            .with_context(|| format!("the pour of seed {seed}"))
    };
    let first = poured(1)?;
    let reference = run_setting(args, size, &reference, 1, &first, &pool)?;
    say(args.quiet, "reference", &reference, streams)?;
    let mut runs = Vec::with_capacity(grid.len());
    for s in &grid {
        let m = run_setting(args, size, s, 1, &first, &pool)?;
        say(args.quiet, "setting", &m, streams)?;
        runs.push(m);
    }
    // The spread: the default on the further pours against the first.
    let default = &runs[0];
    let mut spread: Option<Errors> = None;
    for seed in 2..=pours {
        let packing = poured(seed)?;
        let m = run_setting(args, size, &grid[0], seed, &packing, &pool)?;
        say(args.quiet, "spread", &m, streams)?;
        let e = Errors::of(&m, default);
        if !args.quiet {
            writeln!(
                streams.stderr,
                "study: pour {seed} against pour 1: curve {:.3e}, a {:.3e}, 1/b {:.3e}",
                e.curve, e.kawakita_a, e.kawakita_inv_b
            )?;
        }
        spread = Some(spread.map_or(e, |s| s.max(e)));
    }
    let title = format!(
        "work-precision, bed of {} {} granules ({}, reference: {} at half speed)",
        args.granules.unwrap_or(size.granules),
        args.material.granule_type,
        mesh,
        reference.setting.element_name()
    );
    Ok(StudyRuns {
        errors: super::work_precision::errors_against(&reference, &runs),
        reference,
        runs,
        spread,
        title,
        x_desc: "largest relative error against the reference (P(C) L2, a, 1/b)",
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_changes_one_setting_at_a_time_and_holds_no_twins() {
        let (reference, grid) = bed_grid(MeshLevel::new(4, 1), false);
        let base = grid[0];
        assert_eq!(base.name, "default");
        assert_eq!(reference.element, ElementKind::FBar);
        for s in &grid[1..] {
            let differs = [
                s.mesh != base.mesh,
                s.element != base.element,
                s.kappa != base.kappa,
                s.safety != base.safety,
                // The mass scaling: its factor, whether it is selective and
                // its variable part.
                s.mass_scaling != base.mass_scaling
                    || s.selective_mass != base.selective_mass
                    || s.time_step_floor != base.time_step_floor,
                s.speed_factor != base.speed_factor,
                s.sweep_tolerance != base.sweep_tolerance,
                // What the contact sweeps hold: within a step, and between
                // searches.
                s.hold_constraints != base.hold_constraints
                    || s.contact_search_interval != base.contact_search_interval,
            ];
            assert_eq!(
                differs.iter().filter(|d| **d).count(),
                1,
                "`{}` changes one setting",
                s.name
            );
        }
        for (i, a) in grid.iter().enumerate() {
            for b in &grid[i + 1..] {
                assert_ne!(a.named(""), b.named(""), "`{}` = `{}`", a.name, b.name);
            }
        }
        // The mesh level is in the grid: the other of the two meshes.
        let other = |mesh: MeshLevel| {
            let (_, grid) = bed_grid(mesh, false);
            let rows: Vec<_> = grid.iter().filter(|s| s.mesh != mesh).collect();
            assert_eq!(rows.len(), 1, "{mesh}");
            (rows[0].name, rows[0].mesh)
        };
        assert_eq!(
            other(MeshLevel::new(4, 1)),
            ("mesh 8x2", MeshLevel::STANDARD)
        );
        assert_eq!(
            other(MeshLevel::STANDARD),
            ("mesh 4x1", MeshLevel::new(4, 1))
        );
        // Not in the quick grid (the CI's).
        assert!(
            bed_grid(MeshLevel::new(4, 1), true)
                .1
                .iter()
                .all(|s| s.mesh.n == 4)
        );
    }
}
