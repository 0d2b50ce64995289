//! Contact between two deforming granules: node-to-surface detection on the
//! predicted configuration and the kinematic ("defence-node") forces with
//! Coulomb friction (physics.md §5.2–§5.4).
//!
//! A pair (A, B) is handled in two steps that the driver may run for many
//! pairs in parallel:
//!
//! 1. [`detect`] finds the constraints: in pass A→B every surface node of A
//!    inside the pair's overlap box is projected on B's quads (and in pass
//!    B→A the other way round); a node gets at most one constraint per
//!    opposing granule. The constraints go into a caller slice; a full
//!    slice is an error ([`ContactError::Capacity`]), never a silent drop.
//! 2. [`forces`] turns each constraint into the force that closes its
//!    predicted gap in one step, shared between the slave node and the
//!    defence node by their effective masses, and writes one
//!    [`NodeForce`] per node touched into a per-pair slice. The driver sums
//!    those per node in a fixed order, so the result does not depend on
//!    the thread count.
//!
//! Between the two, [`mark_involvement`] counts how many contacts each node
//! takes part in, for the mass sharing m̃ = m/n of §5.3.

use core::fmt;

use crate::Real;
use crate::contact::face_lists::{FaceLists, check_len, face_diagonal};
use crate::contact::quad::{
    QuadProjection, QuadSieve, Vec3, dot, norm, project, project_clamped, sub,
};
use crate::contact::surface::{Aabb, SurfaceBody};
use crate::math::{abs, max, sqrt};

/// Settings of the granule–granule contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSettings {
    /// Coulomb friction coefficient μ; ≥ 0 (0 skips friction).
    pub friction: Real,
    /// Tolerance of the inside-the-face test on |ξ|, |η| (physics.md: 1e-6).
    pub inside_tolerance: Real,
    /// Gap window g_max as a fraction of the face diagonal (physics.md:
    /// 0.25): deeper projections are far-side faces, not contacts.
    pub window_fraction: Real,
    /// Margin by which the pair's overlap box is grown, m.
    pub margin: Real,
    /// Symmetric two-pass (each side slave once, weight ½ where both
    /// passes see the spot, see [`forces`]) or a single pass with A's nodes
    /// as slaves (weight 1).
    pub symmetric: bool,
    /// Capture distance, m (0 ≤ c ≤ `margin`): a node with no penetration
    /// that lies in front of a face by less than this (inside it, normals
    /// opposing) gets a *near* constraint, with gap ≥ 0, so that a driver
    /// that holds the constraints over steps without searching
    /// ([`regap`]) sees it close. [`forces`] and [`mark_involvement`] skip
    /// near constraints (and watches, below; gap ≥ 0: a driver may hand
    /// them [`penetrating`]'s part). 0: none (the detection as it was, bit
    /// for bit).
    pub capture: Real,
    /// With a capture distance: a node that lies in front of a face's plane
    /// by less than it but just off the face (by at most 0.25 in ξ or η: it
    /// is coming over the face's edge), and has neither a contact nor a
    /// near constraint, gets a *watch* ([`Constraint::watch`]) on the
    /// nearest such face, which [`regap`] turns into a contact once the
    /// node crosses the face. false: no watches (as before the field).
    pub watch_beside: bool,
    /// Also estimate the contact area ([`PairForce::area`]): each
    /// constraint then evaluates its slave node's tributary area, which no
    /// force needs (false: the area is 0; the forces are the same bits).
    pub contact_area: bool,
    /// How far a held constraint's node may slide along its face before
    /// [`regap`] projects it on the face afresh, m (> 0; 0 or less: at
    /// every call; ∞ or NaN: never, the first-order gap as before): the
    /// tangential part of x̃_s − Σ Nᵢ x̃ᵢ.
    /// On a curved face the gap along the held normal misses about
    /// s²/(2R) after a slide s (R the face's radius of curvature).
    pub reproject_slide: Real,
    /// **Choice (deviates from physics.md §5.2):** a node behind faces it
    /// projects inside (within the gap window) is held against the nearest
    /// of them, the smallest |g|, whatever its own averaged normal, where
    /// physics.md also asks n_s·n < 0. Far past 30 % a granule's surface
    /// folds at some nodes, whose averaged normal then turns up to 90° and
    /// more from the face they press into: those nodes failed the normal
    /// test while inside the other granule (a winding-number check), no
    /// contact held them, and they sank by up to half an element unseen,
    /// as the overlap measure uses the same detection (BENCHMARKS.md,
    /// "Overlaps the detection did not see"). The far-side faces the
    /// normal test was to reject are still rejected: by the gap window and
    /// by the check that no other face lies nearer. Near constraints,
    /// watches and concave edges keep the normal test. false: the normal
    /// test on every hit (physics.md, as before the field).
    pub nearest_penetrated_face: bool,
}

impl PairSettings {
    /// The gap window g_max of the face with corners `corners`, m: the
    /// [`Self::window_fraction`] of its longer diagonal. A node deeper
    /// behind the face is no contact of it.
    #[inline]
    fn window(&self, corners: &[Vec3; 4]) -> Real {
        self.window_fraction * face_diagonal(corners)
    }

    /// physics.md's choices: μ = `friction`, inside tolerance 1e-6, window
    /// 0.25 × face diagonal, 20 µm margin, symmetric two-pass, the normal
    /// test on every hit; no capture distance, no watches, no contact
    /// area, held constraints never re-projected.
    pub fn standard(friction: Real) -> Self {
        Self {
            friction,
            inside_tolerance: 1e-6,
            window_fraction: 0.25,
            margin: 20e-6,
            capture: 0.0,
            symmetric: true,
            contact_area: false,
            watch_beside: false,
            reproject_slide: Real::INFINITY,
            nearest_penetrated_face: false,
        }
    }
}

/// The partition weight w of constraint `c` among `constraints` (pass A→B
/// then pass B→A, each in increasing slave order): ½ when the opposite
/// pass also holds this spot (a corner of `c`'s face is a slave there),
/// else 1.
///
/// **Choice (physics.md §5.3 gives w = ½ throughout):** with ½ on a
/// one-sided contact (a node of A inside a face of B, no node of B inside
/// A there, as at a vertex or an edge) only half the gap closed per step,
/// and a 40-granule die kept up to 5 µm of penetration (3.6 % of the
/// element size; `tests/assembly_die.rs`). Where both passes see the spot
/// their two halves still add up to one closure.
///
/// `split` is where pass B→A starts in `constraints` (computed once per
/// [`forces`] call), and `c.quad` must be a quad of `quads`.
#[inline]
fn partition_weight(
    c: &Constraint,
    constraints: &[Constraint],
    split: usize,
    quads: &[[u32; 4]],
) -> Real {
    let other = match c.side {
        Side::A => Side::B,
        Side::B => Side::A,
    };
    let (pass_a, pass_b) = constraints.split_at(split.min(constraints.len()));
    let opposite = match other {
        Side::A => pass_a,
        Side::B => pass_b,
    };
    let shared = quads.get(c.quad as usize).is_some_and(|q| {
        q.iter()
            .any(|&id| opposite.binary_search_by(|k| k.slave.cmp(&id)).is_ok())
    });
    if shared { 0.5 } else { 1.0 }
}

/// Which body of the pair holds a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The pair's first body.
    A,
    /// The pair's second body.
    B,
}

