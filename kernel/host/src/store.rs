//! A granule's run buffers, the time step's scratch and the pour's
//! buffers, owned.

use alloc::vec;
use alloc::vec::Vec;

use granbed_kernel::Real;
use granbed_kernel::dem::neighbors::Pair;
use granbed_kernel::dem::pour::{PourBuffers, PourError, PourParams};
use granbed_kernel::granule::dynamics::GranuleBuffers;
use granbed_kernel::granule::timestep::PowerIterationBuffers;
use granbed_kernel::scene::platens::PlatenBuffers;

use crate::mesh::OwnedReference;

/// Owned per-granule state for the kernel's [`GranuleBuffers`]: node
/// buffers for every node of the mesh and `points` C_p⁻¹ per element.
#[derive(Clone, Debug)]
pub struct GranuleStore {
    /// Positions, m.
    pub x: Vec<[Real; 3]>,
    /// Velocities, m/s.
    pub v: Vec<[Real; 3]>,
    /// Scratch: velocity before contact v*, m/s.
    pub v_star: Vec<[Real; 3]>,
    /// Predicted positions x̃, m.
    pub x_pred: Vec<[Real; 3]>,
    /// Internal + hourglass forces, N.
    pub f_int: Vec<[Real; 3]>,
    /// Contact forces of the step, N.
    pub f_c: Vec<[Real; 3]>,
    /// Damping forces, N.
    pub f_d: Vec<[Real; 3]>,
    /// Lumped masses, kg.
    pub mass: Vec<Real>,
    /// The masses the kinematic contact sees, kg: `mass`, or under selective
    /// mass scaling the effective nodal masses of
    /// [`granbed_kernel::granule::damping::selective_contact_masses`]
    /// (set by the owner of the contact phase; the assembly sets them on
    /// the surface nodes only, which are all that contact touches: the
    /// interior entries are not kept up to date and nothing reads them).
    pub contact_mass: Vec<Real>,
    /// Per node, bit a = velocity component a held at zero.
    pub fixed: Vec<u8>,
    /// C_p⁻¹ per integration point.
    pub cp_inv: Vec<[Real; 6]>,
}

impl GranuleStore {
    /// The bytes [`GranuleStore::new`] allocates for `mesh` with `points`
    /// integration points per element, without allocating them: what a
    /// host checks against its memory before it makes many granules.
    pub fn bytes_for(mesh: &OwnedReference, points: usize) -> u64 {
        use core::mem::size_of;
        let nodes = mesh.positions.len() as u64;
        let per_node = 7 * size_of::<[Real; 3]>() + 2 * size_of::<Real>() + size_of::<u8>();
        let states = (mesh.hexes.len() as u64).saturating_mul(points as u64);
        nodes
            .saturating_mul(per_node as u64)
            .saturating_add(states.saturating_mul(size_of::<[Real; 6]>() as u64))
    }

