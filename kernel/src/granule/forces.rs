//! Internal forces of one granule: every element of the shared reference
//! mesh evaluated at the granule's current positions, assembled into nodal
//! forces in element order (deterministic).

use core::fmt;

use crate::Real;
use crate::constitutive::{UpdateError, UpdateInfo, UpdateOptions};
use crate::element::batch::{BATCH, BatchOutput, ElementPath, Sink, evaluate};
use crate::element::fbar::{fbar_elastic_energy, fbar_forces, fbar_stress};
use crate::element::force::HexForces;
use crate::element::hex8::HexCoords;
use crate::material::Material;
use crate::mesh::reference::ReferenceMesh;
use crate::tensor::Voigt;

/// The element formulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementKind {
    /// One-point uniform-gradient hex with FB hourglass stiffness (production).
    OnePoint,
    /// 2×2×2 F-bar hex (verification; 8 integration points, no hourglass).
    FBar,
}

/// The range of [`UpdateOptions::yield_tolerance`] as the checks name it.
pub const YIELD_TOLERANCE_RANGE: &str = "0 <= tolerance <= 1e-6";

/// Element-loop settings of a granule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementSettings {
    /// Element formulation.
    pub kind: ElementKind,
    /// Constitutive switches.
    pub update: UpdateOptions,
    /// Hourglass coefficient κ (one-point element only).
    pub hourglass_kappa: Real,
}

impl ElementSettings {
    /// [`ForcesError::InvalidParameter`] unless 0 ≤ κ ≤ 1 (a NaN κ made
    /// every force NaN, a negative one a negative hourglass energy) and
    /// the yield tolerance is valid
    /// ([`UpdateOptions::yield_tolerance_is_valid`]).
    pub fn check(&self) -> Result<(), ForcesError> {
        if !(0.0..=1.0).contains(&self.hourglass_kappa) {
            return Err(ForcesError::InvalidParameter {
                field: "hourglass_kappa",
                value: self.hourglass_kappa,
                allowed: "0 <= kappa <= 1",
            });
        }
        if !self.update.yield_tolerance_is_valid() {
            return Err(ForcesError::InvalidParameter {
                field: "yield_tolerance",
                value: self.update.yield_tolerance,
                allowed: YIELD_TOLERANCE_RANGE,
            });
        }
        Ok(())
    }

    /// Integration points, hence C_p⁻¹ states, per element: 1 or 8.
    pub fn points_per_element(&self) -> usize {
        match self.kind {
            ElementKind::OnePoint => 1,
            ElementKind::FBar => 8,
        }
    }
}

/// An element whose update failed, with the kernel's reason.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementFailure {
    /// Element index in the reference mesh.
    pub element: usize,
    /// What went wrong.
    pub error: UpdateError,
}

impl fmt::Display for ElementFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "element {}: {}", self.element, self.error)
    }
}

impl core::error::Error for ElementFailure {}

/// Why an element pass could not run, or stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ForcesError {
    /// A buffer's length does not match the mesh: `x` and `f` hold one
    /// entry per node, `cp_inv` one per integration point, the mesh's
    /// `elements` one per hex (for
    /// [`crate::element::batch::one_point_elements`]: `refs` and `cp_inv`
    /// one per hex).
    BufferLength {
        /// The buffer.
        buffer: &'static str,
        /// Entries expected.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// A hex names a node beyond the node buffers.
    NodeId {
        /// The largest node id of the mesh's hexes.
        id: u32,
        /// Nodes (ids must be below this).
        nodes: usize,
    },
    /// A setting is out of range.
    InvalidParameter {
        /// The [`ElementSettings`] field.
        field: &'static str,
        /// Value given.
        value: Real,
        /// Allowed range.
        allowed: &'static str,
    },
    /// An element's update failed.
    Element(ElementFailure),
}

impl fmt::Display for ForcesError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferLength {
                buffer,
                expected,
                got,
            } => write!(
                f,
                "element buffer `{buffer}` has {got} entries, expected {expected}"
            ),
            Self::NodeId { id, nodes } => write!(
                f,
                "a hex names node {id}, but there are {nodes} nodes (ids 0..{nodes})"
            ),
            Self::InvalidParameter {
                field,
                value,
                allowed,
            } => write!(f, "invalid `{field}` = {value}: allowed range is {allowed}"),
            Self::Element(failure) => failure.fmt(f),
        }
    }
}

