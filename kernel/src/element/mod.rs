//! Hexahedral finite elements.
//!
//! * [`hex8`]: node ordering, shape functions, Jacobians;
//! * [`reference`]: per-element reference data (V0, B0, γ0, lumped volumes).

pub mod hex8;
pub mod reference;
