//! Owned storage for the caller-buffer APIs of [`granbed_kernel`], for
//! hosts with an allocator (`granbed-cli`, `granbed-wasm`).
//!
//! The kernel never allocates: every function borrows the buffers it
//! works on. A host that runs a granule has to own those buffers somewhere;
//! this crate owns them in `Vec`s and lends them to the kernel as its
//! borrowed views ([`MeshView`](granbed_kernel::mesh::octant::MeshView),
//! [`ReferenceMesh`](granbed_kernel::mesh::reference::ReferenceMesh),
//! [`GranuleBuffers`](granbed_kernel::granule::dynamics::GranuleBuffers), …).
//! The command line and the browser build their meshes here, so the
//! browser's curve is the CLI's by construction, not by a copy of the code.
//!
//! - [`mesh`]: a reference mesh (sphere, its octant, or a cube) with its
//!   element data, and the mesh level `NxM`.
//! - [`store`]: a granule's node and integration-point buffers, the time
//!   step's power-iteration scratch, the platen experiment's pair of them,
//!   and the discrete-element pour's buffers.
//! - [`text`]: numbers as messages show them (`1e300`, not 301 digits).

#![no_std]

extern crate alloc;

pub mod mesh;
pub mod store;
pub mod text;

pub use mesh::{MeshLevel, OwnedReference, regrouped};
pub use store::{GranuleStore, PlatenStore, PourStore, PowerStore};