/// One node-to-face constraint found on the predicted configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constraint {
    /// The body that holds the slave node (the face is on the other one).
    pub side: Side,
    /// Slave node id in its body.
    pub slave: u32,
    /// Master quad id in the other body.
    pub quad: u32,
    /// Bilinear weights Nᵢ of the quad's corners at the contact point.
    pub weights: [Real; 4],
    /// Master's outward unit normal at the contact point.
    pub normal: Vec3,
    /// Signed gap n·(x̃_s − x_c), m: < 0 for a contact, ≥ 0 for a near
    /// constraint or a watch ([`PairSettings::capture`]).
    pub gap: Real,
    /// A *watch* (a near constraint beside its face, see
    /// [`PairSettings::capture`]): the node lay in front of the face's
    /// plane but just off the face, so weights, normal and gap are those
    /// of that outside projection (gap ≥ 0), and [`regap`] projects the
    /// node onto the face afresh instead of re-measuring them.
    pub watch: bool,
}

impl Default for Constraint {
    /// A placeholder (zero weights and gap) for sizing caller lists.
    fn default() -> Self {
        Self {
            side: Side::A,
            slave: 0,
            quad: 0,
            weights: [0.0; 4],
            normal: [0.0; 3],
            gap: 0.0,
            watch: false,
        }
    }
}

impl Default for NodeForce {
    /// A zero force on node 0 of A, for sizing caller lists.
    fn default() -> Self {
        Self {
            side: Side::A,
            node: 0,
            force: [0.0; 3],
        }
    }
}

/// A force on one node, as a pair writes it for the driver to sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeForce {
    /// The body of the node.
    pub side: Side,
    /// Node id in that body.
    pub node: u32,
    /// Force, N.
    pub force: Vec3,
}

/// What one pair's force pass did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairForce {
    /// Σ F_n over the constraints (both passes), N.
    pub normal: Real,
    /// Σ of the friction forces on A, N.
    pub friction_on_a: Vec3,
    /// Total force on A (normal + friction), N; B gets the opposite.
    pub total_on_a: Vec3,
    /// Constraints that carried a force.
    pub constraints: usize,
    /// Constraints at the friction cap (slipping).
    pub slipping: usize,
    /// Contact area estimate, m²: Σ w × the slave node's tributary area
    /// (a quarter of its quads' areas), so a spot both passes see counts
    /// once; 0 unless [`PairSettings::contact_area`].
    pub area: Real,
    /// Most negative predicted gap, m (0 if none).
    pub min_gap: Real,
}

/// A contact buffer or input problem. A full list ([`Self::Capacity`]):
/// the driver must grow the buffer and retry, or report it: a contact is
/// never dropped silently. The other variants are caller errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactError {
    /// A fixed-capacity list is full.
    Capacity {
        /// Which list.
        buffer: &'static str,
        /// Its capacity.
        capacity: usize,
    },
    /// A buffer has the wrong length.
    BufferLength {
        /// Which buffer.
        buffer: &'static str,
        /// Length needed.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// An id read from a caller buffer (a constraint's slave node or
    /// master quad, a quad's corner node, a node's quad list, a face list)
    /// is not an index of the buffer it selects from.
    IdOutOfRange {
        /// Where the id was read, e.g. `constraints.slave` or `quads`.
        buffer: &'static str,
        /// Index of the entry of `buffer` that holds it.
        index: usize,
        /// The id.
        id: u32,
        /// Length of the buffer the id indexes (ids must be below it).
        len: usize,
    },
    /// A scalar input is outside its range.
    InvalidParameter {
        /// Name of the argument or field.
        field: &'static str,
        /// The value given.
        value: Real,
        /// The allowed range.
        allowed: &'static str,
    },
}

impl fmt::Display for ContactError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Capacity { buffer, capacity } => {
                write!(f, "contact list `{buffer}` is full ({capacity} entries)")
            }
            Self::BufferLength {
                buffer,
                expected,
                got,
            } => write!(
                f,
                "contact buffer `{buffer}` has length {got}, expected at least {expected}"
            ),
            Self::IdOutOfRange {
                buffer,
                index,
                id,
                len,
            } => write!(
                f,
                "contact id out of range: `{buffer}` entry {index} holds id {id}, \
                 but the buffer it indexes has {len} entries"
            ),
            Self::InvalidParameter {
                field,
                value,
                allowed,
            } => write!(
                f,
                "invalid contact input `{field}` = {value}: allowed range is {allowed}"
            ),
        }
    }
}

impl core::error::Error for ContactError {}

/// A master face near a pair's overlap region, cached once per pass: its
/// predicted corners, its gap window and its box grown by the window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CandidateFace {
    /// Quad id in the master body.
    pub quad: u32,
    /// Predicted corner positions, m.
    pub corners: [Vec3; 4],
    /// Gap window g_max of this face, m.
    pub window: Real,
    /// The face's box.
    pub bounds: Aabb,
    /// The face's box grown by `window`.
    pub reach: Aabb,
    /// The cheap pre-test of the projection (`None`: degenerate face).
    pub sieve: Option<QuadSieve>,
}

impl Default for CandidateFace {
    fn default() -> Self {
        Self {
            quad: 0,
            corners: [[0.0; 3]; 4],
            window: 0.0,
            bounds: Aabb::EMPTY,
            reach: Aabb::EMPTY,
            sieve: None,
        }
    }
}

/// Finds the constraints of the pair (A, B) on the predicted configuration
/// and writes them to `out`, pass A→B first (A's nodes as slaves, in node
/// order), then B→A when symmetric. `scratch` holds the candidate faces of
/// a pass and needs at least as many entries as the larger quad count.
/// Returns the number of constraints.
pub fn detect(
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
    settings: &PairSettings,
    scratch: &mut [CandidateFace],
    out: &mut [Constraint],
) -> Result<usize, ContactError> {
    check_buffers(a, b, scratch)?;
    let mut count = detect_pass(a, b, Side::A, settings, scratch, &mut AllFaces, out, 0)?;
    if settings.symmetric {
        count = detect_pass(b, a, Side::B, settings, scratch, &mut AllFaces, out, count)?;
    }
    Ok(count)
}

