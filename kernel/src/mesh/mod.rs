//! Reference meshes of a granule.
//!
//! * [`sphere`]: the cubed-sphere hex mesh of physics.md §3;
//! * [`cube`]: an n×n×n hex cube (the sliding body of the friction oracle, §5.6);
//! * [`octant`]: the positive octant of a symmetric mesh;
//! * [`reference`](mod@reference): a mesh with its shared per-element data;
//! * [`surface`]: area and enclosed volume of a quad surface.

pub mod cube;
pub mod octant;
pub mod reference;
pub mod sphere;
pub mod surface;
