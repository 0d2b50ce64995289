//! VTU snapshots of a bed (`vtk/` in the output): at each of the scene's
//! `snapshot_strains`, `bed_<k>.vtu` holds every granule's outer surface
//! quads (or, on request, all its hexes) in the current configuration,
//! with cell data per granule: `granule` (id), `relative_density`
//! (η_g = η0 V0/V), `heywood_dv` (α_SV with d_V) and `heywood_d` (α_SV with
//! the nominal diameter); and per element (a surface quad shows the hex
//! under it): `pressure_pa` (−tr σ/3), `von_mises_pa`, `axial_stress_pa`
//! (−σ_zz, along the punches' axis) and `element_relative_density` (η0/J).
//! `bed.pvd` lists the snapshots with the strain as the timestep and is
//! rewritten after each one, so a run that stops early leaves a valid
//! collection. k is the index of the strain among the
//! scene's sorted snapshot strains, and the collection lists every
//! snapshot up to the current one whose file is there, so a resumed run
//! continues the collection of the run it resumes.
//!
//! The `.vtu` files are written with the `vtkio` crate (VTK XML, binary
//! data arrays base64-encoded inline); `vtkio` has no `.pvd` collection
//! type, so that short index is written here.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};
use granbed_kernel::Real;
use granbed_kernel::analysis::bed::{granule_shape, surface_geometry};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, IOBuffer, UnstructuredGridPiece,
    Version, VertexNumbers, Vtk,
};

use super::density_map::{density_map, write_map};
use super::network::{interior, network_stats, write_network};
use super::section::{Frame, Quantity, SectionInput, section_svg};
use super::snapshot_tables::{
    CONTACT_COLUMNS, ContactRow, GRANULE_COLUMNS, centres_of_mass, contact_rows, contacts_file,
    granule_rows, granules_file,
};
use super::stress_profile::{WallReadings, stress_profile, write_profile};
use crate::assembly::Assembly;
use crate::csv::write_table;
use crate::model::OwnedReference;
use crate::output::{create_file, finish_file, write_text};

/// Sub-directory of the output directory holding the snapshots.
pub const VTK_DIR: &str = "vtk";

/// File name of the snapshot collection in [`VTK_DIR`].
pub const PVD_FILE: &str = "bed.pvd";

/// What a snapshot holds of each granule.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SnapshotContent {
    /// The outer surface quads (`VTK_QUAD`), on the surface nodes only.
    #[default]
    Surfaces,
    /// Every hex (`VTK_HEXAHEDRON`, hex8 order = VTK's), on all nodes.
    Hexes,
}

/// The per-granule cell data of a snapshot, one value per granule.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GranuleFields {
    /// η_g = η0 V0/V (NaN for a degenerate surface).
    pub relative_density: Vec<Real>,
    /// α_SV = d_V S/V.
    pub heywood_dv: Vec<Real>,
    /// α_SV = d S/V with the nominal diameter d.
    pub heywood_d: Vec<Real>,
}

/// The per-granule fields of `asm` (granule meshes `mesh`), with the
/// nominal diameter `d_fixed_m` for `heywood_d`. A granule whose surface
/// is degenerate gets NaN (shown, not an error).
pub fn granule_fields(asm: &Assembly<'_>, mesh: &OwnedReference, d_fixed_m: Real) -> GranuleFields {
    let eta0 = asm.params().material.params.eta0;
    let v0 = surface_geometry(&mesh.positions, &mesh.quads).map_or(Real::NAN, |(_, v)| v);
    let mut f = GranuleFields::default();
    for g in asm.granules() {
        let s = granule_shape(&g.x, &mesh.quads, eta0, v0, d_fixed_m).ok();
        f.relative_density
            .push(s.map_or(Real::NAN, |s| s.relative_density));
        f.heywood_dv.push(s.map_or(Real::NAN, |s| s.heywood_dv));
        f.heywood_d.push(s.map_or(Real::NAN, |s| s.heywood_fixed));
    }
    f
}