/// Finds the same constraints as [`detect`], to the bit, trying each slave
/// node only against the faces of its list (`lists[0]`: pass A→B,
/// `lists[1]`: pass B→A, from [`crate::contact::face_lists::build`] on
/// anchors that no surface node of A or B has left by more than the
/// lists' drift). `slot` has one entry per quad of the larger body, all
/// `u32::MAX` on entry, and is left so. The lists' layout is checked first
/// ([`FaceLists::check`]).
pub fn detect_listed(
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
    settings: &PairSettings,
    lists: [&FaceLists<'_>; 2],
    scratch: &mut [CandidateFace],
    slot: &mut [u32],
    out: &mut [Constraint],
) -> Result<usize, ContactError> {
    check_buffers(a, b, scratch)?;
    check_len("slot", slot.len(), a.quads.len().max(b.quads.len()))?;
    lists[0].check()?;
    if settings.symmetric {
        lists[1].check()?;
    }
    let mut faces = ListedFaces {
        lists: lists[0],
        slot,
    };
    let mut count = detect_pass(a, b, Side::A, settings, scratch, &mut faces, out, 0)?;
    if settings.symmetric {
        faces.lists = lists[1];
        count = detect_pass(b, a, Side::B, settings, scratch, &mut faces, out, count)?;
    }
    Ok(count)
}

fn check_buffers(
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
    scratch: &[CandidateFace],
) -> Result<(), ContactError> {
    check_len("scratch", scratch.len(), a.quads.len().max(b.quads.len()))?;
    for body in [a, b] {
        if body.quad_bounds.len() != body.quads.len() {
            return Err(ContactError::BufferLength {
                buffer: "quad_bounds",
                expected: body.quads.len(),
                got: body.quad_bounds.len(),
            });
        }
    }
    Ok(())
}

/// How far outside a face (in ξ, η beyond ±1) a node may project and still
/// be tried against a concave edge.
const EDGE_REACH: Real = 0.25;

/// Which master faces a pass builds and which a slave node is tried
/// against: all of them ([`AllFaces`]) or the node's list
/// ([`ListedFaces`]). Both give a node its candidate faces in ascending
/// quad order, so both find the same constraints.
trait PassFaces {
    /// How many master quads may become candidates.
    fn quad_count(&self, master: &SurfaceBody<'_>) -> usize;
    /// The `i`-th of them, ascending in `i`.
    fn quad(&self, i: usize) -> usize;
    /// Records that quad `q` is candidate `index` of the pass.
    fn note(&mut self, q: usize, index: usize);
    /// Slave nodes that may find a face (ascending), each with its index
    /// for [`Self::faces_of`].
    fn nodes(&self, slave: &SurfaceBody<'_>) -> impl Iterator<Item = (usize, usize)>;
    /// Node `k`'s candidates among `candidates`, ascending.
    fn faces_of<'c>(
        &self,
        k: usize,
        candidates: &'c [CandidateFace],
    ) -> impl Iterator<Item = &'c CandidateFace> + Clone;
    /// Undoes [`Self::note`] at the end of the pass.
    fn clear(&mut self);
}

/// Every master face, every slave surface node.
struct AllFaces;

impl PassFaces for AllFaces {
    fn quad_count(&self, master: &SurfaceBody<'_>) -> usize {
        master.quads.len()
    }
    fn quad(&self, i: usize) -> usize {
        i
    }
    fn note(&mut self, _: usize, _: usize) {}
    fn nodes(&self, slave: &SurfaceBody<'_>) -> impl Iterator<Item = (usize, usize)> {
        (slave.first_surface..slave.x_pred.len()).map(|s| (s, 0))
    }
    fn faces_of<'c>(
        &self,
        _: usize,
        candidates: &'c [CandidateFace],
    ) -> impl Iterator<Item = &'c CandidateFace> + Clone {
        candidates.iter()
    }
    fn clear(&mut self) {}
}

/// The faces of each node's list that are candidates of this sweep.
struct ListedFaces<'l, 's> {
    lists: &'l FaceLists<'l>,
    /// Per master quad: its candidate index, `u32::MAX` if none.
    slot: &'s mut [u32],
}

impl PassFaces for ListedFaces<'_, '_> {
    fn quad_count(&self, _: &SurfaceBody<'_>) -> usize {
        self.lists.used.len()
    }
    fn quad(&self, i: usize) -> usize {
        self.lists.used[i] as usize
    }
    fn note(&mut self, q: usize, index: usize) {
        self.slot[q] = index as u32;
    }
    fn nodes(&self, _: &SurfaceBody<'_>) -> impl Iterator<Item = (usize, usize)> {
        self.lists
            .nodes
            .iter()
            .enumerate()
            .map(|(k, &s)| (s as usize, k))
    }
    fn faces_of<'c>(
        &self,
        k: usize,
        candidates: &'c [CandidateFace],
    ) -> impl Iterator<Item = &'c CandidateFace> + Clone {
        let slot: &[u32] = self.slot;
        self.lists
            .faces_of(k)
            .iter()
            .filter_map(move |&q| candidates.get(*slot.get(q as usize)? as usize))
    }
    fn clear(&mut self) {
        for &q in self.lists.used {
            if let Some(slot) = self.slot.get_mut(q as usize) {
                *slot = u32::MAX;
            }
        }
    }
}

/// One pass: `slave`'s nodes against `master`'s faces (those `pass`
/// offers); appends to `out` from `start` and returns the new length.
#[allow(clippy::too_many_arguments)]
fn detect_pass(
    slave: &SurfaceBody<'_>,
    master: &SurfaceBody<'_>,
    side: Side,
    settings: &PairSettings,
    scratch: &mut [CandidateFace],
    pass: &mut impl PassFaces,
    out: &mut [Constraint],
    start: usize,
) -> Result<usize, ContactError> {
    let m = settings.margin;
    let region = slave
        .bounds
        .expanded(m)
        .intersect(&master.bounds.expanded(m));
    if region.is_empty() {
        return Ok(start);
    }
    // Master faces near the region and within reach of the slave's
    // bounding sphere, with their windows and reach.
    let slave_reach = slave.sphere.radius + m;
    let mut faces = 0;
    for i in 0..pass.quad_count(master) {
        let q = pass.quad(i);
        let Some(bounds) = master.quad_bounds.get(q) else {
            pass.clear();
            return Err(ContactError::IdOutOfRange {
                buffer: "face lists (used)",
                index: i,
                id: u32::try_from(q).unwrap_or(u32::MAX),
                len: master.quad_bounds.len(),
            });
        };
        if bounds.overlaps(&region) && bounds.distance_to(&slave.sphere.centre) <= slave_reach {
            let Some(corners) = master.corners(q) else {
                pass.clear();
                return Err(master.quad_error(q));
            };
            let window = settings.window(&corners);
            scratch[faces] = CandidateFace {
                quad: q as u32,
                corners,
                window,
                bounds: *bounds,
                reach: bounds.expanded(window),
                sieve: QuadSieve::new(&corners),
            };
            pass.note(q, faces);
            faces += 1;
        }
    }
    let candidates = &scratch[..faces];
    let mut count = start;
    // Only nodes inside the master's bounding sphere can be behind its
    // surface.
    let (centre, reach) = (master.sphere.centre, master.sphere.radius + m);
    let mut failed = None;
    for (s, k) in pass.nodes(slave) {
        let Some(&p) = slave.x_pred.get(s) else {
            failed = Some(ContactError::IdOutOfRange {
                buffer: "face lists (nodes)",
                index: k,
                id: u32::try_from(s).unwrap_or(u32::MAX),
                len: slave.x_pred.len(),
            });
            break;
        };
        if !region.contains(&p) || norm(&sub(&p, &centre)) > reach {
            continue;
        }
        let mut bad_normal = false;
        let hit = closest_face(
            slave,
            s,
            &p,
            pass.faces_of(k, candidates),
            settings,
            &mut bad_normal,
        );
        if bad_normal {
            failed = Some(
                slave
                    .node_normal(s)
                    .err()
                    .unwrap_or(ContactError::IdOutOfRange {
                        buffer: "node_quads",
                        index: s,
                        id: u32::MAX,
                        len: slave.quads.len(),
                    }),
            );
            break;
        }
        if let Some(c) = hit {
            let Some(slot) = out.get_mut(count) else {
                failed = Some(ContactError::Capacity {
                    buffer: "constraints",
                    capacity: count,
                });
                break;
            };
            *slot = Constraint {
                side,
                slave: s as u32,
                quad: c.quad,
                weights: c.projection.weights,
                normal: c.projection.normal,
                gap: c.projection.gap,
                watch: c.watch,
            };
            count += 1;
        }
    }
    pass.clear();
    match failed {
        Some(e) => Err(e),
        None => Ok(count),
    }
}