impl core::error::Error for ForcesError {}

impl From<ElementFailure> for ForcesError {
    fn from(failure: ElementFailure) -> Self {
        Self::Element(failure)
    }
}

/// Checks an element pass's buffers against `mesh` (lengths `x`, `cp_inv`,
/// `f`), as [`internal_forces`] and [`elastic_energy`] do before they run,
/// so that no length or node id can make the loop index out of bounds: `x` (and
/// `f`, when given) one entry per node, `cp_inv` `points` per hex, the
/// mesh's `elements` one per hex, every node id of `hexes` below the node
/// count (one pass over the ids: a maximum the compiler vectorises, about
/// 1 % of an element pass).
pub fn check_element_buffers(
    mesh: &ReferenceMesh<'_>,
    points: usize,
    x: usize,
    cp_inv: usize,
    f: Option<usize>,
) -> Result<(), ForcesError> {
    let nodes = mesh.mesh.positions.len();
    let hexes = mesh.mesh.hexes.len();
    for (buffer, expected, got) in [
        ("x", nodes, x),
        ("f", nodes, f.unwrap_or(nodes)),
        ("cp_inv", hexes * points, cp_inv),
        ("elements", hexes, mesh.elements.len()),
    ] {
        if got != expected {
            return Err(ForcesError::BufferLength {
                buffer,
                expected,
                got,
            });
        }
    }
    let id = mesh
        .mesh
        .hexes
        .as_flattened()
        .iter()
        .fold(0, |m, &i| m.max(i));
    if hexes > 0 && id as usize >= nodes {
        return Err(ForcesError::NodeId { id, nodes });
    }
    Ok(())
}

/// What an element pass measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceSummary {
    /// Hourglass energy Σ (k/2)Σ|q|², J.
    pub hourglass_energy: Real,
    /// Plastic dissipation of this step Σ V0 Δγ (2β² + ⅔ a1 α²), J.
    pub plastic_dissipation: Real,
    /// Smallest element J = det F̄.
    pub min_j: Real,
    /// Elements that yielded.
    pub plastic_elements: usize,
    /// Most return-map iterations of any element.
    pub max_iterations: u32,
    /// Elements whose a2 was clamped (η ≤ η_c).
    pub a2_clamped: usize,
}

/// Evaluates all elements at positions `x` (`[node][xyz]`, m) and writes the
/// assembled internal + hourglass force into `f` (`[node][xyz]`, N, zeroed
/// first). `cp_inv` holds [`ElementSettings::points_per_element`] C_p⁻¹ per
/// element, element by element (in/out; F-bar's eight in
/// [`crate::element::hex8::gauss_points`] order). The one-point element runs on the
/// fastest [`ElementPath`] of the processor (all paths give the same bits).
///
/// Lengths: `x`, `f` = nodes; `cp_inv` = hexes × points per element; the
/// mesh's `elements` = hexes; node ids below the node count. Checked
/// before anything is written ([`ForcesError::BufferLength`],
/// [`ForcesError::NodeId`]); an element whose update fails stops the pass
/// with [`ForcesError::Element`].
pub fn internal_forces(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    x: &[[Real; 3]],
    cp_inv: &mut [Voigt],
    f: &mut [[Real; 3]],
) -> Result<ForceSummary, ForcesError> {
    internal_forces_on(ElementPath::fastest(), mesh, mat, settings, x, cp_inv, f)
}

