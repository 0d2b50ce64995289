//! The pour driven to rest: owned buffers ([`PourStore`]) lent to the
//! kernel's [`PourScene`], stepped with [`PourScene::run_to_rest`], and the
//! final state copied out. Nothing here depends on clap.

use core::ops::ControlFlow;
use std::time::Instant;

use granbed_kernel::Real;
use granbed_kernel::dem::neighbors::Pair;
use granbed_kernel::dem::pour::{PourBuffers, PourError, PourParams, PourScene, PourStatus};

use crate::model::PourStore;

/// Steps between the rest checks (and progress reports) of
/// [`PourScene::run_to_rest`]; the settle time is resolved to this many
/// steps (about 5 ms at the standard time step).
pub const CHECK_EVERY: u64 = 5000;

/// What one pour produced. A pour stopped by a kernel error (not settled
/// within the time limit, or unstable) keeps its last state and holds the
/// error in [`PourResult::error`].
#[derive(Clone, Debug)]
pub struct PourResult {
    /// Sphere centres at the end, m, in granule order.
    pub positions: Vec<[Real; 3]>,
    /// The sphere–sphere candidate pairs (i < j) of the last neighbour
    /// list; they include every overlapping pair.
    pub sphere_pairs: Vec<(usize, usize)>,
    /// The state at the end (at rest, or when the run stopped).
    pub status: PourStatus,
    /// The time step, s.
    pub dt_s: Real,
    /// Wall-clock time from the scene's construction to the end of the
    /// run, s.
    pub wall_time_s: f64,
    /// The kernel error that stopped the run, if any.
    pub error: Option<PourError>,
}

/// Checks `params` the way the kernel would, without allocating the
/// buffers or placing a sphere: the kernel validates the parameters before
/// it looks at the buffers, so empty buffers are enough.
///
/// Errors are the kernel's [`PourError::InvalidParameter`].
pub fn check(params: PourParams) -> Result<(), PourError> {
    let buffers = PourBuffers {
        x: &mut [],
        v: &mut [],
        omega: &mut [],
        f: &mut [],
        torque: &mut [],
        x_built: &mut [],
        pairs: &mut [],
        pairs_old: &mut [],
        head: &mut [],
        next: &mut [],
    };
    match PourScene::new(params, buffers) {
        Err(e @ PourError::InvalidParameter { .. }) => Err(e),
        _ => Ok(()),
    }
}

/// The sphere–sphere pairs (i, j) of a kernel pair list (the floor and die
/// pairs, whose partner is not a sphere index, left out).
pub fn sphere_pairs(pairs: &[Pair], spheres: usize) -> Vec<(usize, usize)> {
    pairs
        .iter()
        .filter(|p| (p.j as usize) < spheres)
        .map(|p| (p.i as usize, p.j as usize))
        .collect()
}

/// Pours `params` to rest.
///
/// `on_check` sees the state every [`CHECK_EVERY`] steps, with the wall
/// time since the start in seconds (for progress reports), and may stop
/// the pour there ([`ControlFlow::Break`]: [`PourError::Stopped`] in the
/// result).
///
/// Returns `Err` only if the scene cannot be set up; an error while
/// stepping ends the run and is returned inside the [`PourResult`].
pub fn run_pour(
    params: PourParams,
    on_check: &mut dyn FnMut(&PourStatus, f64) -> ControlFlow<()>,
) -> Result<PourResult, PourError> {
    let mut store = PourStore::new(&params)?;
    let start = Instant::now();
    let mut scene = PourScene::new(params, store.buffers())?;
    let outcome = scene.run_to_rest(CHECK_EVERY, &mut |s| {
        on_check(s, start.elapsed().as_secs_f64())
    });
    let wall_time_s = start.elapsed().as_secs_f64();
    let (status, error) = match outcome {
        Ok(status) => (status, None),
        Err(e) => (scene.status(), Some(e)),
    };
    Ok(PourResult {
        positions: scene.positions().to_vec(),
        sphere_pairs: sphere_pairs(scene.pairs(), params.granules),
        status,
        dt_s: scene.time_step(),
        wall_time_s,
        error,
    })
}