#[derive(Clone, Copy)]
struct Hit {
    quad: u32,
    projection: QuadProjection,
    /// A watch ([`Constraint::watch`]).
    watch: bool,
}

/// The face node `s` of `slave` penetrates, by physics.md §5.2's tests:
/// inside the face, −g_max < g < 0, opposing normals; the smallest |g|
/// wins. With no face, a concave edge or corner shared by several faces is
/// tried: the closest point on it with the faces' averaged normal. `p` is
/// the node's predicted position. If the node's normal is needed and an
/// id of its quads is outside the buffers, `bad_normal` is set (and no
/// face opposes the node).
fn closest_face<'c>(
    slave: &SurfaceBody<'_>,
    s: usize,
    p: &Vec3,
    candidates: impl Iterator<Item = &'c CandidateFace> + Clone,
    settings: &PairSettings,
    bad_normal: &mut bool,
) -> Option<Hit> {
    let p = *p;
    let mut slave_normal: Option<Vec3> = None;
    let mut opposing = |n: &Vec3| {
        let ns = *slave_normal.get_or_insert_with(|| {
            slave.try_node_normal(s).unwrap_or_else(|| {
                *bad_normal = true;
                [0.0; 3]
            })
        });
        dot(&ns, n) < 0.0
    };
    let mut best: Option<Hit> = None;
    // The nearest face in front within the capture distance (a near
    // constraint, returned only when the node penetrates nothing).
    let mut near: Option<Hit> = None;
    // With no near constraint either: the nearest face in front within the
    // capture distance that the node lies just beside (off the face by at
    // most `EDGE_REACH` in ξ or η: come over its edge), held as a watch.
    let mut watch: Option<Hit> = None;
    let capture = settings.capture;
    let mut near_outside = false;
    // The sieve passes what projects within this reach of the face.
    let reach = max(EDGE_REACH, settings.inside_tolerance);
    for face in candidates.clone() {
        let front = if capture > 0.0 {
            crate::math::min(capture, face.window)
        } else {
            0.0
        };
        if !face.reach.contains(&p)
            || !face
                .sieve
                .is_some_and(|s| s.may_touch_within(&p, face.window, front, reach))
        {
            continue;
        }
        let Some(pr) = project(&p, &face.corners) else {
            continue;
        };
        if front > 0.0 && pr.gap >= 0.0 && pr.gap < front {
            // In front within the capture distance: inside the face a near
            // constraint, just beside it a watch; the nearest of each kind.
            let beside = !pr.inside(settings.inside_tolerance);
            let slot = if beside { &mut watch } else { &mut near };
            if (!beside || (settings.watch_beside && pr.inside(EDGE_REACH)))
                && slot.as_ref().is_none_or(|h| pr.gap < h.projection.gap)
                && opposing(&pr.normal)
            {
                *slot = Some(Hit {
                    quad: face.quad,
                    projection: pr,
                    watch: beside,
                });
            }
        }
        if !(pr.gap < 0.0 && pr.gap > -face.window) {
            continue;
        }
        if !pr.inside(settings.inside_tolerance) {
            // Only a node just off the face can be at a concave edge.
            near_outside |= pr.inside(EDGE_REACH);
            continue;
        }
        if !(settings.nearest_penetrated_face || opposing(&pr.normal)) {
            continue;
        }
        let hit = Hit {
            quad: face.quad,
            projection: pr,
            watch: false,
        };
        if best
            .as_ref()
            .is_none_or(|h| abs(pr.gap) < abs(h.projection.gap))
        {
            best = Some(hit);
        }
    }
    if let Some(hit) = best {
        // The nearest surface point decides, edges included: a face whose
        // clamped closest point is nearer than the hit's depth means the
        // node sits beside that face, and the deep hit is the far side of a
        // folded surface (seen at 55 % strain in a dense bed: a node just
        // off one face, 7 µm from it, "inside" a tilted neighbour 70 µm
        // deep; the force that closed that gap shot the face's corner off
        // at 200× the punch speed). A face sharing an edge with the hit's
        // cannot be nearer (its closest point on that edge is a point of
        // the hit's face too), so only other faces can.
        let depth = abs(hit.projection.gap);
        let nearer = candidates.clone().any(|face| {
            face.quad != hit.quad
                && face.bounds.distance_to(&p) < depth
                && project_clamped(&p, &face.corners)
                    .is_some_and(|pr| norm(&sub(&p, &pr.point)) < depth * (1.0 - NEARER_TOLERANCE))
        });
        if !nearer {
            return best;
        }
    } else if !near_outside {
        return near.or(watch);
    }
    concave_edge(&p, candidates)
        .filter(|h| opposing(&h.projection.normal))
        .or(near)
        .or(watch)
}

/// Moves the penetrating constraints (gap < 0) of `constraints` to its
/// front, in their order, and returns how many: what [`forces`] and
/// [`mark_involvement`] take of a detection with a capture distance
/// ([`PairSettings::capture`]).
pub fn penetrating(constraints: &mut [Constraint]) -> usize {
    let mut k = 0;
    for i in 0..constraints.len() {
        if constraints[i].gap < 0.0 {
            constraints[k] = constraints[i];
            k += 1;
        }
    }
    k
}

/// Clamped projections [`concave_edge`] keeps between its two loops, so
/// that each face is projected once (late in the default scene the second
/// loop's were 8 % of all projections, ~4 faces per call); beyond this
/// many the rest are projected again.
const CONCAVE_KEPT: usize = 16;

/// Relative margin by which another face's closest point must be nearer
/// than a hit's depth to overrule it (round-off of the two projections).
const NEARER_TOLERANCE: Real = 1e-9;

/// The closest point of `p` on the candidate faces confined to their
/// edges, when two or more faces share it (a concave edge or corner): the
/// normal is their average, the gap is measured along it.
fn concave_edge<'c>(
    p: &Vec3,
    candidates: impl Iterator<Item = &'c CandidateFace> + Clone,
) -> Option<Hit> {
    let mut best: Option<(Real, u32, QuadProjection, Real)> = None;
    // The clamped projections of the first faces, for the second loop.
    let mut kept: heapless::Vec<Option<QuadProjection>, CONCAVE_KEPT> = heapless::Vec::new();
    for face in candidates.clone() {
        if !face.reach.contains(p) {
            continue;
        }
        let pr = project_clamped(p, &face.corners);
        // A full list only means the second loop projects the rest again.
        let _ = kept.push(pr);
        if let Some(pr) = pr {
            let d = norm(&sub(p, &pr.point));
            if best.as_ref().is_none_or(|b| d < b.0) {
                best = Some((d, face.quad, pr, face.window));
            }
        }
    }
    let (dist, quad, mut pr, window) = best?;
    // Faces whose clamped closest point is the same point share the edge.
    let tol = 1e-9 * window + 1e-15;
    let mut n = [0.0; 3];
    let mut sharing = 0;
    let mut again = kept.iter();
    for face in candidates {
        if !face.reach.contains(p) {
            continue;
        }
        let other = match again.next() {
            Some(&cached) => cached,
            None => project_clamped(p, &face.corners),
        };
        if let Some(other) = other
            && abs(norm(&sub(p, &other.point)) - dist) <= tol
            && norm(&sub(&other.point, &pr.point)) <= tol
        {
            sharing += 1;
            for (nk, ok) in n.iter_mut().zip(other.normal) {
                *nk += ok;
            }
        }
    }
    let len = norm(&n);
    if sharing < 2 || len.is_nan() || len <= 0.0 {
        return None;
    }
    pr.normal = n.map(|c| c / len);
    pr.gap = dot(&pr.normal, &sub(p, &pr.point));
    (pr.gap < 0.0 && pr.gap > -window).then_some(Hit {
        quad,
        projection: pr,
        watch: false,
    })
}