/// [`internal_forces`] with the one-point element on a chosen `path`
/// (to compare the paths, or to pin one).
pub fn internal_forces_on(
    path: ElementPath,
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    x: &[[Real; 3]],
    cp_inv: &mut [Voigt],
    f: &mut [[Real; 3]],
) -> Result<ForceSummary, ForcesError> {
    settings.check()?;
    check_element_buffers(
        mesh,
        settings.points_per_element(),
        x.len(),
        cp_inv.len(),
        Some(f.len()),
    )?;
    f.fill([0.0; 3]);
    let mut s = ForceSummary {
        min_j: Real::INFINITY,
        ..ForceSummary::default()
    };
    match settings.kind {
        ElementKind::OnePoint => {
            let mut sink = Assemble { f, summary: &mut s };
            // The buffers and ids are checked above.
            evaluate(
                path,
                mat,
                &settings.update,
                settings.hourglass_kappa,
                mesh.mesh.hexes,
                mesh.elements,
                mesh.batches,
                x,
                cp_inv,
                &mut sink,
            )
            .map_err(|(element, error)| ElementFailure { element, error })?;
        }
        ElementKind::FBar => {
            let (states, _) = cp_inv.as_chunks_mut::<8>();
            for ((element, hex), c) in mesh.mesh.hexes.iter().enumerate().zip(states.iter_mut()) {
                let xr = core::array::from_fn(|i| mesh.mesh.positions[hex[i] as usize]);
                let xe = core::array::from_fn(|i| x[hex[i] as usize]);
                let out = fbar_forces(mat, &settings.update, &xr, &xe, c)
                    .map_err(|error| ElementFailure { element, error })?;
                scatter(f, hex, |i, a| out.f[i][a]);
                s.plastic_dissipation += out.plastic_dissipation;
                s.min_j = crate::math::min(s.min_j, out.min_j);
                if out.plastic_points > 0 {
                    s.plastic_elements += 1;
                    s.max_iterations = s.max_iterations.max(out.max_iterations);
                }
                s.a2_clamped += out.a2_clamped;
            }
        }
    }
    Ok(s)
}

/// Adds an element's nodal forces to the granule's `f` at its nodes `hex`:
/// `fe(i, a)` is component a of node i's force. Node by node in element
/// order, so the sums keep their order however the element hands them
/// over.
#[inline(always)]
fn scatter(f: &mut [[Real; 3]], hex: &[u32; 8], fe: impl Fn(usize, usize) -> Real) {
    for (i, id) in hex.iter().enumerate() {
        let fi = &mut f[*id as usize];
        fi[0] += fe(i, 0);
        fi[1] += fe(i, 1);
        fi[2] += fe(i, 2);
    }
}

/// The one-point element loop's sink: each element's forces into the
/// granule's `f`, its energies and diagnostics into `summary`, in element
/// order.
struct Assemble<'a> {
    f: &'a mut [[Real; 3]],
    summary: &'a mut ForceSummary,
}

impl Assemble<'_> {
    /// Adds one element's energies and diagnostics to the summary.
    #[inline(always)]
    fn tally(
        &mut self,
        hourglass_energy: Real,
        plastic_dissipation: Real,
        j: Real,
        info: &UpdateInfo,
    ) {
        let s = &mut *self.summary;
        s.hourglass_energy += hourglass_energy;
        s.plastic_dissipation += plastic_dissipation;
        s.min_j = crate::math::min(s.min_j, j);
        if info.plastic {
            s.plastic_elements += 1;
            s.max_iterations = s.max_iterations.max(info.iterations);
        }
        s.a2_clamped += usize::from(info.coefficients.a2_clamped);
    }
}

impl Sink for Assemble<'_> {
    #[inline(always)]
    fn element(&mut self, _: usize, hex: &[u32; 8], out: &HexForces) {
        scatter(self.f, hex, |i, a| out.f[i][a]);
        self.tally(
            out.hourglass_energy,
            out.plastic_dissipation,
            out.j,
            &out.info,
        );
    }

    /// Straight from the lanes, sparing the default's copy of each
    /// element's forces out of them into an [`HexForces`] (30
    /// instructions per element fewer: BENCHMARKS.md, session 32).
    #[inline(always)]
    fn batch(&mut self, _: usize, hexes: &[[u32; 8]; BATCH], out: &BatchOutput<'_>) {
        for (l, hex) in hexes.iter().enumerate() {
            scatter(self.f, hex, |i, a| out.forces[i][a].0[l]);
            self.tally(
                out.hourglass_energy.0[l],
                out.plastic_dissipation[l],
                out.j.0[l],
                &out.info[l],
            );
        }
    }
}

