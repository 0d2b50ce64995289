//! Reference meshes of a granule.
//!
//! * [`sphere`]: the cubed-sphere hex mesh of physics.md §3;
//! * [`octant`]: the positive octant of a symmetric mesh;
//! * [`reference`](mod@reference): a mesh with its shared per-element data;
//! * [`surface`]: area and enclosed volume of a quad surface.

pub mod octant;
pub mod reference;
pub mod sphere;
pub mod surface;