/// Per-node contact counts of one body for the mass sharing of §5.3.
pub struct Involvement<'a> {
    /// Last pair tag that counted the node (the driver resets it before
    /// each count).
    pub tag: &'a mut [u32],
    /// Contacts the node takes part in this step.
    pub count: &'a mut [u16],
}

impl Involvement<'_> {
    /// Counts node `i` once for the contact tagged `tag`. A node outside
    /// `tag` or `count` is not counted (no panic): [`forces`] rejects
    /// both a count slice shorter than the body's nodes and a node id
    /// outside the body.
    pub fn mark(&mut self, i: usize, tag: u32) {
        if let (Some(t), Some(n)) = (self.tag.get_mut(i), self.count.get_mut(i))
            && *t != tag
        {
            *t = tag;
            *n = n.saturating_add(1);
        }
    }
}

/// Counts, once per pair (tag `tag`, unique within the step), every node of
/// A and B that takes part in one of `constraints` as a slave or as a
/// master corner with a non-zero weight: [`mark_side`] for A, then for B.
pub fn mark_involvement(
    constraints: &[Constraint],
    a: (&SurfaceBody<'_>, &mut Involvement<'_>),
    b: (&SurfaceBody<'_>, &mut Involvement<'_>),
    tag: u32,
) {
    let (body_a, inv_a) = a;
    let (body_b, inv_b) = b;
    mark_side(constraints, Side::A, body_a.quads, inv_a, tag);
    mark_side(constraints, Side::B, body_b.quads, inv_b, tag);
}

/// The half of [`mark_involvement`] that concerns one body of the pair:
/// counts, once per pair (tag `tag`), every node of the body on `side`
/// (its surface quads `quads`) that is the slave of one of `constraints`
/// or a corner with a non-zero weight of the master face of one. A node's
/// count does not depend on the other body, so a driver may count each
/// granule over its own pairs, granules in parallel, and get the counts
/// of a pass over the pairs.
///
/// Like [`forces`], it skips constraints that are not penetrating
/// (g ≥ 0 or NaN). It does not panic on bad ids: a constraint whose quad
/// id is outside `quads`, or a node outside `inv`, is not counted, and
/// [`forces`] on the same constraints — the only user of the counts —
/// reports it ([`ContactError::IdOutOfRange`] or
/// [`ContactError::BufferLength`]). (It returns nothing so that its
/// callers need not change; the error surfaces at [`forces`].)
pub fn mark_side(
    constraints: &[Constraint],
    side: Side,
    quads: &[[u32; 4]],
    inv: &mut Involvement<'_>,
    tag: u32,
) {
    for c in constraints {
        if c.gap.is_nan() || c.gap >= 0.0 {
            continue;
        }
        if c.side == side {
            inv.mark(c.slave as usize, tag);
        } else if let Some(quad) = quads.get(c.quad as usize) {
            for (id, w) in quad.iter().zip(c.weights) {
                if w != 0.0 {
                    inv.mark(*id as usize, tag);
                }
            }
        }
    }
}

/// One node-to-face constraint as [`node_face_force`] needs it: the slave
/// node and the four master corners (start and predicted end of the step)
/// with their (shared) masses, and where the node meets the face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeFace {
    /// Slave node mass m_s (after mass sharing), kg.
    pub slave_mass: Real,
    /// Slave node position at the start of the step x_n, m.
    pub slave_x_n: Vec3,
    /// Slave node predicted position x̃ (end of the step without contact), m.
    pub slave_x_pred: Vec3,
    /// Master corner masses mᵢ (after mass sharing), kg.
    pub master_mass: [Real; 4],
    /// Master corner positions at the start of the step, m.
    pub master_x_n: [Vec3; 4],
    /// Master corner predicted positions, m.
    pub master_x_pred: [Vec3; 4],
    /// Bilinear weights Nᵢ of the corners at the contact point (Σ = 1).
    pub weights: [Real; 4],
    /// The master face's outward unit normal at the contact point.
    pub normal: Vec3,
    /// Signed predicted gap n·(x̃_s − x_c), m; only a negative gap pushes.
    pub gap: Real,
}

/// The kinematic force of one constraint (physics.md §5.3–§5.4).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeFaceForce {
    /// Force on the slave node (normal + friction), N. Corner i of the
    /// master face gets −Nᵢ times it.
    pub force: Vec3,
    /// Its friction part, N.
    pub friction: Vec3,
    /// Normal force magnitude F_n = w (−g) m_eff / Δt², N.
    pub normal: Real,
    /// The friction force sits on the Coulomb cap μ F_n (slip).
    pub slipping: bool,
}

/// Tolerance of the unit-length checks of [`node_face_force`]: the normal
/// must satisfy | |n| − 1 | ≤ this, the weights |Σ Nᵢ − 1| ≤ this.
pub const UNIT_TOLERANCE: Real = 1e-6;

/// [`ContactError::InvalidParameter`] unless `ok`.
pub(crate) fn check_param(
    ok: bool,
    field: &'static str,
    value: Real,
    allowed: &'static str,
) -> Result<(), ContactError> {
    if ok {
        Ok(())
    } else {
        Err(ContactError::InvalidParameter {
            field,
            value,
            allowed,
        })
    }
}

/// Coulomb μ finite and ≥ 0 (NaN fails).
pub(crate) fn check_friction(friction: Real) -> Result<(), ContactError> {
    check_param(
        friction.is_finite() && friction >= 0.0,
        "friction",
        friction,
        "finite, >= 0",
    )
}

/// The per-call scalars of [`node_face_force`] and [`forces`]: μ finite
/// and ≥ 0, Δt² finite and > 0 (NaN fails both).
pub(crate) fn check_step(friction: Real, dt_squared: Real) -> Result<(), ContactError> {
    check_friction(friction)?;
    check_param(
        dt_squared.is_finite() && dt_squared > 0.0,
        "dt_squared",
        dt_squared,
        "finite, > 0",
    )
}

