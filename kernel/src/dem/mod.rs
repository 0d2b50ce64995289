//! Discrete-element pour of rigid spheres into the die (physics.md §6): the
//! bed that the finite-element compression starts from.
//!
//! * [`contact`]: Hertz–Mindlin contact law with restitution damping;
//! * [`neighbors`]: cell grid and sorted candidate pairs with a skin;
//! * [`pour`]: the pour scene (lattice, random velocities, ramped dissipation).

pub mod contact;
pub mod neighbors;
pub mod pour;
