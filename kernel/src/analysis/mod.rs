//! Post-processing formulas (physics.md §7).
//!
//! * [`fit`]: least-squares lines;
//! * [`granule`]: σ_est and σ_y,eff0 of the single-granule experiment;
//! * [`bed`]: pressure, strain, Kawakita fit, granule η_g and α_SV,
//!   coordination number and mean relative density of a compressed bed;
//! * [`quasi_static`]: the quasi-static certificate of a loading run;
//! * [`overlap`]: how deep a point lies inside a closed surface, by its
//!   winding number: an overlap measure independent of the contact
//!   detection.

pub mod bed;
pub mod fit;
pub mod granule;
pub mod overlap;
pub mod quasi_static;