/// The force that closes the predicted gap of one node-to-face constraint
/// in one step, shared by effective mass m_eff = m_s / (1 + m_s Σ Nᵢ²/mᵢ),
/// with the partition weight `weight` (½ or 1, see [`forces`]), Coulomb
/// friction `friction` (μ ≥ 0; 0 skips it) from the relative tangential
/// motion of the step, and `dt_squared` = Δt_{n+½}·Δt_n (s²).
///
/// A constraint with g ≥ 0 is not active (physics.md §5.3: F_n only if
/// g < 0): its force is zero, normal and friction alike — never a pull.
///
/// Errors ([`ContactError::InvalidParameter`], naming the field): `weight`
/// outside 0 < w ≤ 1; `friction` not finite or < 0; `dt_squared` not
/// finite or ≤ 0; a mass (`slave_mass`, any of `master_mass`, also one
/// whose weight is 0) not finite or ≤ 0; a non-finite position or gap; the
/// `weights` not finite, |Σ Nᵢ − 1| > [`UNIT_TOLERANCE`] or a weight
/// outside [0, 1] by more than it; the `normal` not finite or | |n| − 1 |
/// > [`UNIT_TOLERANCE`]; a force that overflows (named as the `gap`).
pub fn node_face_force(
    c: &NodeFace,
    weight: Real,
    friction: Real,
    dt_squared: Real,
) -> Result<NodeFaceForce, ContactError> {
    check_param(
        weight > 0.0 && weight <= 1.0,
        "weight",
        weight,
        "0 < w <= 1",
    )?;
    check_step(friction, dt_squared)?;
    for (field, m) in [("slave_mass", c.slave_mass)]
        .into_iter()
        .chain(c.master_mass.map(|m| ("master_mass", m)))
    {
        check_param(m.is_finite() && m > 0.0, field, m, "finite, > 0")?;
    }
    let positions = [
        ("slave_x_n", &c.slave_x_n),
        ("slave_x_pred", &c.slave_x_pred),
    ]
    .into_iter()
    .chain(c.master_x_n.iter().map(|x| ("master_x_n", x)))
    .chain(c.master_x_pred.iter().map(|x| ("master_x_pred", x)));
    for (field, x) in positions {
        if let Some(&v) = x.iter().find(|v| !v.is_finite()) {
            return Err(ContactError::InvalidParameter {
                field,
                value: v,
                allowed: "finite",
            });
        }
    }
    check_param(c.gap.is_finite(), "gap", c.gap, "finite")?;
    let sum: Real = c.weights.iter().sum();
    check_param(
        abs(sum - 1.0) <= UNIT_TOLERANCE,
        "weights",
        sum,
        "finite, summing to 1 within 1e-6",
    )?;
    // The weights of a point on the face: each in [0, 1] (within the
    // tolerance). (2, −1, 0, 0) sums to 1 but lies off the face.
    for &w in &c.weights {
        check_param(
            (-UNIT_TOLERANCE..=1.0 + UNIT_TOLERANCE).contains(&w),
            "weights",
            w,
            "each in [0, 1] within 1e-6 (a point on the face)",
        )?;
    }
    let len = norm(&c.normal);
    check_param(
        abs(len - 1.0) <= UNIT_TOLERANCE,
        "normal",
        len,
        "unit length: | |n| - 1 | <= 1e-6",
    )?;
    if c.gap >= 0.0 {
        return Ok(NodeFaceForce::default());
    }
    let increment = || {
        let mut du = sub(&c.slave_x_pred, &c.slave_x_n);
        for i in 0..4 {
            let dm = sub(&c.master_x_pred[i], &c.master_x_n[i]);
            for (d, m) in du.iter_mut().zip(dm) {
                *d -= c.weights[i] * m;
            }
        }
        du
    };
    let spot = Spot {
        slave_mass: c.slave_mass,
        master_mass: c.master_mass,
        weights: &c.weights,
        normal: &c.normal,
        gap: c.gap,
    };
    let out = kinematic_force(&spot, increment, weight, friction, dt_squared);
    // Finite inputs can still overflow: |g| m_eff / Δt² beyond the range
    // of f64 (a gap of 1e300 m in a step of 1e-150 s).
    check_param(
        out.force.iter().all(|v| v.is_finite()) && out.normal.is_finite(),
        "gap",
        c.gap,
        "a gap whose force |gap| m_eff / dt_squared is finite",
    )?;
    Ok(out)
}

/// What [`kinematic_force`] needs besides the motion of the step.
struct Spot<'a> {
    slave_mass: Real,
    master_mass: [Real; 4],
    weights: &'a [Real; 4],
    normal: &'a Vec3,
    gap: Real,
}

/// The arithmetic of [`node_face_force`], shared with [`forces`] (which
/// reads the positions from its bodies): `increment` gives the relative
/// motion of the step Δu = (x̃_s − x_s) − Σ Nᵢ (x̃ᵢ − xᵢ), asked for only
/// when there is friction.
#[inline]
fn kinematic_force(
    c: &Spot<'_>,
    increment: impl FnOnce() -> Vec3,
    weight: Real,
    friction: Real,
    dt_squared: Real,
) -> NodeFaceForce {
    let m_s = c.slave_mass;
    let inv_md: Real = (0..4)
        .map(|i| c.weights[i] * c.weights[i] / c.master_mass[i])
        .sum();
    let m_eff = m_s / (1.0 + m_s * inv_md);
    let n = *c.normal;
    let f_n = weight * (-c.gap) * m_eff / dt_squared;
    let mut f = n.map(|v| f_n * v);
    let mut f_t = [0.0; 3];
    let mut slipping = false;
    if friction > 0.0 {
        let du = increment();
        let dn = dot(&du, &n);
        f_t = core::array::from_fn(|a| -weight * m_eff * (du[a] - dn * n[a]) / dt_squared);
        let mag = sqrt(dot(&f_t, &f_t));
        let cap = friction * f_n;
        if mag > cap {
            let scale = cap / mag;
            f_t = f_t.map(|v| v * scale);
            slipping = true;
        }
        for a in 0..3 {
            f[a] += f_t[a];
        }
    }
    NodeFaceForce {
        force: f,
        friction: f_t,
        normal: f_n,
        slipping,
    }
}

