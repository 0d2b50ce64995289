//! The granule–granule contact phase of an assembly step: broad phase,
//! detection, mass-sharing counts, forces and the fixed-order gather.

use granbed_kernel::Real;
use granbed_kernel::contact::broad::{
    Bound, BroadScratch, GranulePair, bounding_sphere, candidate_pairs, needs_rebuild,
};
use granbed_kernel::contact::face_lists::{self, AnchorSurface, FaceLists, FaceListsMut, ReachBox};
use granbed_kernel::contact::pair::{
    CandidateFace, Constraint, ContactError, Involvement, NodeForce, PairForce, PairSettings, Side,
    detect, detect_listed, forces, mark_side, penetrating, regap,
};
use granbed_kernel::contact::surface::{Aabb, SurfaceBody, quad_bounds};
use granbed_kernel::contact::wall::{Wall, count_wall_contacts};
use rayon::prelude::*;

use crate::model::{GranuleStore, OwnedReference};

/// The buffers and results of one candidate pair.
#[derive(Clone, Debug, Default)]
pub struct PairWork {
    constraints: Vec<Constraint>,
    count: usize,
    forces: Vec<NodeForce>,
    force_count: usize,
    /// What the last force pass (sweep) did.
    pub result: PairForce,
    /// What every sweep of the last step did together: forces summed,
    /// constraint counts and contact area of the first sweep, the smallest
    /// gap.
    pub step: PairForce,
    /// The face lists of the pair's two passes.
    lists: PairLists,
    /// The constraints of the last search's first sweep, which the step's
    /// later sweeps, and the steps up to the next search, re-measure
    /// instead of searching again ([`ContactPhase::detect`]), when
    /// `holding`.
    held: Vec<Constraint>,
    /// The pair holds `held` (false: nothing; the next sweep searches it —
    /// a pair new to the list, moved in it by a rebuild, or searched
    /// without holding).
    holding: bool,
}

/// What a pair holds from the last search for the sweeps that follow
/// without searching (`None`: nothing; `Some` of no constraints: it was
/// searched and found none).
pub type HeldConstraints = Option<Vec<Constraint>>;

/// A pair's face lists (pass A→B, pass B→A) and what they were built for.
#[derive(Clone, Debug, Default)]
struct PairLists {
    /// The pair and its granules' anchor epochs at the build (`None`: not
    /// built); the lists serve only while all three are the same.
    key: Option<(GranulePair, u32, u32)>,
    pass: [OwnedLists; 2],
}

/// One pass's lists in the layout of [`FaceLists`].
#[derive(Clone, Debug, Default)]
struct OwnedLists {
    nodes: Vec<u32>,
    starts: Vec<u32>,
    faces: Vec<u32>,
    used: Vec<u32>,
}

impl OwnedLists {
    fn view(&self) -> FaceLists<'_> {
        FaceLists {
            nodes: &self.nodes,
            starts: &self.starts,
            faces: &self.faces,
            used: &self.used,
        }
    }

    /// Builds the lists of `slave` → `master` on their anchors, growing
    /// the face buffer until it fits.
    fn build(
        &mut self,
        slave: &AnchorSurface<'_>,
        master: &AnchorSurface<'_>,
        window_fraction: Real,
        drift: Real,
        scratch: &mut Vec<ReachBox>,
    ) -> Result<(), ContactError> {
        scratch.resize(scratch.len().max(master.quads.len()), ReachBox::default());
        self.nodes.resize(slave.x.len(), 0);
        self.starts.resize(slave.x.len() + 1, 0);
        self.used.resize(master.quads.len(), 0);
        if self.faces.is_empty() {
            self.faces.resize(256, 0);
        }
        let len = loop {
            let out = FaceListsMut {
                nodes: &mut self.nodes,
                starts: &mut self.starts,
                faces: &mut self.faces,
                used: &mut self.used,
            };
            match face_lists::build(slave, master, window_fraction, drift, scratch, out) {
                Ok(len) => break len,
                Err(ContactError::Capacity {
                    buffer: "face lists",
                    ..
                }) => {
                    let grown = 2 * self.faces.len();
                    self.faces.resize(grown, 0);
                }
                Err(e) => return Err(e),
            }
        };
        self.nodes.truncate(len.nodes);
        self.starts.truncate(len.nodes + 1);
        self.faces.truncate(len.faces);
        self.used.truncate(len.used);
        Ok(())
    }
}

/// Per-thread scratch of the detection.
#[derive(Default)]
struct DetectScratch {
    faces: Vec<CandidateFace>,
    reach: Vec<ReachBox>,
    /// Per master quad, its candidate index (`u32::MAX`: none).
    slot: Vec<u32>,
}

impl PairWork {
    /// After a search: with `keep`, holds the pair's constraints for the
    /// step's later sweeps and the first sweeps of the steps up to the next
    /// search; else forgets any held ones (a later sweep that searched, no
    /// holding, or a pair moved in the list).
    fn hold(&mut self, keep: bool) {
        self.held.clear();
        self.holding = keep;
        if keep {
            self.held.extend_from_slice(&self.constraints[..self.count]);
        }
    }

    /// The constraints found in the last detection (sweep).
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints[..self.count]
    }

    /// True if the pair touched (had a constraint) in the last step.
    pub fn touching(&self) -> bool {
        self.step.constraints > 0
    }
}