/// The per-element cell data of a snapshot, `[granule][hex]` flattened:
/// each element's stress and volume at the snapshot's positions
/// ([`granbed_kernel::granule::forces::element_stresses`]: what the next
/// step's element pass computes, the stored states unchanged).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementFields {
    /// Pressure −tr σ/3, Pa, positive in compression.
    pub pressure_pa: Vec<Real>,
    /// Von Mises stress √(3/2)‖dev σ‖, Pa.
    pub von_mises_pa: Vec<Real>,
    /// Axial stress −σ_zz along the punches' axis, Pa, positive in
    /// compression.
    pub axial_stress_pa: Vec<Real>,
    /// The element's relative density η0/J (J its current / reference
    /// volume).
    pub relative_density: Vec<Real>,
    /// Lateral stress −(σ_xx + σ_yy)/2 across the punches' axis, Pa,
    /// positive in compression: the mean of the radial and hoop stresses.
    pub lateral_stress_pa: Vec<Real>,
    /// The element's current volume J V0, m³.
    pub volume_m3: Vec<Real>,
    /// Height of the element's centre (the mean of its nodes' z), m.
    pub height_m: Vec<Real>,
    /// Distance of the element's centre from the die's axis (the z axis),
    /// m.
    pub radius_m: Vec<Real>,
}

/// The pressure −tr σ/3 and von Mises stress √(3/2)‖dev σ‖ of a Cauchy
/// stress σ (Voigt `[xx, yy, zz, yz, xz, xy]`), Pa.
pub fn pressure_and_von_mises(sigma: &[Real; 6]) -> (Real, Real) {
    use granbed_kernel::tensor::{deviator, norm, trace};
    (
        -trace(sigma) / 3.0,
        granbed_kernel::math::sqrt(1.5) * norm(&deviator(sigma)),
    )
}

/// The element fields of every granule of `asm` (meshes `mesh`), granules
/// in parallel (each on its own; the values do not depend on the threads).
/// A granule whose element update fails (an inverted element) gets NaN
/// throughout: the picture shows it, the run's own step reports it.
pub fn element_fields(asm: &Assembly<'_>, mesh: &OwnedReference) -> ElementFields {
    use granbed_kernel::granule::forces::{ElementStress, element_stresses};
    use rayon::prelude::*;
    let params = asm.params();
    let eta0 = params.material.params.eta0;
    let hexes = mesh.hexes.len();
    let per_granule: Vec<Vec<ElementStress>> = asm
        .granules()
        .par_iter()
        .map(|g| {
            let mut out = vec![ElementStress::default(); hexes];
            let ok = element_stresses(
                &mesh.view(),
                &params.material,
                &params.elements,
                &g.x,
                &g.cp_inv,
                &mut out,
            );
            if ok.is_err() {
                out.fill(ElementStress {
                    sigma: [Real::NAN; 6],
                    j: Real::NAN,
                });
            }
            out
        })
        .collect();
    let mut f = ElementFields::default();
    for (g, out) in asm.granules().iter().zip(&per_granule) {
        for ((o, hex), reference) in out.iter().zip(&mesh.hexes).zip(&mesh.elements) {
            let (p, q) = pressure_and_von_mises(&o.sigma);
            f.pressure_pa.push(p);
            f.von_mises_pa.push(q);
            f.axial_stress_pa.push(-o.sigma[2]);
            f.relative_density.push(eta0 / o.j);
            f.lateral_stress_pa.push(-0.5 * (o.sigma[0] + o.sigma[1]));
            f.volume_m3.push(o.j * reference.volume);
            let centre = hex.iter().fold([0.0; 3], |c, &n| {
                let x = g.x[n as usize];
                [c[0] + x[0], c[1] + x[1], c[2] + x[2]]
            });
            f.height_m.push(centre[2] / 8.0);
            f.radius_m.push(centre[0].hypot(centre[1]) / 8.0);
        }
    }
    f
}

/// The hex of each surface quad of `mesh` (the hex holding its four
/// nodes), in quad order.
pub fn quad_hexes(mesh: &OwnedReference) -> anyhow::Result<Vec<usize>> {
    let mut hexes_of_node: Vec<Vec<usize>> = vec![Vec::new(); mesh.positions.len()];
    for (h, hex) in mesh.hexes.iter().enumerate() {
        for &n in hex {
            if let Some(list) = hexes_of_node.get_mut(n as usize) {
                list.push(h);
            }
        }
    }
    mesh.quads
        .iter()
        .enumerate()
        .map(|(q, quad)| {
            hexes_of_node
                .get(quad[0] as usize)
                .and_then(|list| {
                    list.iter()
                        .copied()
                        .find(|&h| quad.iter().all(|n| mesh.hexes[h].contains(n)))
                })
                .with_context(|| format!("surface quad {q} is the face of no hex"))
        })
        .collect()
}

