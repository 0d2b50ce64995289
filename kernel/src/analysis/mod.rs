//! Post-processing formulas (physics.md §7).
//!
//! * [`fit`]: least-squares lines;
//! * [`granule`]: σ_est and σ_y,eff0 of the single-granule experiment.

pub mod fit;
pub mod granule;