/// Re-measures `held` — constraints [`detect`] found between `a` and `b`
/// on an earlier x̃ of the same step — on the bodies' current x̃, at their
/// contact points: the gap n·(x̃_s − Σ Nᵢ x̃ᵢ) with each constraint's held
/// weights Nᵢ and normal n. The constraints still penetrating (g < 0) are
/// written to `out` in their order (so a subsequence keeps [`detect`]'s
/// order, which [`forces`] relies on), with the new gap. Returns how many.
///
/// A constraint whose node has slid along the face by more than
/// `settings.reproject_slide` (the tangential part of x̃_s − Σ Nᵢ x̃ᵢ) is
/// projected on its face afresh while the node still lies on the face: it
/// is written with the projection's weights, normal and gap if the node
/// penetrates the face as a search would find it (inside, behind by less
/// than the gap window, normals opposing), and dropped if it does not.
/// Off the face, the held weights and normal measure it as before.
///
/// A watch ([`Constraint::watch`]: the node lay just beside its face at the
/// search) is always projected afresh, and written, as an ordinary
/// constraint, only once the node penetrates the face so (with
/// `settings.watch_beside` false, never). A node that comes
/// over a face's edge between two searches is then held where a search
/// would have found it, and no force acts on the face's extension beside
/// it.
///
/// **Choice (physics.md §5.3 leaves the later Jacobi sweeps open):** a
/// later sweep of a step corrects the contacts the step's search found
/// rather than searching again. The gap is first-order exact in the
/// corrections (it leaves out how far the closest point slides, and the
/// turn of the normal); a node that a correction pushes into a face
/// without a held constraint is found by the next step's search. A NaN
/// gap is no penetration here (the driver's checks of the motion report
/// a non-finite state).
///
/// Errors: `out` shorter than `held` ([`ContactError::BufferLength`]); a
/// held constraint's slave or quad id, or a corner id of its quad, outside
/// the bodies ([`ContactError::IdOutOfRange`], buffer `held.slave`,
/// `held.quad` or `quads`, whichever path measures the constraint).
pub fn regap(
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
    held: &[Constraint],
    settings: &PairSettings,
    out: &mut [Constraint],
) -> Result<usize, ContactError> {
    if out.len() < held.len() {
        return Err(ContactError::BufferLength {
            buffer: "constraints",
            expected: held.len(),
            got: out.len(),
        });
    }
    let mut k = 0;
    for (index, c) in held.iter().enumerate() {
        let (slave, master) = match c.side {
            Side::A => (a, b),
            Side::B => (b, a),
        };
        // A constraint of other bodies: its ids lie outside these.
        let out_of = |buffer, at, id: u32, len| ContactError::IdOutOfRange {
            buffer,
            index: at,
            id,
            len,
        };
        let p = slave
            .x_pred
            .get(c.slave as usize)
            .ok_or_else(|| out_of("held.slave", index, c.slave, slave.x_pred.len()))?;
        let quad = master
            .quads
            .get(c.quad as usize)
            .ok_or_else(|| out_of("held.quad", index, c.quad, master.quads.len()))?;
        if c.watch {
            // Watches held from a search with them, re-measured without
            // (a run resumed with them switched off): dropped.
            if !settings.watch_beside {
                continue;
            }
            if let Reprojection::Contact(found) = reprojected(slave, master, c, p, settings)? {
                out[k] = found;
                k += 1;
            }
            continue;
        }
        let mut d = *p;
        for (&id, &wi) in quad.iter().zip(&c.weights) {
            let x = master
                .x_pred
                .get(id as usize)
                .ok_or_else(|| out_of("quads", c.quad as usize, id, master.x_pred.len()))?;
            for (dk, xk) in d.iter_mut().zip(x) {
                *dk -= wi * xk;
            }
        }
        let gap = dot(&c.normal, &d);
        let slid = {
            let t: Vec3 = core::array::from_fn(|i| d[i] - gap * c.normal[i]);
            dot(&t, &t) > settings.reproject_slide * settings.reproject_slide
        };
        if slid {
            match reprojected(slave, master, c, p, settings)? {
                Reprojection::OffFace => {}
                Reprojection::Clear => continue,
                Reprojection::Contact(found) => {
                    out[k] = found;
                    k += 1;
                    continue;
                }
            }
        }
        if gap < 0.0 {
            out[k] = Constraint { gap, ..*c };
            k += 1;
        }
    }
    Ok(k)
}

/// What a held constraint projected afresh on its face finds
/// ([`reprojected`]).
enum Reprojection {
    /// The node lies off the face (or the projection failed).
    OffFace,
    /// On the face, but no contact a search would find: in front of it,
    /// deeper than the gap window, or with normals not opposing.
    Clear,
    /// The face's contact, with the projection's weights, normal and gap.
    Contact(Constraint),
}

/// Held constraint `c` of [`regap`] projected afresh on its face at the
/// slave's position `p`, with a search's tests (inside the face, behind it
/// by less than the gap window, normals opposing unless
/// [`PairSettings::nearest_penetrated_face`]). A corner or slave id
/// outside the bodies is an error.
fn reprojected(
    slave: &SurfaceBody<'_>,
    master: &SurfaceBody<'_>,
    c: &Constraint,
    p: &Vec3,
    settings: &PairSettings,
) -> Result<Reprojection, ContactError> {
    let q = c.quad as usize;
    let corners = master.corners(q).ok_or_else(|| master.quad_error(q))?;
    let Some(pr) = project(p, &corners).filter(|pr| pr.inside(settings.inside_tolerance)) else {
        return Ok(Reprojection::OffFace);
    };
    if !(pr.gap < 0.0 && pr.gap > -settings.window(&corners)) {
        return Ok(Reprojection::Clear);
    }
    // Normals opposing (a NaN opposes nothing), unless a search would
    // take the face whatever the node's normal.
    let taken = settings.nearest_penetrated_face
        || dot(&slave.node_normal(c.slave as usize)?, &pr.normal) < 0.0;
    Ok(if taken {
        Reprojection::Contact(Constraint {
            weights: pr.weights,
            normal: pr.normal,
            gap: pr.gap,
            watch: false,
            ..*c
        })
    } else {
        Reprojection::Clear
    })
}

/// Shared mass m/max(1, n) of node `i` (`share` empty: no sharing).
fn shared_mass(body: &SurfaceBody<'_>, share: &[u16], i: usize) -> Real {
    let n = share.get(i).copied().unwrap_or(1).max(1);
    body.mass[i] / Real::from(n)
}

/// The error of constraint `index` of [`forces`] (`c`, between `a` and
/// `b`), if any: a NaN gap, or its slave, quad or a corner id outside the
/// bodies (or inside `x_pred` but outside a shorter `x_n` or `mass`).
fn bad_constraint(
    index: usize,
    c: &Constraint,
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
) -> Option<ContactError> {
    let (slave, master) = match c.side {
        Side::A => (a, b),
        Side::B => (b, a),
    };
    // Node `id` (read from entry `at` of `buffer`) of `body`, if bad.
    let node = |body: &SurfaceBody<'_>, buffer, at, id: u32| {
        let n = body.x_pred.len();
        if id as usize >= n {
            Some(ContactError::IdOutOfRange {
                buffer,
                index: at,
                id,
                len: n,
            })
        } else if id as usize >= body.x_n.len() {
            Some(ContactError::BufferLength {
                buffer: "x_n",
                expected: n,
                got: body.x_n.len(),
            })
        } else if id as usize >= body.mass.len() {
            Some(ContactError::BufferLength {
                buffer: "mass",
                expected: n,
                got: body.mass.len(),
            })
        } else {
            None
        }
    };
    if c.gap.is_nan() {
        return Some(ContactError::InvalidParameter {
            field: "constraints.gap",
            value: c.gap,
            allowed: "not NaN (< 0: penetrating, >= 0: inactive)",
        });
    }
    if let Some(e) = node(slave, "constraints.slave", index, c.slave) {
        return Some(e);
    }
    let Some(q) = master.quads.get(c.quad as usize) else {
        return Some(ContactError::IdOutOfRange {
            buffer: "constraints.quad",
            index,
            id: c.quad,
            len: master.quads.len(),
        });
    };
    q.iter()
        .find_map(|&id| node(master, "quads", c.quad as usize, id))
}

/// The error of the first bad constraint of `constraints` (see
/// [`bad_constraint`]).
#[cold]
#[inline(never)]
fn first_bad_constraint(
    constraints: &[Constraint],
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
) -> ContactError {
    constraints
        .iter()
        .enumerate()
        .find_map(|(index, c)| bad_constraint(index, c, a, b))
        .unwrap_or(ContactError::BufferLength {
            buffer: "constraints",
            expected: 0,
            got: constraints.len(),
        })
}