/// The snapshot of `asm` as a VTK unstructured grid: the granules one
/// after the other (points, then cells, in granule order), with the
/// granule fields `fields` ([`granule_fields`]) and the element fields
/// `elements` ([`element_fields`]).
pub fn snapshot_vtk(
    asm: &Assembly<'_>,
    mesh: &OwnedReference,
    fields: &GranuleFields,
    elements: &ElementFields,
    content: SnapshotContent,
) -> anyhow::Result<Vtk> {
    let nodes = mesh.positions.len();
    // Nodes written per granule and the first of them; surfaces use the
    // last `surface_nodes` nodes, which carry every surface quad.
    let (first, count) = match content {
        SnapshotContent::Surfaces => (nodes - mesh.surface_nodes.min(nodes), mesh.surface_nodes),
        SnapshotContent::Hexes => (0, nodes),
    };
    let local: Vec<u64> = match content {
        SnapshotContent::Surfaces => mesh
            .quads
            .iter()
            .flatten()
            .map(|&n| (n as usize).checked_sub(first).filter(|&i| i < count))
            .collect::<Option<Vec<usize>>>()
            .context("a surface quad uses a node outside the surface nodes")?
            .into_iter()
            .map(|i| i as u64)
            .collect(),
        SnapshotContent::Hexes => mesh.hexes.iter().flatten().map(|&n| u64::from(n)).collect(),
    };
    let (cell_type, per_cell) = match content {
        SnapshotContent::Surfaces => (CellType::Quad, 4),
        SnapshotContent::Hexes => (CellType::Hexahedron, 8),
    };
    let cells_per_granule = local.len() / per_cell;
    let granules = asm.granules();
    let mut points = Vec::with_capacity(3 * count * granules.len());
    let mut connectivity = Vec::with_capacity(local.len() * granules.len());
    for (g, store) in granules.iter().enumerate() {
        if store.x.len() != nodes {
            bail!("granule {g} has {} nodes, the mesh {nodes}", store.x.len());
        }
        points.extend(store.x[first..first + count].iter().flatten());
        let base = (g * count) as u64;
        connectivity.extend(local.iter().map(|i| base + i));
    }
    let cells = cells_per_granule * granules.len();
    let offsets = (1..=cells).map(|c| (c * per_cell) as u64).collect();
    let per_cell_values = |v: &[Real]| -> Vec<Real> {
        v.iter()
            .flat_map(|&x| core::iter::repeat_n(x, cells_per_granule))
            .collect()
    };
    let ids: Vec<i64> = (0..granules.len() as i64)
        .flat_map(|g| core::iter::repeat_n(g, cells_per_granule))
        .collect();
    // Each cell's element: the hex itself, or the hex under the quad.
    let cell_hex: Vec<usize> = match content {
        SnapshotContent::Surfaces => quad_hexes(mesh)?,
        SnapshotContent::Hexes => (0..mesh.hexes.len()).collect(),
    };
    let per_element = |v: &[Real]| -> Vec<Real> {
        v.chunks(mesh.hexes.len().max(1))
            .flat_map(|granule| cell_hex.iter().map(|&h| granule[h]))
            .collect()
    };
    let cell_data = vec![
        Attribute::generic("granule", 1).with_data(ids),
        // The active scalars: what a viewer colours by at first.
        Attribute::scalars("relative_density", 1)
            .with_data(per_cell_values(&fields.relative_density)),
        Attribute::generic("heywood_dv", 1).with_data(per_cell_values(&fields.heywood_dv)),
        Attribute::generic("heywood_d", 1).with_data(per_cell_values(&fields.heywood_d)),
        Attribute::generic("pressure_pa", 1).with_data(per_element(&elements.pressure_pa)),
        Attribute::generic("von_mises_pa", 1).with_data(per_element(&elements.von_mises_pa)),
        Attribute::generic("axial_stress_pa", 1).with_data(per_element(&elements.axial_stress_pa)),
        Attribute::generic("element_relative_density", 1)
            .with_data(per_element(&elements.relative_density)),
    ];
    Ok(Vtk {
        version: Version::new_xml(1, 0),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity,
                    offsets,
                },
                types: vec![cell_type; cells],
            },
            data: Attributes {
                point: Vec::new(),
                cell: cell_data,
            },
        }),
    })
}

