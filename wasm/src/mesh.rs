//! The granule's reference mesh and the run buffers, owned here for the
//! program's lifetime.
//!
//! The kernel's [`PlatenScene`](granbed_kernel::scene::platens::PlatenScene)
//! borrows its mesh and buffers; a handle that JavaScript keeps between
//! calls cannot hold a borrow of its own fields, so the storage is given
//! `'static` lifetime once and reused: meshes are cached per (diameter,
//! level) and run buffers go back to a pool when a run is dropped (see
//! [`crate::experiment::Experiment`]). Memory therefore grows only with the
//! number of distinct diameters and of runs alive at once, not with the
//! number of runs. The mesh and the buffers themselves are built by
//! `granbed-host`, as `granbed-cli granule` builds them.

use alloc::boxed::Box;
use alloc::vec::Vec;
use core::cell::RefCell;

use granbed_host::{MeshLevel, OwnedReference, PlatenStore};
use granbed_kernel::Real;
use granbed_kernel::scene::platens::PlatenBuffers;

type MeshKey = (u64, u32, u32);

std::thread_local! {
    static MESHES: RefCell<Vec<(MeshKey, &'static OwnedReference)>> = const { RefCell::new(Vec::new()) };
    static POOL: RefCell<Vec<PlatenBuffers<'static>>> = const { RefCell::new(Vec::new()) };
}

/// The cached positive octant of the sphere of `radius` (m) at level
/// `n`x`m` with its element data (`OwnedReference::sphere(radius, level,
/// true)`, as the CLI's `granule` builds it), generated on first use;
/// `None` if the kernel rejects the level or radius.
pub fn octant_mesh(radius: Real, n: u32, m: u32) -> Option<&'static OwnedReference> {
    let key = (radius.to_bits(), n, m);
    if let Some(mesh) = MESHES.with_borrow(|c| c.iter().find(|(k, _)| *k == key).map(|(_, m)| *m)) {
        return Some(mesh);
    }
    let mesh = OwnedReference::sphere(radius, MeshLevel::new(n, m), true).ok()?;
    let mesh: &'static OwnedReference = Box::leak(Box::new(mesh));
    MESHES.with_borrow_mut(|c| c.push((key, mesh)));
    Some(mesh)
}

/// Run buffers for `mesh` with `points` integration points per element: a
/// pooled set of that size, or a new one (the scene initialises them
/// either way).
pub fn take_buffers(mesh: &OwnedReference, points: usize) -> PlatenBuffers<'static> {
    let (nodes, states) = (mesh.positions.len(), mesh.hexes.len() * points);
    let pooled = POOL.with_borrow_mut(|pool| {
        let i = pool
            .iter()
            .position(|b| b.granule.x.len() == nodes && b.granule.cp_inv.len() == states)?;
        Some(pool.swap_remove(i))
    });
    pooled.unwrap_or_else(|| Box::leak(Box::new(PlatenStore::new(mesh, points))).buffers())
}

/// Returns `buffers` to the pool for the next run.
pub fn give_back(buffers: PlatenBuffers<'static>) {
    POOL.with_borrow_mut(|pool| pool.push(buffers));
}
