//! Finite-strain porous elastoplasticity (physics.md §1): multiplicative split
//! F = F^e F^p, compressible neo-Hookean elasticity in b^e, a density-dependent
//! elliptic yield surface, and a return map that stays exact on the surface.
//!
//! * [`elastic`]: stress and energy of the neo-Hookean law.
//! * [`yield_surface`]: a1(η), a2(η) and φ.
//! * [`return_map`]: the corrector in (ε, δ) and its solvers.
//! * [`update`]: one integration point from F_{n+1} and C_p⁻¹_n.
//! * [`batch`]: the same over slices of points.

pub mod batch;
pub mod elastic;
pub mod return_map;
pub mod update;
pub mod yield_surface;

pub use batch::{BatchError, update_points};
pub use return_map::ReturnMethod;
pub use update::{PointUpdate, UpdateError, UpdateInfo, UpdateOptions, update_point};