/// The text of a ParaView collection (`.pvd`) of `(timestep, file)`
/// entries, the files relative to the collection.
pub fn pvd_text(entries: &[(Real, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, file) in entries {
        s.push_str(&format!(
            "    <DataSet timestep=\"{t:?}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
            crate::output::escape_markup(file)
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// File name of snapshot `k`.
pub fn snapshot_file(k: usize) -> String {
    format!("bed_{k}.vtu")
}

/// File name of the section picture of snapshot `k` ([`section_svg`]).
pub fn section_file(k: usize) -> String {
    format!("section_{k}.svg")
}

/// The k of a file `name` of the form `<prefix><k><suffix>` with k in
/// decimal digits (a snapshot `bed_<k>.vtu`, a section picture
/// `section_<k>.svg`), or `None`.
pub fn numbered(name: &str, prefix: &str, suffix: &str) -> Option<usize> {
    let k = name.strip_prefix(prefix)?.strip_suffix(suffix)?;
    if k.is_empty() || !k.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    k.parse().ok()
}

/// The files `<prefix><k><suffix>` in `dir` ([`numbered`]), in the order
/// of k; none if the folder is not there.
pub fn numbered_files(dir: &Path, prefix: &str, suffix: &str) -> Vec<(usize, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut found: Vec<(usize, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            Some((numbered(&name, prefix, suffix)?, e.path()))
        })
        .collect();
    found.sort_unstable();
    found
}

/// Every file `<prefix><k>.csv` in `vtk_dir`, in the order of k, read by
/// `read` (given k and the path), and why each file that could not be read
/// was left out of the summary's `field` (a damaged file must not cost the
/// run's other outputs). Nothing if the folder is not there.
pub fn read_snapshot_files<T>(
    vtk_dir: &Path,
    prefix: &str,
    field: &str,
    read: impl Fn(usize, &Path) -> anyhow::Result<T>,
) -> (Vec<T>, Vec<String>) {
    let (mut read_in, mut left_out) = (Vec::new(), Vec::new());
    for (k, path) in numbered_files(vtk_dir, prefix, ".csv") {
        match read(k, &path) {
            Ok(t) => read_in.push(t),
            Err(e) => left_out.push(format!("{e:#}; left out of {field}")),
        }
    }
    (read_in, left_out)
}

/// The die's radius and the upper punch's height of `asm`, m (from its
/// walls; NaN and 0 for a scene without them).
pub fn die_geometry(asm: &Assembly<'_>) -> (Real, Real) {
    use granbed_kernel::contact::wall::Wall;
    let (mut die_radius_m, mut upper_z_m) = (Real::NAN, 0.0);
    for wall in asm.walls() {
        match wall {
            Wall::Die { radius } => die_radius_m = radius,
            // The upper punch: normal −z, gap −z − offset.
            Wall::Plane(p) if p.normal[2] < 0.0 => upper_z_m = -p.offset,
            Wall::Plane(_) => {}
        }
    }
    (die_radius_m, upper_z_m)
}

/// What the walls of `asm` (granules meshed as `mesh`) read in its last
/// step, as pressures on the compact between its punches.
pub fn wall_readings(asm: &Assembly<'_>, mesh: &OwnedReference) -> WallReadings {
    use crate::assembly::die::wall_index::{DIE, LOWER, UPPER};
    let (die_radius_m, height_m) = die_geometry(asm);
    let area = core::f64::consts::PI * die_radius_m * die_radius_m;
    let walls = &asm.last().walls;
    let params = asm.params();
    let granule_volume: Real = mesh.elements.iter().map(|e| e.volume).sum();
    let mass = asm.granules().len() as Real * params.material.density0 * granule_volume;
    let volume = area * height_m;
    // Σ over the walls in their order, a fixed order.
    let virial = |a: usize, b: usize| walls.iter().map(|w| w.virial[a][b]).sum::<Real>();
    WallReadings {
        height_m,
        upper_punch_pa: walls[UPPER].normal / area,
        lower_punch_pa: walls[LOWER].normal / area,
        die_wall_pa: walls[DIE].normal / (2.0 * core::f64::consts::PI * die_radius_m * height_m),
        weight_pa: mass * params.gravity_m_s2 / area,
        walls_lateral_pa: -0.5 * (virial(0, 0) + virial(1, 1)) / volume,
        walls_axial_pa: -virial(2, 2) / volume,
    }
}

/// What the section picture of `asm` at `strain` shows: the granules'
/// positions, the mesh, the axial stress of `elements`, the die's radius
/// and the upper punch's height (from the walls).
fn section_input<'a>(
    asm: &'a Assembly<'_>,
    mesh: &'a OwnedReference,
    elements: &'a ElementFields,
    strain: Real,
) -> SectionInput<'a> {
    let (die_radius_m, upper_z_m) = die_geometry(asm);
    SectionInput {
        granules: asm.granules().iter().map(|g| g.x.as_slice()).collect(),
        hexes: &mesh.hexes,
        quads: &mesh.quads,
        values: &elements.axial_stress_pa,
        quantity: Quantity::AxialStress,
        frame: Frame::Die {
            radius_m: die_radius_m,
            upper_z_m,
        },
        title: format!("Section through the die axis at C = {strain:.3}: axial stress −σzz"),
    }
}

/// Removes the snapshots an earlier run left in `out`/[`VTK_DIR`]
/// (`bed_<k>.vtu`, `section_<k>.svg`, `contacts_<k>.csv`, `granules_<k>.csv`,
/// `network_<k>.csv`, `stress_<k>.csv`, `density_map_<k>.csv` and
/// [`PVD_FILE`]; nothing else), so that a fresh run
/// into the same directory does not leave stale snapshots beside its own
/// (e.g. of strains it does not reach). Returns how many files went.
pub fn remove_old(out: &Path) -> anyhow::Result<usize> {
    let dir = out.join(VTK_DIR);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Ok(0);
    };
    let mut removed = 0;
    for entry in entries {
        let entry = entry.with_context(|| format!("cannot list `{}`", dir.display()))?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let snapshot = numbered(name, "bed_", ".vtu").is_some()
            || numbered(name, "section_", ".svg").is_some()
            || numbered(name, "contacts_", ".csv").is_some()
            || numbered(name, "granules_", ".csv").is_some()
            || numbered(name, "network_", ".csv").is_some()
            || numbered(name, "stress_", ".csv").is_some()
            || numbered(name, "density_map_", ".csv").is_some();
        if (snapshot || name == PVD_FILE) && entry.path().is_file() {
            std::fs::remove_file(entry.path())
                .with_context(|| format!("cannot remove `{}`", entry.path().display()))?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// Writes the snapshots of one run into `<out>/vtk/`.
#[derive(Debug)]
pub struct SnapshotWriter {
    dir: PathBuf,
    content: SnapshotContent,
    d_fixed_m: Real,
    strains: Vec<Real>,
}

impl SnapshotWriter {
    /// A writer into `out`/[`VTK_DIR`] (created at the first snapshot) for
    /// the scene's `snapshot_strains`; `d_fixed_m` is the nominal granule
    /// diameter for `heywood_d`.
    pub fn new(
        out: &Path,
        content: SnapshotContent,
        snapshot_strains: &[Real],
        d_fixed_m: Real,
    ) -> Self {
        let mut strains = snapshot_strains.to_vec();
        strains.sort_by(Real::total_cmp);
        strains.dedup();
        Self {
            dir: out.join(VTK_DIR),
            content,
            d_fixed_m,
            strains,
        }
    }

    /// Index k of the snapshot at `strain` (a strain not in the scene's
    /// list is added to it).
    fn index(&mut self, strain: Real) -> usize {
        match self.strains.iter().position(|&c| c == strain) {
            Some(k) => k,
            None => {
                let k = self.strains.partition_point(|&c| c < strain);
                self.strains.insert(k, strain);
                k
            }
        }
    }

    /// Writes `bed_<k>.vtu` of `asm` at `strain`, its section picture, its
    /// density map ([`super::density_map`]) and, if `asm` has taken a
    /// step, its tables ([`super::snapshot_tables`]), and rewrites
    /// `bed.pvd`.
    pub fn write(
        &mut self,
        strain: Real,
        asm: &Assembly<'_>,
        mesh: &OwnedReference,
    ) -> anyhow::Result<()> {
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create directory `{}`", self.dir.display()))?;
        let k = self.index(strain);
        let path = self.dir.join(snapshot_file(k));
        let elements = element_fields(asm, mesh);
        let granules = granule_fields(asm, mesh, self.d_fixed_m);
        let vtk = snapshot_vtk(asm, mesh, &granules, &elements, self.content)?;
        let mut file = create_file(&path)?;
        vtk.write_xml(&mut file)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("cannot write `{}`", path.display()))?;
        finish_file(file, &path)?;
        write_text(
            &self.dir.join(section_file(k)),
            &section_svg(&section_input(asm, mesh, &elements, strain)),
        )?;
        let (die_radius_m, height_m) = die_geometry(asm);
        write_map(
            &self.dir,
            &density_map(k, strain, &elements, die_radius_m, height_m),
        )?;
        // The tables need a step's contact forces: none at C = 0, before
        // the first step.
        if asm.has_stepped() {
            let centres = centres_of_mass(asm);
            let contacts = contact_rows(asm, &centres);
            write_table(
                &self.dir.join(contacts_file(k)),
                &CONTACT_COLUMNS,
                contacts.iter().map(ContactRow::fields),
            )?;
            write_table(
                &self.dir.join(granules_file(k)),
                &GRANULE_COLUMNS,
                granule_rows(&centres, &granules, &contacts).into_iter(),
            )?;
            let mu = asm.params().contact.friction;
            let inside = interior(&centres, &contacts, die_radius_m, height_m, self.d_fixed_m);
            write_network(
                &self.dir,
                k,
                &network_stats(k, strain, mu, &contacts, inside),
            )?;
            let profile =
                stress_profile(k, strain, &elements, die_radius_m, wall_readings(asm, mesh));
            write_profile(&self.dir, &profile)?;
        }
        let entries: Vec<(Real, String)> = self.strains[..=k]
            .iter()
            .enumerate()
            .map(|(j, &c)| (c, snapshot_file(j)))
            .filter(|(_, name)| self.dir.join(name).is_file())
            .collect();
        let pvd = self.dir.join(PVD_FILE);
        write_text(&pvd, &pvd_text(&entries))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniaxial compression σ_zz = −s: p = s/3, von Mises s; pure shear
    /// σ_xy = t: p = 0, von Mises √3 t; a hydrostatic stress has none.
    #[test]
    fn pressure_and_von_mises_of_known_stresses() {
        let close = |a: Real, b: Real| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        let (p, q) = pressure_and_von_mises(&[0.0, 0.0, -3e4, 0.0, 0.0, 0.0]);
        assert!(close(p, 1e4) && close(q, 3e4), "{p} {q}");
        let (p, q) = pressure_and_von_mises(&[0.0, 0.0, 0.0, 0.0, 0.0, 2e3]);
        assert!(close(p, 0.0) && close(q, 3.0_f64.sqrt() * 2e3), "{p} {q}");
        let (p, q) = pressure_and_von_mises(&[-5.0, -5.0, -5.0, 0.0, 0.0, 0.0]);
        assert!(close(p, 5.0) && q == 0.0, "{p} {q}");
    }

    #[test]
    fn the_collection_escapes_and_keeps_the_strains() {
        let text = pvd_text(&[(0.0, "bed_0.vtu".into()), (0.1, "a&b.vtu".into())]);
        assert!(text.contains("timestep=\"0.0\""), "{text}");
        assert!(text.contains("timestep=\"0.1\" group=\"\" part=\"0\" file=\"a&amp;b.vtu\""));
        assert!(text.ends_with("</VTKFile>\n"));
    }
}