/// Contact state carried between steps.
#[derive(Debug, Default)]
pub struct ContactPhase {
    pairs: Vec<GranulePair>,
    work: Vec<PairWork>,
    /// Per granule: (pair index, side of the granule in it), pair order.
    by_granule: Vec<Vec<(u32, Side)>>,
    built: Vec<Bound>,
    /// Per granule, the bounding sphere of its surface on the last x̃.
    pub(super) bounds: Vec<Bound>,
    /// Per granule, the box of its surface on x̃ as of its last refresh
    /// (current unless `stale`; [`Self::refresh_surfaces`]).
    boxes: Vec<Aabb>,
    /// Per granule, the box of every surface quad on x̃, as `boxes`.
    quad_boxes: Vec<Vec<Aabb>>,
    /// Per granule: its x̃ moved since its boxes and anchor were last
    /// brought up to date (a sweep that did not search); the next search
    /// takes them first ([`Self::refresh_surfaces`]).
    stale: Vec<bool>,
    /// Some pair of the list holds nothing of this step's first sweep (a
    /// rebuild in a later sweep added a pair or moved one in the list): the
    /// later sweeps search.
    unheld: bool,
    /// Per granule and node: contacts this step (mass sharing).
    pub(super) share: Vec<Vec<u16>>,
    tag: Vec<Vec<u32>>,
    head: Vec<u32>,
    next: Vec<u32>,
    rebuilds: u64,
    /// Per granule: f_c of its surface nodes (the last `surface_nodes`;
    /// contact forces act on no other node) before the current sweep, for
    /// the x̃ update.
    pub(super) f_before: Vec<Vec<[Real; 3]>>,
    /// Per granule: whether the last sweep put a contact force on it (only
    /// then did its x̃ move, so only then can its pairs change); narrowed
    /// by `narrow_to_deep_pairs` to the granules whose pairs the next sweep
    /// searches again.
    pub(super) touched: Vec<bool>,
    /// Per granule: whether the last sweep put a contact force on it (not
    /// narrowed): only such a granule's f_c differs from `f_before`.
    pub(super) forced: Vec<bool>,
    /// Per granule: bit k set if it touched wall k (mod 64) in any sweep of
    /// the step.
    pub(super) on_wall: Vec<u64>,
    /// Pair searches so far (all sweeps; a re-measured pair is no search).
    searches: u64,
    /// Scratch of `narrow_to_deep_pairs`, per granule: [`DEEP`] or
    /// [`NEAR_DEEP`] bits.
    narrow: Vec<u8>,
    /// Face-list drift, m (0: no face lists).
    list_drift: Real,
    /// Per granule: its surface nodes' x̃ when its anchor was last renewed
    /// (the configuration its pairs' face lists were built on).
    anchors: Vec<Vec<[Real; 3]>>,
    /// Per granule: how many times its anchor was renewed.
    epochs: Vec<u32>,
    /// Face-list builds so far (both passes of a pair count one).
    list_builds: u64,
    /// Anchor renewals so far (over all granules).
    anchor_renewals: u64,
}

/// `narrow` bit: the granule is in a pair deeper than the tolerance.
const DEEP: u8 = 1;
/// `narrow` bit: the granule is in a pair deeper than the tolerance or
/// touches a granule that is.
const NEAR_DEEP: u8 = 2;

/// Whether granule `g`'s x̃ may have changed since the last sweep: in the
/// first sweep of a step every granule's has; later only those the last
/// sweep put a force on (`forced`; a granule it does not list counts as
/// moved).
fn moved(forced: &[bool], g: usize, first_sweep: bool) -> bool {
    first_sweep || forced.get(g).is_none_or(|&f| f)
}

/// The kernel's view of granule `g` on its predicted configuration.
fn body<'a>(
    g: &'a GranuleStore,
    mesh: &'a OwnedReference,
    boxes: (Aabb, Bound, &'a [Aabb]),
) -> SurfaceBody<'a> {
    body_at(g, &g.x_pred, mesh, boxes)
}

/// The kernel's view of granule `g` with `x_pred` as the configuration
/// to detect on (its x̃, or x_n itself to measure the current overlap).
fn body_at<'a>(
    g: &'a GranuleStore,
    x_pred: &'a [[Real; 3]],
    mesh: &'a OwnedReference,
    (bounds, sphere, quad_bounds): (Aabb, Bound, &'a [Aabb]),
) -> SurfaceBody<'a> {
    SurfaceBody {
        x_n: &g.x,
        x_pred,
        mass: &g.contact_mass,
        first_surface: mesh.surface_range().start,
        quads: &mesh.quads,
        node_quads: &mesh.node_quads,
        bounds,
        sphere,
        quad_bounds,
    }
}

impl ContactPhase {
    /// Empty contact state for `granules`.
    pub fn new(granules: &[GranuleStore], mesh: &OwnedReference) -> Self {
        let n = granules.len();
        let nodes = mesh.positions.len();
        Self {
            by_granule: vec![Vec::new(); n],
            share: vec![vec![0; nodes]; n],
            tag: vec![vec![u32::MAX; nodes]; n],
            head: vec![0; 8 * n + 8],
            next: vec![0; n],
            ..Self::default()
        }
    }

    /// Uses per-node face lists with drift `drift` (m; 0: none).
    pub fn with_face_lists(mut self, drift: Real) -> Self {
        self.list_drift = drift;
        self
    }

    /// Face-list builds so far (a pair's two passes count one).
    pub fn list_builds(&self) -> u64 {
        self.list_builds
    }

    /// Anchor renewals so far (over all granules).
    pub fn anchor_renewals(&self) -> u64 {
        self.anchor_renewals
    }

    /// Pair searches (detections) so far, over all sweeps.
    pub fn searches(&self) -> u64 {
        self.searches
    }

    /// Candidate pairs of the current list.
    pub fn pairs(&self) -> &[GranulePair] {
        &self.pairs
    }

    /// Per candidate pair, its buffers and last result.
    pub fn work(&self) -> &[PairWork] {
        &self.work
    }

    /// Granules whose bounding sphere (as the last sweep left it) differs
    /// from that of their x̃ now, or whose box or quad boxes differ while
    /// they are not marked stale or a search is due (a stale granule's are
    /// taken before the next search): always empty, since a sweep skips
    /// only granules whose x̃ did not move, and a sweep that searches
    /// nothing defers the boxes of those it moved, marked stale. For tests.
    pub fn stale_boxes(&self, granules: &[GranuleStore], mesh: &OwnedReference) -> Vec<usize> {
        let first = mesh.surface_range().start;
        let mut quads = vec![Aabb::EMPTY; mesh.quads.len()];
        (0..granules.len())
            .filter(|&g| {
                let x = &granules[g].x_pred;
                quad_bounds(x, &mesh.quads, &mut quads);
                // Stale boxes are allowed only while no search is due.
                let stale = self.stale.get(g) == Some(&true) && !self.unheld;
                self.bounds.get(g) != Some(&bounding_sphere(x, first))
                    || !stale
                        && (self.boxes.get(g) != Some(&Aabb::of_surface(x, first))
                            || self.quad_boxes.get(g) != Some(&quads))
            })
            .collect()
    }

