//! Owned buffers for the kernel's platen experiment
//! ([`granbed_kernel::scene::platens`]) and the loop that drives it to its
//! final strain, collecting every sample.
//!
//! The kernel works over caller buffers; [`PlatenStore`] owns them (one
//! allocation per buffer, sized from the mesh and the element's integration
//! points) and [`run_platens`] lends them to a [`PlatenScene`] for one run. Nothing here depends on clap, so the
//! test suites and the `--types` loop drive exactly this code.

use std::time::Instant;

use granbed_kernel::Real;
use granbed_kernel::scene::platens::{PlatenParams, PlatenSample, PlatenScene, SceneError};

use crate::model::{OwnedReference, PlatenStore};

/// Everything one run produced. A run stopped by a kernel error keeps the
/// samples taken before it and holds the error in [`RunResult::error`].
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Samples in time order: [`PlatenScene::sample`] at t = 0 first, then
    /// every sample [`PlatenScene::step`] returned.
    pub samples: Vec<PlatenSample>,
    /// Granule diameter d that strains are measured against, m.
    pub diameter_m: Real,
    /// Time step of the first step, s.
    pub initial_dt_s: Real,
    /// Steps completed (a failed step is not counted).
    pub steps: u64,
    /// Element evaluations (steps × simulated hexes).
    pub element_steps: u64,
    /// Wall-clock time from the scene's construction to the end of the
    /// loop (stepping and sampling; not the mesh generation), s.
    pub wall_time_s: f64,
    /// The kernel error that stopped the run early, if any.
    pub error: Option<SceneError>,
    /// Node positions at the end of the run, m (the state a failed step
    /// left: not one to show).
    pub final_x: Vec<[Real; 3]>,
    /// The integration points' C_p⁻¹ at the end of the run (Voigt).
    pub final_cp_inv: Vec<[Real; 6]>,
}

/// Checks `params` against `mesh` the way a run would (the kernel's
/// parameter validation and buffer checks), without stepping; returns the
/// run's first time step, s.
///
/// Errors are those of [`PlatenScene::new`].
pub fn check(params: PlatenParams, mesh: &OwnedReference) -> Result<Real, SceneError> {
    let mut store = PlatenStore::new(mesh, params.elements.points_per_element());
    PlatenScene::new(params, mesh.view(), store.buffers()).map(|s| s.time_step())
}

/// Runs the platen experiment `params` on `mesh` to its final strain.
///
/// `on_sample` sees every sample as it is taken, with the wall time since
/// the start in seconds (for progress reports); it cannot stop the run.
///
/// Returns `Err` only if the scene cannot be set up (invalid parameter,
/// unstable initial time step); an error while stepping ends the run and is
/// returned inside the [`RunResult`] with the samples so far.
pub fn run_platens(
    params: PlatenParams,
    mesh: &OwnedReference,
    on_sample: &mut dyn FnMut(&PlatenSample, f64),
) -> Result<RunResult, SceneError> {
    let mut store = PlatenStore::new(mesh, params.elements.points_per_element());
    let start = Instant::now();
    let mut scene = PlatenScene::new(params, mesh.view(), store.buffers())?;
    let initial_dt_s = scene.time_step();
    let first = scene.sample();
    on_sample(&first, start.elapsed().as_secs_f64());
    let mut samples = vec![first];
    let mut error = None;
    while !scene.finished() {
        match scene.step() {
            Ok(Some(sample)) => {
                on_sample(&sample, start.elapsed().as_secs_f64());
                samples.push(sample);
            }
            Ok(None) => {}
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    let wall_time_s = start.elapsed().as_secs_f64();
    // The scene borrows the store's buffers up to here.
    let (diameter_m, steps, element_steps) =
        (scene.diameter(), scene.steps(), scene.element_steps());
    Ok(RunResult {
        samples,
        diameter_m,
        initial_dt_s,
        steps,
        element_steps,
        wall_time_s,
        error,
        // The store goes out of scope here: its final state is moved.
        final_x: core::mem::take(&mut store.granule.x),
        final_cp_inv: core::mem::take(&mut store.granule.cp_inv),
    })
}
