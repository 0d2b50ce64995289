//! Reference meshes of a granule.
//!
//! * [`sphere`]: the cubed-sphere hex mesh of physics.md §3;
//! * [`surface`]: area and enclosed volume of a quad surface.

pub mod sphere;
pub mod surface;