    /// Zeroed buffers for `mesh` with `points` integration points per element
    /// (the kernel's scene or [`GranuleBuffers::reset`] initialises them).
    pub fn new(mesh: &OwnedReference, points: usize) -> Self {
        let n = mesh.positions.len();
        Self {
            x: vec![[0.0; 3]; n],
            v: vec![[0.0; 3]; n],
            v_star: vec![[0.0; 3]; n],
            x_pred: vec![[0.0; 3]; n],
            f_int: vec![[0.0; 3]; n],
            f_c: vec![[0.0; 3]; n],
            f_d: vec![[0.0; 3]; n],
            mass: vec![0.0; n],
            contact_mass: vec![0.0; n],
            fixed: vec![0; n],
            cp_inv: vec![[0.0; 6]; mesh.hexes.len() * points],
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> GranuleBuffers<'_> {
        GranuleBuffers {
            x: &mut self.x,
            v: &mut self.v,
            v_star: &mut self.v_star,
            x_pred: &mut self.x_pred,
            f_int: &mut self.f_int,
            f_c: &mut self.f_c,
            f_d: &mut self.f_d,
            mass: &mut self.mass,
            fixed: &mut self.fixed,
            cp_inv: &mut self.cp_inv,
        }
    }
}

/// Owned scratch for the kernel's power iteration (the global time-step
/// estimate) of one granule.
#[derive(Clone, Debug)]
pub struct PowerStore {
    mode: Vec<[Real; 3]>,
    x_pert: Vec<[Real; 3]>,
    f_plus: Vec<[Real; 3]>,
    f_minus: Vec<[Real; 3]>,
    cp_scratch: Vec<[Real; 6]>,
}

impl PowerStore {
    /// Buffers for `mesh` with `points` integration points per element.
    pub fn new(mesh: &OwnedReference, points: usize) -> Self {
        let n = mesh.positions.len();
        Self {
            mode: vec![[0.0; 3]; n],
            x_pert: vec![[0.0; 3]; n],
            f_plus: vec![[0.0; 3]; n],
            f_minus: vec![[0.0; 3]; n],
            cp_scratch: vec![[0.0; 6]; mesh.hexes.len() * points],
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> PowerIterationBuffers<'_> {
        PowerIterationBuffers {
            mode: &mut self.mode,
            x_pert: &mut self.x_pert,
            f_plus: &mut self.f_plus,
            f_minus: &mut self.f_minus,
            cp_scratch: &mut self.cp_scratch,
        }
    }
}

/// Owned state of the single-granule platen experiment.
#[derive(Clone, Debug)]
pub struct PlatenStore {
    /// The granule.
    pub granule: GranuleStore,
    /// Time-step scratch.
    pub power: PowerStore,
}

impl PlatenStore {
    /// Buffers for `mesh` with `points` integration points per element.
    pub fn new(mesh: &OwnedReference, points: usize) -> Self {
        Self {
            granule: GranuleStore::new(mesh, points),
            power: PowerStore::new(mesh, points),
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> PlatenBuffers<'_> {
        PlatenBuffers {
            granule: self.granule.buffers(),
            power: self.power.buffers(),
        }
    }
}

/// Owned buffers of the discrete-element pour ([`PourBuffers`]).
#[derive(Clone, Debug)]
pub struct PourStore {
    /// Centres, m.
    pub x: Vec<[Real; 3]>,
    /// Velocities, m/s.
    pub v: Vec<[Real; 3]>,
    omega: Vec<[Real; 3]>,
    f: Vec<[Real; 3]>,
    torque: Vec<[Real; 3]>,
    x_built: Vec<[Real; 3]>,
    pairs: Vec<Pair>,
    pairs_old: Vec<Pair>,
    head: Vec<u32>,
    next: Vec<u32>,
}

impl PourStore {
    /// Buffers for `params`, with room for 12 candidate pairs per sphere;
    /// the parameters are checked first ([`PourParams::validate`]), since
    /// the grid of parameters the pour refuses can have too many cells to
    /// allocate.
    pub fn new(params: &PourParams) -> Result<Self, PourError> {
        params.validate()?;
        let n = params.granules;
        let z = [0.0; 3];
        let empty = Pair { i: 0, j: 0, xi: z };
        Ok(Self {
            x: vec![z; n],
            v: vec![z; n],
            omega: vec![z; n],
            f: vec![z; n],
            torque: vec![z; n],
            x_built: vec![z; n],
            pairs: vec![empty; 12 * n],
            pairs_old: vec![empty; 12 * n],
            head: vec![0; params.grid().cells()],
            next: vec![0; n],
        })
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> PourBuffers<'_> {
        PourBuffers {
            x: &mut self.x,
            v: &mut self.v,
            omega: &mut self.omega,
            f: &mut self.f,
            torque: &mut self.torque,
            x_built: &mut self.x_built,
            pairs: &mut self.pairs,
            pairs_old: &mut self.pairs_old,
            head: &mut self.head,
            next: &mut self.next,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshLevel;

    /// The bytes `store`'s buffers hold, every field named (a new field
    /// fails to compile here until it is counted).
    fn bytes(store: &GranuleStore) -> u64 {
        use core::mem::size_of_val;
        let GranuleStore {
            x,
            v,
            v_star,
            x_pred,
            f_int,
            f_c,
            f_d,
            mass,
            contact_mass,
            fixed,
            cp_inv,
        } = store;
        let nodes: usize = [x, v, v_star, x_pred, f_int, f_c, f_d]
            .iter()
            .map(|b| size_of_val(b.as_slice()))
            .sum();
        (nodes
            + size_of_val(mass.as_slice())
            + size_of_val(contact_mass.as_slice())
            + size_of_val(fixed.as_slice())
            + size_of_val(cp_inv.as_slice())) as u64
    }

    /// Pour parameters the kernel refuses are refused before the buffers
    /// are sized from their grid (a lattice spacing of 0 made the grid's
    /// lattice walk without end; an infinite die gives a grid too large to
    /// allocate), with the kernel's own error naming the field.
    #[test]
    fn pour_buffers_are_refused_for_refused_parameters() {
        let standard = PourParams::standard(1200.0, 1);
        assert!(PourStore::new(&standard).is_ok());
        let refused = PourParams {
            lattice_spacing: 0.0,
            ..standard
        };
        assert!(matches!(
            refused.validate(),
            Err(PourError::InvalidParameter {
                field: "lattice_spacing",
                ..
            })
        ));
        assert_eq!(PourStore::new(&refused).map(|_| ()), refused.validate());
    }

    /// What `bytes_for` predicts is what `new` allocates, for the one-point
    /// element and F-bar's eight points, on two mesh levels.
    #[test]
    fn the_predicted_bytes_are_those_allocated() {
        for level in [MeshLevel::new(4, 1), MeshLevel::STANDARD] {
            let mesh = OwnedReference::sphere(0.5e-3, level, false).unwrap();
            for points in [1, 8] {
                let store = GranuleStore::new(&mesh, points);
                assert_eq!(
                    GranuleStore::bytes_for(&mesh, points),
                    bytes(&store),
                    "{level} with {points} points"
                );
            }
        }
    }
}