/// An element's stress and volume change ([`element_stresses`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ElementStress {
    /// Cauchy stress σ, Pa, Voigt `[xx, yy, zz, yz, xz, xy]`, positive in
    /// tension.
    pub sigma: Voigt,
    /// The element's volume ratio J = det F̄ (current / reference volume;
    /// the element's local relative density is η0/J).
    pub j: Real,
}

/// The Cauchy stress and volume ratio of every element of a granule at
/// positions `x`: what the next element pass would compute from the stored
/// states `cp_inv`, which are read, not changed (each update runs on a
/// copy, so a trial state beyond the yield surface is returned onto it).
/// `out[e]` is element e's: σ = τ/J at the one-point element's point, the
/// volume average of the Gauss points' for F-bar
/// ([`crate::element::fbar::fbar_stress`]); either way σ v is the element's
/// virial Σ_I x_I ⊗ f_I of its internal forces (without the one-point
/// element's hourglass forces). For pictures and
/// post-processing (the bed's snapshots); `x` and `cp_inv` as in
/// [`internal_forces`], checked the same way, `out` one entry per hex. An
/// element whose update fails stops the pass with its index.
pub fn element_stresses(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    x: &[[Real; 3]],
    cp_inv: &[Voigt],
    out: &mut [ElementStress],
) -> Result<(), ForcesError> {
    settings.check()?;
    check_element_buffers(
        mesh,
        settings.points_per_element(),
        x.len(),
        cp_inv.len(),
        None,
    )?;
    let hexes = mesh.mesh.hexes;
    if out.len() != hexes.len() {
        return Err(ForcesError::BufferLength {
            buffer: "out",
            expected: hexes.len(),
            got: out.len(),
        });
    }
    let opts = &settings.update;
    for (element, (hex, o)) in hexes.iter().zip(out.iter_mut()).enumerate() {
        let xe: HexCoords = core::array::from_fn(|i| x[hex[i] as usize]);
        let stress = match settings.kind {
            ElementKind::OnePoint => {
                let f =
                    crate::element::force::mean_deformation_gradient(&mesh.elements[element], &xe);
                let j = crate::tensor::det_mat(&f);
                crate::constitutive::update_point(mat, opts, &f, &mut cp_inv[element].clone())
                    .map(|up| (up.tau.map(|t| t / j), j))
            }
            ElementKind::FBar => {
                let xr = core::array::from_fn(|i| mesh.mesh.positions[hex[i] as usize]);
                let (states, _) = cp_inv.as_chunks::<8>();
                fbar_stress(mat, opts, &xr, &xe, &states[element])
            }
        };
        let (sigma, j) = stress.map_err(|error| ElementFailure { element, error })?;
        *o = ElementStress { sigma, j };
    }
    Ok(())
}

/// Stored elastic energy Σ ∫ψ(b^e, J^e) dV0 of a granule, J, with
/// b^e = F C_p⁻¹ Fᵀ and J^e = det F √det C_p⁻¹ at each integration point
/// (F = F̄ of the element's formulation). `x` and `cp_inv` as in
/// [`internal_forces`], checked the same way.
pub fn elastic_energy(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    x: &[[Real; 3]],
    cp_inv: &[Voigt],
) -> Result<Real, ForcesError> {
    check_element_buffers(
        mesh,
        settings.points_per_element(),
        x.len(),
        cp_inv.len(),
        None,
    )?;
    let mut energy = 0.0;
    match settings.kind {
        ElementKind::OnePoint => {
            for ((hex, r), c) in mesh
                .mesh
                .hexes
                .iter()
                .zip(mesh.elements.iter())
                .zip(cp_inv.iter())
            {
                let xe = core::array::from_fn(|i| x[hex[i] as usize]);
                let f = crate::element::force::mean_deformation_gradient(r, &xe);
                energy += r.volume * crate::constitutive::elastic::energy_density_of(mat, &f, c);
            }
        }
        ElementKind::FBar => {
            let (states, _) = cp_inv.as_chunks::<8>();
            for (hex, c) in mesh.mesh.hexes.iter().zip(states.iter()) {
                let xr = core::array::from_fn(|i| mesh.mesh.positions[hex[i] as usize]);
                let xe = core::array::from_fn(|i| x[hex[i] as usize]);
                energy += fbar_elastic_energy(mat, &xr, &xe, c);
            }
        }
    }
    Ok(energy)
}