    /// The check the skin argument of `contact::broad` promises: granule
    /// pairs whose bounding spheres (on the last x̃) overlap but are not in
    /// the candidate list, found by brute force over all pairs. Always
    /// empty unless the broad phase is broken; O(N²), for tests.
    pub fn missed_pairs(&self) -> Vec<GranulePair> {
        let b = &self.bounds;
        let mut missed = Vec::new();
        for i in 0..b.len() {
            for j in i + 1..b.len() {
                let d: Real = (0..3)
                    .map(|k| (b[i].centre[k] - b[j].centre[k]).powi(2))
                    .sum::<Real>()
                    .sqrt();
                let pair = GranulePair {
                    a: i as u32,
                    b: j as u32,
                };
                if d < b[i].radius + b[j].radius && self.pairs.binary_search(&pair).is_err() {
                    missed.push(pair);
                }
            }
        }
        missed
    }

    /// The candidate pairs, the bounding spheres of their build and, per
    /// pair, the constraints it holds from the last search (`None`: it
    /// holds nothing).
    pub(super) fn broad_state(&self) -> (Vec<GranulePair>, Vec<Bound>, Vec<HeldConstraints>) {
        let held = self
            .work
            .iter()
            .map(|w| w.holding.then(|| w.held.clone()))
            .collect();
        (self.pairs.clone(), self.built.clone(), held)
    }

    /// Continues with `pairs` built from `built`, each holding its entry of
    /// `held` (from [`Self::broad_state`]; shorter, e.g. empty: the pairs
    /// past its end hold nothing, and their next sweep searches).
    pub(super) fn restore_broad(
        &mut self,
        pairs: &[GranulePair],
        built: &[Bound],
        held: &[HeldConstraints],
    ) {
        self.pairs = pairs.to_vec();
        self.built = built.to_vec();
        self.work = vec![PairWork::default(); pairs.len()];
        for (w, h) in self.work.iter_mut().zip(held) {
            if let Some(h) = h {
                w.held.clone_from(h);
                w.holding = true;
            }
        }
        self.index_pairs();
    }

    /// Rebuilds each granule's list of (pair, side) from the pair list.
    fn index_pairs(&mut self) {
        for list in &mut self.by_granule {
            list.clear();
        }
        for (k, p) in self.pairs.iter().enumerate() {
            self.by_granule[p.a as usize].push((k as u32, Side::A));
            self.by_granule[p.b as usize].push((k as u32, Side::B));
        }
    }

    /// Narrows the next sweep to the neighbourhood of the pairs whose last
    /// sweep found a gap deeper than `tolerance` (m): a granule stays
    /// marked as moved (its pairs are searched again) only if it is in such
    /// a pair or touches a granule that is. Elsewhere every gap left is
    /// shallower than the tolerance, which the sweep loop accepts anyway.
    pub(super) fn narrow_to_deep_pairs(&mut self, tolerance: Real) {
        let marks = &mut self.narrow;
        marks.clear();
        marks.resize(self.touched.len(), 0);
        for (p, w) in self.pairs.iter().zip(&self.work) {
            if w.result.min_gap < -tolerance {
                marks[p.a as usize] = DEEP | NEAR_DEEP;
                marks[p.b as usize] = DEEP | NEAR_DEEP;
            }
        }
        for (p, w) in self.pairs.iter().zip(&self.work) {
            let (a, b) = (p.a as usize, p.b as usize);
            if w.force_count > 0 && (marks[a] | marks[b]) & DEEP != 0 {
                marks[a] |= NEAR_DEEP;
                marks[b] |= NEAR_DEEP;
            }
        }
        for (t, &m) in self.touched.iter_mut().zip(marks.iter()) {
            *t &= m & NEAR_DEEP != 0;
        }
    }

    /// Broad-phase rebuilds so far.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// Pairs in contact (at least one constraint) in the last step.
    pub fn pairs_in_contact(&self) -> usize {
        self.work.iter().filter(|w| w.touching()).count()
    }

    /// Per granule, the number of granules it touched in the last step.
    pub fn contacts_per_granule(&self) -> Vec<usize> {
        let mut n = vec![0; self.by_granule.len()];
        for (p, w) in self.pairs.iter().zip(&self.work) {
            if w.touching() {
                n[p.a as usize] += 1;
                n[p.b as usize] += 1;
            }
        }
        n
    }

    /// Bounding spheres of every granule's predicted surface, then the
    /// candidate list, rebuilt if a granule drifted half the margin.
    /// After the first sweep of a step (`first_sweep` false) only the
    /// granules the last sweep moved (`forced`) get new spheres: the
    /// others' x̃ and so their spheres are unchanged. (The boxes the search
    /// needs are [`Self::detect`]'s to take.)
    pub(super) fn broad(
        &mut self,
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        margin: Real,
        first_sweep: bool,
    ) -> Result<(), ContactError> {
        let first = mesh.surface_range().start;
        let forced = &self.forced;
        if first_sweep {
            self.unheld = false;
        }
        // In place: this runs every sweep of every step.
        self.bounds.resize(granules.len(), Bound::default());
        self.bounds
            .par_iter_mut()
            .zip(granules.par_iter())
            .enumerate()
            .filter(|(g, _)| moved(forced, *g, first_sweep))
            .for_each(|(_, (b, g))| *b = bounding_sphere(&g.x_pred, first));
        if !self.built.is_empty() && !needs_rebuild(&self.built, &self.bounds, margin) {
            return Ok(());
        }
        let mut out = vec![GranulePair { a: 0, b: 0 }; 8 * granules.len() + 8];
        let count = loop {
            let mut scratch = BroadScratch {
                head: &mut self.head,
                next: &mut self.next,
            };
            match candidate_pairs(&self.bounds, margin, &mut scratch, &mut out) {
                Ok(n) => break n,
                Err(ContactError::Capacity {
                    buffer: "granule pairs",
                    capacity,
                }) => out.resize(2 * capacity.max(8), GranulePair { a: 0, b: 0 }),
                Err(e) => return Err(e),
            }
        };
        out.truncate(count);
        // Each pair that stays keeps its work at its new place: its face
        // lists (which only save time; before, a pair whose place moved
        // rebuilt them) and its sums of the step (before, a rebuild in a
        // later sweep gave a moved pair another pair's). What it holds it
        // keeps only where its place did not move: a moved pair searches
        // again in its next sweep, as it did when the work stayed by place.
        // Held by pair instead, the published run searched 9 % less late in
        // the compression, but the coarse stability suite passed 30 of its
        // 36 beds instead of 33 (BENCHMARKS.md, session 41).
        debug_assert_eq!(self.pairs.len(), self.work.len());
        let mut old = core::mem::take(&mut self.work);
        let mut unheld = false;
        self.work = out
            .iter()
            .enumerate()
            .map(|(i, p)| match self.pairs.binary_search(p) {
                Ok(k) if k < old.len() => {
                    let mut w = core::mem::take(&mut old[k]);
                    if k != i {
                        w.hold(false);
                        unheld = true;
                    }
                    w
                }
                // New to the list (or an old list that was not sorted:
                // the pair then only starts afresh).
                _ => {
                    unheld = true;
                    PairWork::default()
                }
            })
            .collect();
        self.pairs = out;
        self.index_pairs();
        self.built.clone_from(&self.bounds);
        self.rebuilds += 1;
        // A pair new to the list, or moved in it, holds nothing of this
        // step's first sweep, so the later sweeps of this step search.
        self.unheld |= !first_sweep && unheld;
        Ok(())
    }

