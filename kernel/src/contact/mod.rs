//! Contact of granule surfaces with each other and with rigid walls
//! (physics.md §5).
//!
//! * [`quad`]: closest point of a node on a bilinear quad;
//! * [`surface`]: a granule's surface on the predicted configuration, boxes;
//! * [`broad`]: candidate granule pairs from bounding spheres on a grid;
//! * [`face_lists`]: per-node lists of reachable master faces with a skin,
//!   so detection need not try every face every sweep;
//! * [`pair`]: node-to-surface detection and kinematic forces between two
//!   granules (symmetric two-pass, mass sharing, Coulomb friction);
//! * [`wall`]: kinematic contact with rigid planes and the die cylinder;
//! * [`rigid`]: the rigid pre-solve of a granule's wall contacts under
//!   selective mass scaling (a building block, not used by the bed yet).

pub mod broad;
pub mod face_lists;
pub mod pair;
pub mod quad;
pub mod rigid;
pub mod surface;
pub mod wall;
