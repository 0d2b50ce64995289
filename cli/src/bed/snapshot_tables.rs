//! The tables of a bed snapshot, beside `bed_<k>.vtu` in `vtk/`, for
//! readers without ParaView (granule ids are the snapshot's `granule`
//! field). A snapshot taken before the run's first step (the one at
//! C = 0) has none: no contact has been detected yet.
//!
//! * `contacts_<k>.csv`, the contact network: one row per granule pair
//!   that carried a contact force in the snapshot's step, in the order of
//!   (granule_a, granule_b), granule_a < granule_b. From it a reader gets
//!   the distribution of the contact forces (force chains), the fabric
//!   tensor ⟨n ⊗ n⟩ of the branch vectors l, each granule's coordination,
//!   and the granular stress −Σ f ⊗ l / V (f the force on granule_a: the
//!   sum Σ f ⊗ l is negative in compression, hence the sign, to match the
//!   snapshots' compression-positive stresses).
//! * `granules_<k>.csv`: one row per granule: its centre of mass, relative
//!   density, Heywood coefficients and contacts, for density profiles along
//!   and across the die.
//!
//! The forces are the snapshot step's, summed over its contact sweeps (the
//! force the step applied), not averaged over an interval as
//! `compression.csv`'s punch forces are: the kinematic contact enforces
//! each constraint anew every step (physics.md §5). In a quasi-static bed
//! they vary little from step to step: measured once (session 50, a
//! scratch print of 13 consecutive steps of a 100-granule 8x2 bed at
//! C = 0.20), a pair's normal force varied by a median coefficient of
//! variation of 7 % over the pairs, 5 % over the pairs carrying more
//! than a tenth of the largest force. The test
//! `tests/cli_bed_contacts.rs` checks that the forces balance on the
//! granules inside a bed.

use granbed_kernel::Real;

use super::snapshots::GranuleFields;
use crate::assembly::Assembly;
use crate::csv::Field;

/// Columns of a contacts file, in order: (name, meaning with its unit).
pub const CONTACT_COLUMNS: [(&str, &str); 13] = [
    (
        "granule_a",
        "the first granule of the pair (the snapshot's granule id)",
    ),
    ("granule_b", "the second granule (granule_b > granule_a)"),
    (
        "normal_force_n",
        "Σ of the normal forces of the pair's constraints in the step, N",
    ),
    (
        "friction_force_n",
        "magnitude of the pair's total friction force, N",
    ),
    (
        "force_x_n",
        "x of the total force on granule_a, N (granule_b: the opposite)",
    ),
    ("force_y_n", "y of that force, N"),
    (
        "force_z_n",
        "z of that force, N (z along the die axis, upwards)",
    ),
    (
        "constraints",
        "node-to-face constraints that carried a force in the step's first contact sweep (0: the pair touched only in a later sweep)",
    ),
    (
        "slipping",
        "the most node constraints at their friction cap μF_n in any one sweep of the step (can exceed constraints, which counts the first sweep only; a pair slides as a whole only when its friction_force_n reaches μ normal_force_n)",
    ),
    (
        "branch_x_m",
        "x of the branch vector: granule_b's centre of mass − granule_a's, m",
    ),
    ("branch_y_m", "y of the branch vector, m"),
    ("branch_z_m", "z of the branch vector, m"),
    ("branch_length_m", "the branch vector's length, m"),
];

/// One pair in contact: what [`CONTACT_COLUMNS`] lists.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactRow {
    /// First granule (the smaller id).
    pub a: u32,
    /// Second granule.
    pub b: u32,
    /// Σ F_n over the pair's constraints, N.
    pub normal_n: Real,
    /// |Σ friction force on a|, N.
    pub friction_n: Real,
    /// Total force on a, N.
    pub force_on_a: [Real; 3],
    /// Constraints that carried a force in the step's first sweep.
    pub constraints: usize,
    /// The most constraints at the friction cap in one sweep.
    pub slipping: usize,
    /// Centre of mass of b − that of a, m.
    pub branch: [Real; 3],
}

