//! Hexahedral finite elements.
//!
//! * [`batch`]: the one-point element several at a time (same bits), path chosen at run time;
//! * [`fbar`]: the 2×2×2 F-bar verification element;
//! * [`force`]: nodal forces of the one-point element with hourglass control;
//! * [`hex8`]: node ordering, shape functions, Jacobians;
//! * [`reference`](mod@reference): per-element reference data (V0, B0, γ0, lumped volumes).

pub mod batch;
pub mod fbar;
pub mod force;
pub mod hex8;
pub mod reference;