    /// Detection on every candidate pair (in parallel), growing a pair's
    /// constraint list when it is full.
    ///
    /// After the first sweep of a step only pairs with a granule that the
    /// last sweep moved are searched again: the others found nothing (a
    /// constraint would have moved both) and their x̃ is unchanged. With
    /// `hold`, a later sweep does not search a pair the step's first sweep
    /// searched: it re-measures that sweep's constraints of the pair on the
    /// current x̃ at their contact points ([`regap`]), keeping those still
    /// penetrating (a pair held with none stays without any for the step).
    /// Only a pair new to the list, or moved in it, by a rebuild within the
    /// step is searched.
    ///
    /// With `hold` and `between` (a step between two searches,
    /// [`super::AssemblyParams::contact_search_interval`]) the first sweep
    /// does the same with what the last search held: a pair that holds
    /// constraints of the last step's first sweep (searched or held then)
    /// re-measures them; only a pair that holds nothing (new to the list
    /// since, or moved in it) is searched, and what it finds is held from
    /// then on.
    pub(super) fn detect(
        &mut self,
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        settings: &PairSettings,
        first: bool,
        hold: bool,
        between: bool,
    ) -> Result<(), ContactError> {
        let drift = self.list_drift;
        // Which pairs re-measure what they hold instead of searching.
        let reuse_held = hold && (!first || between);
        // A sweep searches some pair unless every pair re-measures: only
        // then does it need the boxes and anchors (else it marks them stale).
        let searching =
            !reuse_held || self.unheld || (first && !self.work.iter().all(|w| w.holding));
        self.refresh_surfaces(granules, mesh, first, searching);
        let (boxes, bounds, quad_boxes) = (&self.boxes, &self.bounds, &self.quad_boxes);
        let (touched, anchors, epochs) = (&self.touched, &self.anchors, &self.epochs);
        let stale = &self.stale;
        let first_surface = mesh.surface_range().start;
        let anchor = |g: usize| AnchorSurface {
            x: &anchors[g],
            first_surface,
            quads: &mesh.quads,
        };
        // Searches pair `p` into `w`; returns the face-list builds (0 or 1).
        let search = |p: &GranulePair,
                      (body_a, body_b): (&SurfaceBody<'_>, &SurfaceBody<'_>),
                      scratch: &mut DetectScratch,
                      w: &mut PairWork|
         -> Result<u64, ContactError> {
            if drift <= 0.0 {
                detect_growing(body_a, body_b, settings, scratch, w, false)?;
                return Ok(0);
            }
            let m = settings.margin;
            if body_a
                .bounds
                .expanded(m)
                .intersect(&body_b.bounds.expanded(m))
                .is_empty()
            {
                // Both passes would stop here: nothing to list.
                w.count = 0;
                return Ok(0);
            }
            let (a, b) = (p.a as usize, p.b as usize);
            let key = Some((*p, epochs[a], epochs[b]));
            let mut builds = 0;
            if w.lists.key != key {
                let (ab, ba) = w.lists.pass.split_at_mut(1);
                let f = settings.window_fraction;
                ab[0].build(&anchor(a), &anchor(b), f, drift, &mut scratch.reach)?;
                ba[0].build(&anchor(b), &anchor(a), f, drift, &mut scratch.reach)?;
                w.lists.key = key;
                builds = 1;
            }
            detect_growing(body_a, body_b, settings, scratch, w, true)?;
            Ok(builds)
        };
        let (builds, searches) = self
            .pairs
            .par_iter()
            .zip(self.work.par_iter_mut())
            .try_fold(
                || (DetectScratch::default(), 0u64, 0u64),
                |(mut scratch, mut builds, mut searches), (p, w)| {
                    let (a, b) = (p.a as usize, p.b as usize);
                    if !first && !touched[a] && !touched[b] {
                        w.count = 0;
                        return Ok((scratch, builds, searches));
                    }
                    let body_a = body(&granules[a], mesh, (boxes[a], bounds[a], &quad_boxes[a]));
                    let body_b = body(&granules[b], mesh, (boxes[b], bounds[b], &quad_boxes[b]));
                    if reuse_held && w.holding {
                        if w.constraints.len() < w.held.len() {
                            w.constraints.resize(w.held.len(), Constraint::default());
                        }
                        w.count = regap(&body_a, &body_b, &w.held, settings, &mut w.constraints)?;
                        return Ok((scratch, builds, searches));
                    }
                    debug_assert!(!stale[a] && !stale[b], "pair {p:?} searched on stale boxes");
                    searches += 1;
                    builds += search(p, (&body_a, &body_b), &mut scratch, w)?;
                    // Every search, and only a search, renews what is held
                    // (the first sweep searches every pair).
                    w.hold(hold && first);
                    // Near constraints (a capture distance) are held only:
                    // the forces and counts take the penetrating ones.
                    if settings.capture > 0.0 {
                        w.count = penetrating(&mut w.constraints[..w.count]);
                    }
                    Ok((scratch, builds, searches))
                },
            )
            .map(|r| r.map(|(_, builds, searches)| (builds, searches)))
            .try_reduce(|| (0, 0), |x, y| Ok((x.0 + y.0, x.1 + y.1)))?;
        self.list_builds += builds;
        self.searches += searches;
        Ok(())
    }