/// The [`ContactError::BufferLength`] of a share slice of [`forces`]
/// that is neither empty nor one per node.
#[cold]
#[inline(never)]
fn share_error(a: (&SurfaceBody<'_>, &[u16]), b: (&SurfaceBody<'_>, &[u16])) -> ContactError {
    let (buffer, (body, share)) = if a.1.is_empty() || a.1.len() >= a.0.x_pred.len() {
        ("share_b", b)
    } else {
        ("share_a", a)
    };
    ContactError::BufferLength {
        buffer,
        expected: body.x_pred.len(),
        got: share.len(),
    }
}

/// The forces of `constraints` (from [`detect`] on the same predicted
/// configuration), written to `out` in constraint order: the slave node,
/// then the four master corners. `share_a` / `share_b` are the contact
/// counts of [`mark_involvement`] (one per node; empty slices mean no mass
/// sharing). `dt_squared` is Δt_{n+½}·Δt_n. Returns the number of entries
/// written and the pair's totals.
///
/// A constraint with g ≥ 0 (a near constraint of [`PairSettings::capture`])
/// is not active: it writes nothing and does not count, as in
/// [`node_face_force`]. The constraints' normals, weights and the bodies'
/// masses are taken as [`detect`] and the mesh made them (not re-checked:
/// that would be per-constraint work on the bed's hot path).
///
/// Errors, all found before any force is computed (a first pass over the
/// constraints checks their ids and gaps): `settings.friction` or
/// `dt_squared` out of range or a NaN gap
/// ([`ContactError::InvalidParameter`]); `out` shorter than five entries
/// per constraint, a non-empty share slice shorter than the body's nodes,
/// a body's `x_n` or `mass` too short for a node a constraint names
/// ([`ContactError::BufferLength`]); a constraint's slave or quad id or
/// its quad's corner ids outside the bodies
/// ([`ContactError::IdOutOfRange`]) — and, only with
/// [`PairSettings::contact_area`], a bad id in the slave's `node_quads`
/// (then `out` may hold partial entries).
pub fn forces(
    a: (&SurfaceBody<'_>, &[u16]),
    b: (&SurfaceBody<'_>, &[u16]),
    constraints: &[Constraint],
    settings: &PairSettings,
    dt_squared: Real,
    out: &mut [NodeForce],
) -> Result<(usize, PairForce), ContactError> {
    if out.len() < 5 * constraints.len() {
        return Err(ContactError::BufferLength {
            buffer: "node forces",
            expected: 5 * constraints.len(),
            got: out.len(),
        });
    }
    check_step(settings.friction, dt_squared)?;
    let share_fits = |(body, share): (&SurfaceBody<'_>, &[u16])| {
        share.is_empty() | (share.len() >= body.x_pred.len())
    };
    if !(share_fits(a) & share_fits(b)) {
        return Err(share_error(a, b));
    }
    // A node id must index x_n, x̃ and the masses.
    let nodes = |body: &SurfaceBody<'_>| body.x_pred.len().min(body.x_n.len()).min(body.mass.len());
    let (nodes_a, nodes_b) = (nodes(a.0), nodes(b.0));
    // The ids and gaps first, in a pass of their own: one branch per
    // constraint. (Checks inside the force loop, or a branch there around
    // inactive constraints, cost 10–15 % of a pair's force pass in
    // instructions; this pass costs 3 %.)
    let (mut bad, mut inactive) = (false, false);
    for c in constraints {
        let (slave_nodes, master, master_nodes) = match c.side {
            Side::A => (nodes_a, b.0, nodes_b),
            Side::B => (nodes_b, a.0, nodes_a),
        };
        // A quad id out of range reads as corners no body has.
        let q = master
            .quads
            .get(c.quad as usize)
            .copied()
            .unwrap_or([u32::MAX; 4]);
        let top = q[0].max(q[1]).max(q[2].max(q[3])) as usize;
        bad |= (top >= master_nodes) | (c.slave as usize >= slave_nodes) | c.gap.is_nan();
        inactive |= c.gap >= 0.0;
    }
    if bad {
        return Err(first_bad_constraint(constraints, a.0, b.0));
    }
    // Inactive constraints (g ≥ 0: near constraints of a capture
    // distance) get no force. The common case, none, runs the loop
    // without that test.
    if inactive {
        force_pass(a, b, constraints, settings, dt_squared, out, |c| {
            c.gap < 0.0
        })
    } else {
        force_pass(a, b, constraints, settings, dt_squared, out, |_| true)
    }
}

/// The loop of [`forces`] over the constraints that pass `active`, their
/// ids checked.
#[inline(always)]
fn force_pass(
    a: (&SurfaceBody<'_>, &[u16]),
    b: (&SurfaceBody<'_>, &[u16]),
    constraints: &[Constraint],
    settings: &PairSettings,
    dt_squared: Real,
    out: &mut [NodeForce],
    active: impl Fn(&Constraint) -> bool,
) -> Result<(usize, PairForce), ContactError> {
    let mu = settings.friction;
    let mut total = PairForce::default();
    let mut k = 0;
    let split = constraints.partition_point(|k| k.side == Side::A);
    for c in constraints {
        if !active(c) {
            continue;
        }
        let (slave, s_share, master, m_share, master_side) = match c.side {
            Side::A => (a.0, a.1, b.0, b.1, Side::B),
            Side::B => (b.0, b.1, a.0, a.1, Side::A),
        };
        let w = if settings.symmetric {
            partition_weight(c, constraints, split, master.quads)
        } else {
            1.0
        };
        let s = c.slave as usize;
        let ids = master.quads[c.quad as usize].map(|i| i as usize);
        let increment = || {
            let mut du = sub(&slave.x_pred[s], &slave.x_n[s]);
            for (i, &id) in ids.iter().enumerate() {
                let dm = sub(&master.x_pred[id], &master.x_n[id]);
                for (d, m) in du.iter_mut().zip(dm) {
                    *d -= c.weights[i] * m;
                }
            }
            du
        };
        let spot = Spot {
            slave_mass: shared_mass(slave, s_share, s),
            master_mass: ids.map(|id| shared_mass(master, m_share, id)),
            weights: &c.weights,
            normal: &c.normal,
            gap: c.gap,
        };
        let NodeFaceForce {
            force: f,
            friction: f_t,
            normal: f_n,
            slipping,
        } = kinematic_force(&spot, increment, w, mu, dt_squared);
        total.slipping += usize::from(slipping);
        out[k] = NodeForce {
            side: c.side,
            node: c.slave,
            force: f,
        };
        k += 1;
        for (i, &id) in ids.iter().enumerate() {
            let wi = c.weights[i];
            out[k] = NodeForce {
                side: master_side,
                node: id as u32,
                force: f.map(|v| -wi * v),
            };
            k += 1;
        }
        // Totals on A: the slave's force if A is the slave side, else the
        // reaction on the master corners (Σ Nᵢ = 1).
        let sign = if c.side == Side::A { 1.0 } else { -1.0 };
        for a in 0..3 {
            total.total_on_a[a] += sign * f[a];
            total.friction_on_a[a] += sign * f_t[a];
        }
        total.normal += f_n;
        if settings.contact_area {
            total.area += w * slave.node_area(s)?;
        }
        total.constraints += 1;
        if c.gap < total.min_gap {
            total.min_gap = c.gap;
        }
    }
    Ok((k, total))
}