/// The pairs of `asm` that carried a force in its last step, ordered by
/// (a, b) (a < b in every candidate pair,
/// [`granbed_kernel::contact::broad::GranulePair`]), with the granules'
/// `centres` of mass ([`centres_of_mass`]).
pub fn contact_rows(asm: &Assembly<'_>, centres: &[[Real; 3]]) -> Vec<ContactRow> {
    let contact = asm.contact();
    let mut rows: Vec<ContactRow> = contact
        .pairs()
        .iter()
        .zip(contact.work())
        // A pair that touched only in a later sweep has no first-sweep
        // constraint but carried a force.
        .filter(|(_, w)| w.touching() || w.step.normal > 0.0)
        .map(|(p, w)| {
            let (ca, cb) = (centres[p.a as usize], centres[p.b as usize]);
            let f = &w.step;
            ContactRow {
                a: p.a,
                b: p.b,
                normal_n: f.normal,
                friction_n: norm(f.friction_on_a),
                force_on_a: f.total_on_a,
                constraints: f.constraints,
                slipping: f.slipping,
                branch: core::array::from_fn(|i| cb[i] - ca[i]),
            }
        })
        .collect();
    rows.sort_by_key(|r| (r.a, r.b));
    rows
}

impl ContactRow {
    /// The row's cells, as [`CONTACT_COLUMNS`] lists them.
    pub fn fields(&self) -> [Field; 13] {
        let [fx, fy, fz] = self.force_on_a;
        let [lx, ly, lz] = self.branch;
        [
            self.a.into(),
            self.b.into(),
            self.normal_n.into(),
            self.friction_n.into(),
            fx.into(),
            fy.into(),
            fz.into(),
            Field::Int(self.constraints as u64),
            Field::Int(self.slipping as u64),
            lx.into(),
            ly.into(),
            lz.into(),
            norm(self.branch).into(),
        ]
    }
}

fn norm(v: [Real; 3]) -> Real {
    v.iter().map(|x| x * x).sum::<Real>().sqrt()
}

/// Columns of a granules file, in order: (name, meaning with its unit).
pub const GRANULE_COLUMNS: [(&str, &str); 8] = [
    ("granule", "the granule's id"),
    (
        "x_m",
        "x of its centre of mass, m (the die axis is x = y = 0)",
    ),
    ("y_m", "y of its centre of mass, m"),
    (
        "z_m",
        "z of its centre of mass, m (the lower punch is z = 0)",
    ),
    ("relative_density", "its relative density η0 V0/V"),
    (
        "heywood_dv",
        "its Heywood coefficient d_V S/V (6 for a sphere)",
    ),
    ("heywood_d", "d S/V with the nominal diameter d"),
    (
        "contacts",
        "granules it carried a contact force with in the step (its rows in contacts_<k>.csv; compression.csv's Z counts only the pairs touching in the step's first sweep)",
    ),
];

/// Every granule's centre of mass, m, in granule order.
pub fn centres_of_mass(asm: &Assembly<'_>) -> Vec<[Real; 3]> {
    (0..asm.granules().len())
        .map(|g| asm.centre_of_mass(g))
        .collect()
}

/// One row per granule: [`GRANULE_COLUMNS`] from its centre of mass
/// (`centres`), its `fields` and the number of `contacts` rows it is in.
pub fn granule_rows(
    centres: &[[Real; 3]],
    fields: &GranuleFields,
    contacts: &[ContactRow],
) -> Vec<[Field; 8]> {
    let mut touching = vec![0_u64; centres.len()];
    for c in contacts {
        touching[c.a as usize] += 1;
        touching[c.b as usize] += 1;
    }
    touching
        .iter()
        .enumerate()
        .map(|(g, &n)| {
            let [x, y, z] = centres[g];
            [
                Field::Int(g as u64),
                x.into(),
                y.into(),
                z.into(),
                fields.relative_density[g].into(),
                fields.heywood_dv[g].into(),
                fields.heywood_d[g].into(),
                Field::Int(n),
            ]
        })
        .collect()
}

/// File name of the contacts of snapshot `k`.
pub fn contacts_file(k: usize) -> String {
    format!("contacts_{k}.csv")
}

/// File name of the granules of snapshot `k`.
pub fn granules_file(k: usize) -> String {
    format!("granules_{k}.csv")
}