    /// Brings what a search reads up to date with x̃: each granule's
    /// surface box and quad boxes and, with face lists, its anchor — renewed
    /// when x̃ has left it by more than the face-list drift (or holds a NaN,
    /// or has none yet): its surface x̃ becomes the anchor and its epoch
    /// advances, so its pairs rebuild their lists. The first sweep of a step
    /// takes every granule; a later one only those the last sweep moved
    /// (`forced`), or marked stale since. A sweep that will not search
    /// (`searching` false: every pair re-measures what it holds) only marks
    /// the moved granules stale, so the work is done once, before the next
    /// search.
    fn refresh_surfaces(
        &mut self,
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        first: bool,
        searching: bool,
    ) {
        let surface = mesh.surface_range();
        let drift = self.list_drift;
        let forced = &self.forced;
        let n = granules.len();
        self.stale.resize(n, true);
        self.boxes.resize(n, Aabb::EMPTY);
        // (resize_with: no box list is made unless a granule is new.)
        self.quad_boxes
            .resize_with(n, || vec![Aabb::EMPTY; mesh.quads.len()]);
        // (Without face lists the anchors stay empty and unread.)
        self.anchors.resize(n, Vec::new());
        self.epochs.resize(n, 0);
        let face_lists = drift > 0.0;
        self.anchor_renewals += self
            .stale
            .par_iter_mut()
            .zip(self.boxes.par_iter_mut())
            .zip(self.quad_boxes.par_iter_mut())
            .zip(granules.par_iter())
            .zip(self.anchors.par_iter_mut())
            .zip(self.epochs.par_iter_mut())
            .enumerate()
            .map(|(k, (((((stale, aabb), quads), g), anchor), epoch))| {
                let changed = moved(forced, k, first);
                if !searching {
                    *stale |= changed;
                    return 0;
                }
                if !(changed || *stale) {
                    return 0;
                }
                *stale = false;
                *aabb = Aabb::of_surface(&g.x_pred, surface.start);
                quad_bounds(&g.x_pred, &mesh.quads, quads);
                if !face_lists {
                    return 0;
                }
                let moved = face_lists::drift(&g.x_pred, surface.start, anchor);
                // A NaN renews too.
                let renew = moved.is_nan() || moved > drift;
                if renew {
                    anchor.clear();
                    anchor.extend_from_slice(&g.x_pred[surface.clone()]);
                    *epoch = epoch.wrapping_add(1);
                }
                u64::from(renew)
            })
            .sum::<u64>();
    }

    /// Contact counts per node for the mass sharing, granules in parallel:
    /// each granule's pairs in list order ([`mark_side`]: a node counts
    /// once per pair it takes part in), then its contacts with `walls`
    /// (one per wall). The counts are those of one pass over the pairs.
    /// Errors: a wall the count refuses ([`count_wall_contacts`]).
    pub(super) fn count_contacts(
        &mut self,
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        walls: &[Wall],
    ) -> Result<(), ContactError> {
        // Contacts involve surface nodes only: the other entries stay 0 and
        // u32::MAX from `new`.
        let surface = mesh.surface_range();
        let (pairs_of, work, bounds) = (&self.by_granule, &self.work, &self.bounds);
        self.share
            .par_iter_mut()
            .zip(self.tag.par_iter_mut())
            .zip(granules.par_iter())
            .enumerate()
            .try_for_each(|(g, ((count, tag), store))| {
                count[surface.clone()].fill(0);
                tag[surface.clone()].fill(u32::MAX);
                let mut inv = Involvement { tag, count };
                for &(k, side) in &pairs_of[g] {
                    let w = &work[k as usize];
                    if w.count > 0 {
                        mark_side(w.constraints(), side, &mesh.quads, &mut inv, k);
                    }
                }
                let b = bounds[g];
                walls
                    .iter()
                    .filter(|w| w.may_touch(&b.centre, b.radius))
                    .try_for_each(|w| {
                        count_wall_contacts(w, surface.clone(), &store.x_pred, inv.count)
                    })
            })
    }

    /// The forces of every pair (in parallel) into the pairs' own lists.
    /// `sharing` selects the counts of [`Self::count_contacts`] (else
    /// none). (The bodies' boxes may be stale here: the forces read none.)
    /// `first` marks the first sweep of a step (which resets the step's
    /// per-pair totals).
    pub(super) fn forces(
        &mut self,
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        settings: &PairSettings,
        dt_squared: Real,
        sharing: bool,
        first: bool,
    ) -> Result<(), ContactError> {
        let (boxes, bounds, quad_boxes, share) =
            (&self.boxes, &self.bounds, &self.quad_boxes, &self.share);
        self.pairs
            .par_iter()
            .zip(self.work.par_iter_mut())
            .try_for_each(|(p, w)| {
                let (a, b) = (p.a as usize, p.b as usize);
                let body_a = body(&granules[a], mesh, (boxes[a], bounds[a], &quad_boxes[a]));
                let body_b = body(&granules[b], mesh, (boxes[b], bounds[b], &quad_boxes[b]));
                let (sa, sb): (&[u16], &[u16]) = if sharing {
                    (&share[a], &share[b])
                } else {
                    (&[], &[])
                };
                let need = 5 * w.count;
                if w.forces.len() < need {
                    w.forces.resize(need, NodeForce::default());
                }
                let (k, result) = forces(
                    (&body_a, sa),
                    (&body_b, sb),
                    &w.constraints[..w.count],
                    settings,
                    dt_squared,
                    &mut w.forces,
                )?;
                w.force_count = k;
                w.result = result;
                if first {
                    w.step = result;
                } else {
                    let t = &mut w.step;
                    t.normal += result.normal;
                    for a in 0..3 {
                        t.friction_on_a[a] += result.friction_on_a[a];
                        t.total_on_a[a] += result.total_on_a[a];
                    }
                    t.slipping = t.slipping.max(result.slipping);
                    t.min_gap = t.min_gap.min(result.min_gap);
                }
                Ok(())
            })
    }

