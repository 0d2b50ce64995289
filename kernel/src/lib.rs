#![no_std]
//! # granbed-kernel
//!
//! The physics kernel of granbed, a combined finite/discrete element
//! simulator of granule-bed die compaction. It is `#![no_std]` without an
//! allocator: every routine works on caller-provided buffers and reports
//! failures as values (errors or counted flags), never by panicking.
//!
//! Units are SI throughout, scalars are [`Real`] = `f64`, and every
//! transcendental function goes through [`math`] (libm) so native and wasm
//! builds agree bit for bit.
//!
//! Modules:
//! * [`material`]: parameters, validation, the nine standard granule types;
//! * [`constitutive`]: the finite-strain porous elastoplastic update;
//! * [`material_point`]: one integration point driven along a load path;
//! * [`mesh`]: the cubed-sphere reference mesh of a granule;
//! * [`element`]: the 8-node hexahedron (one at a time, or four side by side);
//! * [`lanes`]: arithmetic over one value or several side by side, same bits;
//! * [`granule`]: element loop, damping and time step of one granule;
//! * [`contact`]: node-to-surface contact between granules (detection, face
//!   lists, kinematic forces with friction) and with rigid walls;
//! * [`dem`]: the discrete-element pour of rigid spheres;
//! * [`rng`]: the seeded random generator;
//! * [`analysis`]: post-processing formulas (fits, σ_est);
//! * [`scene`]: complete experiments (single granule between platens);
//! * [`tensor`]: 3×3 and symmetric (Voigt) tensor helpers;
//! * [`math`]: the scalar functions.
//!
//! Slice-length policy: batch routines check every buffer length first and
//! return an error naming the buffer; they never panic on lengths.

/// The one scalar type of the kernel.
pub type Real = f64;

/// The nalgebra this kernel is built with (its 3×3 matrices,
/// [`tensor::Mat3`], appear in the API): a caller uses it without pinning
/// a version of its own.
pub use nalgebra;

pub mod analysis;
pub mod constitutive;
pub mod contact;
pub mod dem;
pub mod element;
pub mod granule;
pub mod lanes;
pub mod material;
pub mod material_point;
pub mod math;
pub mod mesh;
pub mod rng;
pub mod scene;
pub mod tensor;