    /// Adds the pair forces on granule `g` to `f_c`, its pairs in list
    /// order and each pair's entries in their order; true if there were any.
    pub(super) fn gather(&self, g: usize, f_c: &mut [[Real; 3]]) -> bool {
        let mut any = false;
        for &(k, side) in &self.by_granule[g] {
            let w = &self.work[k as usize];
            any |= w.force_count > 0;
            for e in &w.forces[..w.force_count] {
                if e.side == side {
                    for (f, df) in f_c[e.node as usize].iter_mut().zip(e.force) {
                        *f += df;
                    }
                }
            }
        }
        any
    }

    /// Most negative granule–granule gap on the current positions x_n, m
    /// (0 when nothing overlaps): a detection pass on x_n, pairs in
    /// parallel (a minimum, so the same for any thread count).
    pub(super) fn penetration(
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        settings: &PairSettings,
    ) -> Result<Real, granbed_kernel::contact::pair::ContactError> {
        let first = mesh.surface_range().start;
        let bounds: Vec<Bound> = granules
            .iter()
            .map(|g| bounding_sphere(&g.x, first))
            .collect();
        let boxes: Vec<Aabb> = granules
            .iter()
            .map(|g| Aabb::of_surface(&g.x, first))
            .collect();
        let quad_boxes: Vec<Vec<Aabb>> = granules
            .par_iter()
            .map(|g| {
                let mut out = vec![Aabb::EMPTY; mesh.quads.len()];
                quad_bounds(&g.x, &mesh.quads, &mut out);
                out
            })
            .collect();
        let mut head = vec![0; 8 * granules.len() + 8];
        let mut next = vec![0; granules.len()];
        let mut pairs = vec![GranulePair { a: 0, b: 0 }; 16 * granules.len() + 16];
        let n = candidate_pairs(
            &bounds,
            settings.margin,
            &mut BroadScratch {
                head: &mut head,
                next: &mut next,
            },
            &mut pairs,
        )?;
        pairs[..n]
            .par_iter()
            .map_init(
                || (DetectScratch::default(), PairWork::default()),
                |(scratch, w), p| {
                    let (a, b) = (p.a as usize, p.b as usize);
                    let (ga, gb) = (&granules[a], &granules[b]);
                    detect_growing(
                        &body_at(ga, &ga.x, mesh, (boxes[a], bounds[a], &quad_boxes[a])),
                        &body_at(gb, &gb.x, mesh, (boxes[b], bounds[b], &quad_boxes[b])),
                        settings,
                        scratch,
                        w,
                        false,
                    )?;
                    Ok(w.constraints().iter().map(|c| c.gap).fold(0.0, Real::min))
                },
            )
            .try_reduce(|| 0.0, |x: Real, y: Real| Ok(x.min(y)))
    }
}

/// Detection of the pair into `w` with the (per-thread) `scratch` —
/// through the pair's face lists ([`detect_listed`]) when `listed`, else
/// trying every face ([`detect`]) —, doubling the pair's constraint list
/// until it fits.
fn detect_growing(
    a: &SurfaceBody<'_>,
    b: &SurfaceBody<'_>,
    settings: &PairSettings,
    scratch: &mut DetectScratch,
    w: &mut PairWork,
    listed: bool,
) -> Result<(), ContactError> {
    let need = a.quads.len().max(b.quads.len());
    if scratch.faces.len() < need {
        scratch.faces.resize(need, CandidateFace::default());
    }
    if scratch.slot.len() < need {
        scratch.slot.resize(need, u32::MAX);
    }
    if w.constraints.is_empty() {
        w.constraints.resize(64, Constraint::default());
    }
    let lists = [w.lists.pass[0].view(), w.lists.pass[1].view()];
    loop {
        let found = if listed {
            detect_listed(
                a,
                b,
                settings,
                [&lists[0], &lists[1]],
                &mut scratch.faces,
                &mut scratch.slot,
                &mut w.constraints,
            )
        } else {
            detect(a, b, settings, &mut scratch.faces, &mut w.constraints)
        };
        match found {
            Ok(n) => {
                w.count = n;
                return Ok(());
            }
            Err(ContactError::Capacity {
                buffer: "constraints",
                ..
            }) => {
                let grown = 2 * w.constraints.len();
                let fill = w.constraints[0];
                w.constraints.resize(grown, fill);
            }
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::MeshLevel;

    const R: Real = 0.5e-3;

    /// Granules of `mesh` translated to `centres`, at rest (x = x̃).
    fn granules_at(mesh: &OwnedReference, centres: &[[Real; 3]]) -> Vec<GranuleStore> {
        centres
            .iter()
            .map(|c| {
                let mut g = GranuleStore::new(mesh, 1);
                for (x, x0) in g.x.iter_mut().zip(&mesh.positions) {
                    *x = core::array::from_fn(|a| c[a] + x0[a]);
                }
                g.x_pred.clone_from(&g.x);
                g
            })
            .collect()
    }

    fn phase(granules: &[GranuleStore], mesh: &OwnedReference) -> ContactPhase {
        ContactPhase::new(granules, mesh)
            .with_face_lists(super::super::FACE_LIST_SKIN * mesh.mean_face_diagonal())
    }

    /// The constraints of pair (a, b), if it is a candidate.
    fn pair_constraints(p: &ContactPhase, a: u32, b: u32) -> Option<Vec<Constraint>> {
        let k = p.pairs.iter().position(|q| (q.a, q.b) == (a, b))?;
        Some(p.work[k].constraints().to_vec())
    }

    /// A at the origin touching B (overlap 0.02 R), C far away, to be
    /// moved onto A: the granules and their contact phase after a first
    /// sweep (a search, holding).
    fn a_touching_b_and_c_far(
        mesh: &OwnedReference,
        settings: &PairSettings,
    ) -> (Vec<GranuleStore>, ContactPhase) {
        let overlap = 0.02 * R;
        let start = [
            [0.0; 3],
            [2.0 * R - overlap, 0.0, 0.0],
            [0.0, 10.0 * R, 0.0],
        ];
        let granules = granules_at(mesh, &start);
        let mut p = phase(&granules, mesh);
        p.broad(&granules, mesh, settings.margin, true).unwrap();
        p.detect(&granules, mesh, settings, true, true, false)
            .unwrap();
        (granules, p)
    }

    /// A far above B, B touching C (overlap 0.02 R): the granules and their
    /// contact phase after a first sweep (a search, holding), whose only
    /// pair is (B, C).
    fn a_far_and_b_touching_c(
        mesh: &OwnedReference,
        settings: &PairSettings,
    ) -> (Vec<GranuleStore>, ContactPhase) {
        let start = [
            [0.0, 10.0 * R, 0.0],
            [0.0; 3],
            [2.0 * R - 0.02 * R, 0.0, 0.0],
        ];
        let granules = granules_at(mesh, &start);
        let mut p = phase(&granules, mesh);
        p.broad(&granules, mesh, settings.margin, true).unwrap();
        p.detect(&granules, mesh, settings, true, true, false)
            .unwrap();
        assert_eq!(p.pairs(), &[GranulePair { a: 1, b: 2 }]);
        (granules, p)
    }

    /// Moves granule `g`'s x̃ by `d`.
    fn shift(g: &mut GranuleStore, d: [Real; 3]) {
        for x in &mut g.x_pred {
            for a in 0..3 {
                x[a] += d[a];
            }
        }
    }

    /// Moves C (granule 2 of [`a_touching_b_and_c_far`]) onto A from below.
    fn move_c_onto_a(granules: &mut [GranuleStore], mesh: &OwnedReference) {
        let to = 2.0 * R - 0.02 * R;
        let now = granules[2].x_pred[0][1] - mesh.positions[0][1];
        shift(&mut granules[2], [0.0, -to - now, 0.0]);
    }

    /// What a fresh search (first sweep) of `granules` finds for (a, b).
    fn searched(
        granules: &[GranuleStore],
        mesh: &OwnedReference,
        settings: &PairSettings,
        (a, b): (u32, u32),
    ) -> Vec<Constraint> {
        let mut fresh = phase(granules, mesh);
        fresh.broad(granules, mesh, settings.margin, true).unwrap();
        fresh
            .detect(granules, mesh, settings, true, true, false)
            .unwrap();
        pair_constraints(&fresh, a, b).unwrap()
    }

    /// A held sweep leaves the boxes and anchor of a granule it moved for
    /// the next search to take. When the list is rebuilt within the step,
    /// the new pair is searched, and on the moved granule's current boxes
    /// and anchor: it finds what a first sweep on the same x̃ finds.
    #[test]
    fn a_pair_new_in_a_later_sweep_is_searched_on_current_boxes() {
        let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
        let settings = PairSettings::standard(0.1);
        let (mut granules, mut p) = a_touching_b_and_c_far(&mesh, &settings);
        assert!(
            pair_constraints(&p, 0, 2).is_none(),
            "C is no candidate yet"
        );
        let held = pair_constraints(&p, 0, 1).unwrap();
        assert!(!held.is_empty(), "A and B touch");

        // A later sweep that moves B a little (no rebuild, no search):
        // B's boxes are left stale.
        p.forced = vec![false, true, false];
        p.touched.clone_from(&p.forced);
        shift(&mut granules[1], [-1e-3 * settings.margin, 0.0, 0.0]);
        p.broad(&granules, &mesh, settings.margin, false).unwrap();
        p.detect(&granules, &mesh, &settings, false, true, false)
            .unwrap();
        assert!(p.stale[1], "a held sweep takes no boxes");
        assert!(p.stale_boxes(&granules, &mesh).is_empty());

        // The next moves C onto A from below: the list is rebuilt, the new
        // pair (A, C) searched, and B's boxes taken as well.
        p.forced = vec![false, false, true];
        p.touched.clone_from(&p.forced);
        move_c_onto_a(&mut granules, &mesh);
        p.broad(&granules, &mesh, settings.margin, false).unwrap();
        p.detect(&granules, &mesh, &settings, false, true, false)
            .unwrap();
        let found = pair_constraints(&p, 0, 2).expect("(A, C) is a candidate");
        let expected = searched(&granules, &mesh, &settings, (0, 2));
        assert!(!expected.is_empty(), "A and C touch");
        assert_eq!(found, expected, "the new pair was not searched on C's x̃");
        assert!(p.stale_boxes(&granules, &mesh).is_empty());
    }

    /// A step between two searches holds the last search's constraints:
    /// its first sweep re-measures them on the new x̃ (the same nodes,
    /// faces, weights and normals, the new gaps), searches nothing and
    /// takes no boxes; a pair new to the list since is searched and finds
    /// what a search of the same x̃ finds.
    #[test]
    fn a_step_between_searches_re_measures_what_the_last_search_held() {
        let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
        let settings = PairSettings::standard(0.1);
        let (mut granules, mut p) = a_touching_b_and_c_far(&mesh, &settings);
        let held = pair_constraints(&p, 0, 1).unwrap();
        assert!(!held.is_empty(), "A and B touch");
        let searches = p.searches();

        // The next step moves B a little deeper into A (no rebuild).
        let push = 1e-3 * 0.02 * R;
        shift(&mut granules[1], [-push, 0.0, 0.0]);
        p.broad(&granules, &mesh, settings.margin, true).unwrap();
        p.detect(&granules, &mesh, &settings, true, true, true)
            .unwrap();
        assert_eq!(p.searches(), searches, "a held step searched");
        assert!(p.stale.iter().all(|&s| s), "a held step takes no boxes");
        let again = pair_constraints(&p, 0, 1).unwrap();
        assert_eq!(again.len(), held.len(), "every held constraint deepened");
        for (c, h) in again.iter().zip(&held) {
            assert_eq!(
                (c.side, c.slave, c.quad, c.weights, c.normal),
                (h.side, h.slave, h.quad, h.weights, h.normal)
            );
            let moved = match c.side {
                Side::A => push * h.normal[0],
                Side::B => -push * h.normal[0],
            };
            assert!(
                (c.gap - (h.gap + moved)).abs() <= 1e-12 * R,
                "gap {} against {} + {moved}",
                c.gap,
                h.gap
            );
        }

        // The step after moves C onto A: the list is rebuilt and only the
        // new pair (A, C) is searched, on current boxes.
        move_c_onto_a(&mut granules, &mesh);
        p.broad(&granules, &mesh, settings.margin, true).unwrap();
        p.detect(&granules, &mesh, &settings, true, true, true)
            .unwrap();
        assert_eq!(p.searches(), searches + 1, "only (A, C) is searched");
        assert_eq!(pair_constraints(&p, 0, 1).unwrap(), again);
        let found = pair_constraints(&p, 0, 2).expect("(A, C) is a candidate");
        let expected = searched(&granules, &mesh, &settings, (0, 2));
        assert!(!expected.is_empty(), "A and C touch");
        assert_eq!(found, expected);
        assert!(p.stale_boxes(&granules, &mesh).is_empty());
    }

    /// A rebuild of the candidate list that puts a new pair before an old
    /// one moves the old pair's place: the pair keeps its face lists there
    /// (only the new pair gets lists) and, its place moved, searches again
    /// instead of re-measuring what it held, finding what a fresh search
    /// finds.
    #[test]
    fn a_pair_moved_by_a_rebuild_keeps_its_face_lists_and_searches() {
        let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
        let settings = PairSettings::standard(0.1);
        let (mut granules, mut p) = a_far_and_b_touching_c(&mesh, &settings);
        assert!(
            !pair_constraints(&p, 1, 2).unwrap().is_empty(),
            "B and C touch"
        );
        let (searches, builds) = (p.searches(), p.list_builds());

        // The next step (between searches) puts A onto B: (A, B) comes
        // first in the rebuilt list and (B, C) moves to the second place.
        shift(&mut granules[0], [0.0, -(8.0 * R + 0.02 * R), 0.0]);
        p.broad(&granules, &mesh, settings.margin, true).unwrap();
        p.detect(&granules, &mesh, &settings, true, true, true)
            .unwrap();
        assert_eq!(
            p.pairs(),
            &[GranulePair { a: 0, b: 1 }, GranulePair { a: 1, b: 2 }]
        );
        assert_eq!(p.list_builds(), builds + 1, "only (A, B) gets lists");
        assert_eq!(p.searches(), searches + 2, "both pairs are searched");
        for pair in [(0, 1), (1, 2)] {
            let found = pair_constraints(&p, pair.0, pair.1).unwrap();
            assert!(!found.is_empty(), "{pair:?} touch");
            assert_eq!(found, searched(&granules, &mesh, &settings, pair));
        }
    }

    /// What a step's sweeps did together stays with its pair when a later
    /// sweep rebuilds the list: B touched C in the first sweep, a later
    /// sweep brings A near B (a candidate, no contact), and the pair
    /// counts then name B and C, not A.
    #[test]
    fn a_steps_contacts_follow_their_pair_through_a_rebuild() {
        let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
        let settings = PairSettings::standard(0.1);
        let (mut granules, mut p) = a_far_and_b_touching_c(&mesh, &settings);
        let dt2 = 1e-14;
        p.forces(&granules, &mesh, &settings, dt2, false, true)
            .unwrap();
        assert_eq!(p.contacts_per_granule(), [0, 1, 1]);

        // A later sweep moves A to half the margin above B.
        p.forced = vec![true, false, false];
        p.touched.clone_from(&p.forced);
        shift(
            &mut granules[0],
            [0.0, -(8.0 * R - 0.5 * settings.margin), 0.0],
        );
        p.broad(&granules, &mesh, settings.margin, false).unwrap();
        assert_eq!(p.pairs().len(), 2, "(A, B) is a candidate");
        p.detect(&granules, &mesh, &settings, false, true, false)
            .unwrap();
        p.forces(&granules, &mesh, &settings, dt2, false, false)
            .unwrap();
        assert!(pair_constraints(&p, 0, 1).unwrap().is_empty());
        assert_eq!(p.contacts_per_granule(), [0, 1, 1]);
        assert_eq!(p.pairs_in_contact(), 1);
    }

    /// The mass sharing's counts, granule by granule, equal a pass over
    /// the pairs in list order with `mark_involvement`, on a cluster where
    /// nodes of A take part in two pairs (B and C touch A side by side).
    #[test]
    fn the_counts_per_granule_are_those_of_a_pass_over_the_pairs() {
        let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
        let settings = PairSettings::standard(0.1);
        let d = 2.0 * R - 0.04 * R;
        let t = 1f64.to_radians();
        let centres = [
            [0.0; 3],
            [d * t.cos(), d * t.sin(), 0.0],
            [d * t.cos(), -d * t.sin(), 0.0],
        ];
        let granules = granules_at(&mesh, &centres);
        let mut p = phase(&granules, &mesh);
        p.broad(&granules, &mesh, settings.margin, true).unwrap();
        p.detect(&granules, &mesh, &settings, true, true, false)
            .unwrap();
        p.count_contacts(&granules, &mesh, &[]).unwrap();

        let nodes = mesh.positions.len();
        let mut count = vec![vec![0u16; nodes]; granules.len()];
        let mut tag = vec![vec![u32::MAX; nodes]; granules.len()];
        for (k, (q, w)) in p.pairs.iter().zip(&p.work).enumerate() {
            let (a, b) = (q.a as usize, q.b as usize);
            let (count_lo, count_hi) = count.split_at_mut(b);
            let (tag_lo, tag_hi) = tag.split_at_mut(b);
            let body_of = |g: usize| {
                body(
                    &granules[g],
                    &mesh,
                    (p.boxes[g], p.bounds[g], &p.quad_boxes[g]),
                )
            };
            granbed_kernel::contact::pair::mark_involvement(
                w.constraints(),
                (
                    &body_of(a),
                    &mut Involvement {
                        tag: &mut tag_lo[a],
                        count: &mut count_lo[a],
                    },
                ),
                (
                    &body_of(b),
                    &mut Involvement {
                        tag: &mut tag_hi[0],
                        count: &mut count_hi[0],
                    },
                ),
                k as u32,
            );
        }
        assert!(
            count[0].iter().any(|&n| n >= 2),
            "no node of A in two pairs"
        );
        assert_eq!(p.share, count);
    }
}
