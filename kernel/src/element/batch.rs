//! The one-point element evaluated [`BATCH`] elements side by side, with the
//! bits of [`hex_forces`] (structure of arrays, issue #8).
//!
//! A batch gathers its elements' nodes and reference data into [`Lanes`],
//! and runs the kinematics, the elastic trial state, the elastic stress, the
//! nodal forces and the hourglass forces once for all lanes — the same code
//! as the scalar element ([`mean_gradient_rows`], [`trial`],
//! [`nodal_forces_into`] are generic over [`Num`]), so every lane gets exactly the
//! scalar result. The yield test of [`check_trial`] runs in lanes too (its
//! pieces, [`yield_surface::porous_formula`],
//! [`yield_surface::yield_function_of`], are generic, and η ≥ 1 and the a2
//! clamp are picked lane by lane without branches,
//! [`yield_surface::coefficients_in_lanes`]). The input checks of [`check_input`] give one
//! verdict for the batch, without branches ([`input_is_valid`] of each
//! lane, F's finiteness probed in lanes). Per lane, in scalar code: the
//! test whether the lane yields ([`yields`]). The
//! corrector of the yielding lanes is solved side by side
//! ([`ReturnMapSystem::solve_lanes`]: the Newton iterations of all of them
//! at once, each lane stopping where its scalar solve stops; a batch with
//! one yielding lane takes the scalar solve), and their returned state — τ,
//! the new C_p⁻¹, the dissipation — runs once for all lanes
//! ([`returned_state`], generic; stored whole into the batch's scratch
//! before the lanes are picked, so that the compiler keeps it in lanes).
//! Both are functions of their own that are never inlined: inlined, they
//! cost the elastic batches their registers (BENCHMARKS.md, sessions 33
//! and 34; in a kernel built for baseline x86-64 they are SSE2 code called
//! from the AVX2 loop, the same bits).
//! The batch's results go to a [`Sink`] the loop is generic over, compiled
//! into it, from the lanes ([`Sink::batch`]). A batch in which any lane
//! fails is evaluated again element by element by [`hex_forces`], so
//! errors, and the states left behind, are those of the scalar loop.
//!
//! [`ElementPath`] chooses the code: element by element, portable batches
//! (the build's vector width: 2 lanes with x86-64's SSE2), or batches compiled
//! for AVX2 (4 lanes), taken only when the processor has it (detected at run
//! time with `cpuid`, no `std` needed). All three give the same bits;
//! [`ElementPath::fastest`] is AVX2 where available, the portable batches
//! in a WebAssembly build with SIMD, else element by element.
//! The run-time choice is for a kernel built for baseline x86-64, as another
//! project may link it; this workspace builds every x86-64 binary for
//! x86-64-v3 (`.cargo/config.toml`), where all three paths are AVX2 code,
//! and the browser's wasm32 module with SIMD.
//!
//! This is, with the SSE2 square root of [`crate::math::sqrt`], the
//! kernel's only `unsafe` code (the workspace denies it elsewhere), allowed
//! function by function: reading `cpuid`/`xgetbv` (`detect_avx2`), and
//! declaring and calling the AVX2-compiled loop (`Job::batched_avx2`,
//! `evaluate`, behind [`one_point_elements`]), which is sound only once [`has_avx2`] said yes —
//! each block says so. Nothing inside the AVX2 loop may be inline assembly
//! of legacy SSE (as `libm::sqrt` is on x86-64): it would pay the SSE/AVX
//! transition penalty on every call.

use crate::Real;
use crate::constitutive::return_map::{ReturnMapSystem, ReturnSolution};
use crate::constitutive::update::{
    Returned, Trial, corrector, dissipation_density, input_is_valid, returned_state, trial, yields,
};
#[cfg(doc)]
use crate::constitutive::update::{check_input, check_trial};
use crate::constitutive::yield_surface::{self, YieldCoefficients};
use crate::constitutive::{UpdateError, UpdateInfo, UpdateOptions, elastic};
use crate::element::force::{
    ElementGeometry, HexForces, hex_forces, mean_gradient_rows, nodal_forces_into,
};
use crate::element::reference::HexReference;
use crate::granule::forces::{ElementFailure, ForcesError};
use crate::lanes::{Lanes, Num};
use crate::material::Material;
use crate::tensor::{Rows, Voigt};

/// Elements per batch.
pub const BATCH: usize = 4;

/// How the one-point element loop is evaluated; every path gives the same
/// bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementPath {
    /// Element by element ([`hex_forces`]).
    Scalar,
    /// [`BATCH`] elements side by side in the build's instruction set.
    Batched,
    /// Batches compiled for AVX2; falls back to [`ElementPath::Batched`] on
    /// a processor without AVX2.
    Avx2,
}

impl ElementPath {
    /// The fastest path this processor supports: AVX2 batches if it has
    /// AVX2, otherwise element by element (portable batches at SSE2's two
    /// lanes measured slower than the scalar element: BENCHMARKS.md). In a
    /// WebAssembly build with SIMD, the portable batches: there they run
    /// as pairs of f64x2 and took the browser's B2 run from 2.7 to 2.1 s
    /// in Node (BENCHMARKS.md, "The browser's module with SIMD and the
    /// square root instruction").
    pub fn fastest() -> Self {
        if cfg!(all(target_arch = "wasm32", target_feature = "simd128")) {
            Self::Batched
        } else if has_avx2() {
            Self::Avx2
        } else {
            Self::Scalar
        }
    }
}

/// Whether the processor (and the operating system, which must save the
/// 256-bit registers) supports AVX2. Detected once with `cpuid`/`xgetbv`
/// and cached; `false` on other architectures. Not folded to `true` at
/// compile time in a build for AVX2 (as `is_x86_feature_detected!` is), so
/// such a build can ask whether it may run at all.
pub fn has_avx2() -> bool {
    use core::sync::atomic::{AtomicU8, Ordering};
    static CACHE: AtomicU8 = AtomicU8::new(0);
    match CACHE.load(Ordering::Relaxed) {
        1 => false,
        2 => true,
        _ => {
            let yes = detect_avx2();
            CACHE.store(if yes { 2 } else { 1 }, Ordering::Relaxed);
            yes
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
fn detect_avx2() -> bool {
    use core::arch::x86_64::{__cpuid, __cpuid_count, _xgetbv};
    // Leaf 1: ECX bit 27 OSXSAVE (xgetbv usable), bit 28 AVX.
    #[allow(unused_unsafe)]
    let (max_leaf, leaf1) = unsafe { (__cpuid(0).eax, __cpuid(1)) };
    if max_leaf < 7 || leaf1.ecx & (1 << 27) == 0 || leaf1.ecx & (1 << 28) == 0 {
        return false;
    }
    // SAFETY: OSXSAVE is set, so xgetbv exists; XCR0 bits 1 and 2 say the
    // OS saves the SSE and AVX register state.
    let xcr0 = unsafe { _xgetbv(0) };
    if xcr0 & 0b110 != 0b110 {
        return false;
    }
    // Leaf 7, sub-leaf 0: EBX bit 5 AVX2.
    #[allow(unused_unsafe)]
    let leaf7 = unsafe { __cpuid_count(7, 0) };
    leaf7.ebx & (1 << 5) != 0
}

#[cfg(not(target_arch = "x86_64"))]
fn detect_avx2() -> bool {
    false
}

/// One element's results as the element loop consumes them.
pub type ElementOutput = HexForces;

/// What the element loop hands each element's result to, in element
/// order. The loop is generic over it so that a sink whose methods are
/// `#[inline(always)]` is compiled into the batch loop (an indirect call
/// per element, with the output copied through memory, was 10 % of the
/// elastic element: BENCHMARKS.md, session 28). Any closure
/// `|element, &hex, &output|` is one — wrap it in [`sink`] for the
/// compiler to infer its parameter types — and so is a
/// `&mut dyn FnMut(usize, &[u32; 8], &ElementOutput)`.
pub trait Sink {
    /// Takes the result `out` of element `element` with node ids `hex`.
    fn element(&mut self, element: usize, hex: &[u32; 8], out: &ElementOutput);

    /// Takes the results of the batch of elements `first..first +`
    /// [`BATCH`] (node ids `hexes`), lane l of `out` being element
    /// `first + l`. The default hands each lane to [`Sink::element`] in
    /// order ([`BatchOutput::lane`]); a sink that reads the lanes where
    /// they are spares copying every element's forces out of them and
    /// back in (the assembly's scatter: BENCHMARKS.md, session 32).
    #[inline(always)]
    fn batch(&mut self, first: usize, hexes: &[[u32; 8]; BATCH], out: &BatchOutput<'_>) {
        for (l, hex) in hexes.iter().enumerate() {
            self.element(first + l, hex, &out.lane(l));
        }
    }
}

impl<S: FnMut(usize, &[u32; 8], &ElementOutput) + ?Sized> Sink for S {
    #[inline(always)]
    fn element(&mut self, element: usize, hex: &[u32; 8], out: &ElementOutput) {
        self(element, hex, out)
    }
}

/// The results of one batch where the loop keeps them, lane l = element l
/// of the batch: each lane is the [`ElementOutput`] of the scalar element.
#[derive(Clone, Copy, Debug)]
pub struct BatchOutput<'a> {
    /// Internal plus hourglass force of each node, `[node][xyz]`, N.
    pub forces: &'a [[Lanes<BATCH>; 3]; 8],
    /// Hourglass energy, J.
    pub hourglass_energy: Lanes<BATCH>,
    /// J = det F̄.
    pub j: Lanes<BATCH>,
    /// Kirchhoff stress, Pa (Voigt).
    pub tau: &'a [Lanes<BATCH>; 6],
    /// Constitutive diagnostics.
    pub info: &'a [UpdateInfo; BATCH],
    /// Plastic dissipation of the step, J.
    pub plastic_dissipation: &'a [Real; BATCH],
}

impl BatchOutput<'_> {
    /// Lane `l` as one element's output.
    ///
    /// # Panics
    /// If `l` ≥ [`BATCH`].
    #[inline(always)]
    pub fn lane(&self, l: usize) -> ElementOutput {
        let mut out = HexForces {
            f: [[0.0; 3]; 8],
            hourglass_energy: self.hourglass_energy.0[l],
            j: self.j.0[l],
            tau: [0.0; 6],
            info: self.info[l],
            plastic_dissipation: self.plastic_dissipation[l],
        };
        for (o, fl) in out.f.iter_mut().zip(self.forces) {
            for (oa, fa) in o.iter_mut().zip(fl) {
                *oa = fa.0[l];
            }
        }
        for (o, tk) in out.tau.iter_mut().zip(self.tau) {
            *o = tk.0[l];
        }
        out
    }
}

/// `f` as it is: a closure passed through here gets its parameter types
/// from the [`Sink`] shape, `one_point_elements(…, &mut sink(|e, hex, out|
/// …))`.
pub fn sink<F: FnMut(usize, &[u32; 8], &ElementOutput)>(f: F) -> F {
    f
}

/// The reference data of [`BATCH`] consecutive elements regrouped into
/// lanes (lane l = element l of the batch; structure of arrays), so that a
/// batch loads it as it computes. Built once per mesh by [`regroup`] and
/// shared by every granule; 1 856 bytes per batch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementBatch {
    /// V0, m³.
    pub volume: Lanes<BATCH>,
    /// V0 Σ|B0_I|²/3, m.
    pub hourglass_geometry: Lanes<BATCH>,
    /// B0_I, `[node][xyz]`, 1/m.
    pub b0: [[Lanes<BATCH>; 3]; 8],
    /// γ0_αI, `[mode][node]`.
    pub gamma0: [[Lanes<BATCH>; 8]; 4],
}

impl ElementBatch {
    /// All lanes zero (to fill buffers before [`regroup`]).
    pub const ZERO: Self = {
        let zero = Lanes([0.0; BATCH]);
        Self {
            volume: zero,
            hourglass_geometry: zero,
            b0: [[zero; 3]; 8],
            gamma0: [[zero; 8]; 4],
        }
    };

    /// The lanes of `refs`.
    #[inline(always)]
    pub fn gather(refs: &[HexReference; BATCH]) -> Self {
        let mut g = Self::ZERO;
        for (l, r) in refs.iter().enumerate() {
            g.volume.0[l] = r.volume;
            g.hourglass_geometry.0[l] = r.hourglass_geometry;
            for (gb, rb) in g.b0.iter_mut().zip(&r.b0) {
                for (v, &w) in gb.iter_mut().zip(rb) {
                    v.0[l] = w;
                }
            }
            for (gg, rg) in g.gamma0.iter_mut().zip(&r.gamma0) {
                for (v, &w) in gg.iter_mut().zip(rg) {
                    v.0[l] = w;
                }
            }
        }
        g
    }
}

/// Number of full batches of `elements` elements (the remainder is
/// evaluated element by element).
pub fn batch_count(elements: usize) -> usize {
    elements / BATCH
}

/// Regroups the per-element reference data `elements` into `out`, which
/// must hold [`batch_count`]`(elements.len())` batches; `Err` names the
/// expected length otherwise.
pub fn regroup(elements: &[HexReference], out: &mut [ElementBatch]) -> Result<(), usize> {
    let expected = batch_count(elements.len());
    if out.len() != expected {
        return Err(expected);
    }
    let (chunks, _) = elements.as_chunks::<BATCH>();
    for (o, refs) in out.iter_mut().zip(chunks) {
        *o = ElementBatch::gather(refs);
    }
    Ok(())
}

/// Evaluates the one-point elements `hexes` (with their reference data
/// `refs` and states `cp_inv`, one per element) at node positions `x`, and
/// hands the results to `sink` in element order: a full batch's at once
/// ([`Sink::batch`]), an element evaluated alone (the remainder, a batch
/// redone after a failing lane) by [`Sink::element`]. Stops at the first
/// element whose update fails and returns its index with the error
/// ([`ForcesError::Element`]); the
/// states of the elements before it are updated, the failing one's and
/// those after it are not (as an element-by-element loop would leave them).
///
/// `batches` is `refs` regrouped by [`regroup`]; if it is empty, not
/// [`batch_count`] long, or its first or last batch holds other volumes
/// than `refs`, each batch gathers its lanes from `refs`, which costs time,
/// not bits.
///
/// Lengths: `refs` and `cp_inv` as `hexes`; node ids index `x`. Both are
/// checked first, nothing evaluated if they do not fit
/// ([`ForcesError::BufferLength`], [`ForcesError::NodeId`], the element
/// pass's errors); an element that fails is [`ForcesError::Element`].
/// Not checked here, as in [`hex_forces`]: `kappa` (0 ≤ κ ≤ 1; a NaN gives
/// NaN forces) and `opts`' tolerances — [`crate::granule::forces::internal_forces`]
/// checks them with the element settings ([`crate::granule::forces::ElementSettings::check`]).
#[allow(clippy::too_many_arguments)]
pub fn one_point_elements<S: Sink + ?Sized>(
    path: ElementPath,
    mat: &Material,
    opts: &UpdateOptions,
    kappa: Real,
    hexes: &[[u32; 8]],
    refs: &[HexReference],
    batches: &[ElementBatch],
    x: &[[Real; 3]],
    cp_inv: &mut [Voigt],
    sink: &mut S,
) -> Result<(), ForcesError> {
    for (buffer, got) in [("refs", refs.len()), ("cp_inv", cp_inv.len())] {
        if got != hexes.len() {
            return Err(ForcesError::BufferLength {
                buffer,
                expected: hexes.len(),
                got,
            });
        }
    }
    let id = hexes.as_flattened().iter().fold(0, |m, &i| m.max(i));
    if !hexes.is_empty() && id as usize >= x.len() {
        return Err(ForcesError::NodeId { id, nodes: x.len() });
    }
    evaluate(
        path, mat, opts, kappa, hexes, refs, batches, x, cp_inv, sink,
    )
    .map_err(|(element, error)| ForcesError::Element(ElementFailure { element, error }))
}

/// [`one_point_elements`] without its checks, for a caller that has made
/// them ([`crate::granule::forces::internal_forces_on`] checks the mesh's
/// buffers and ids once per call, as `one_point_elements` would again):
/// lengths or ids that do not fit panic here.
#[allow(clippy::too_many_arguments)]
#[allow(unsafe_code)]
pub(crate) fn evaluate<S: Sink + ?Sized>(
    path: ElementPath,
    mat: &Material,
    opts: &UpdateOptions,
    kappa: Real,
    hexes: &[[u32; 8]],
    refs: &[HexReference],
    batches: &[ElementBatch],
    x: &[[Real; 3]],
    cp_inv: &mut [Voigt],
    sink: &mut S,
) -> Result<(), (usize, UpdateError)> {
    let job = Job {
        mat,
        opts,
        kappa,
        hexes,
        refs,
        batches: if regrouped_from(batches, refs) {
            batches
        } else {
            &[]
        },
        x,
    };
    match path {
        ElementPath::Scalar => job.scalar(0, cp_inv, sink),
        #[cfg(target_arch = "x86_64")]
        ElementPath::Avx2 if has_avx2() => {
            // SAFETY: the processor supports AVX2 (checked above).
            unsafe { job.batched_avx2(cp_inv, sink) }
        }
        ElementPath::Batched | ElementPath::Avx2 => job.batched(cp_inv, sink),
    }
}

/// Whether `batches` can be `refs` regrouped: [`batch_count`] long, and
/// the volumes of the first and the last batch are those of their
/// elements. A cheap check: it catches the regrouped data of another mesh
/// with as many elements unless those elements have the same volumes at
/// both ends (a rotated copy of the mesh would pass); a full comparison
/// would cost what regrouping saves.
fn regrouped_from(batches: &[ElementBatch], refs: &[HexReference]) -> bool {
    let lanes_match = |b: usize| {
        let volumes = &refs[b * BATCH..(b + 1) * BATCH];
        batches[b]
            .volume
            .0
            .iter()
            .zip(volumes)
            .all(|(v, r)| v.to_bits() == r.volume.to_bits())
    };
    batches.len() == batch_count(refs.len())
        && (batches.is_empty() || (lanes_match(0) && lanes_match(batches.len() - 1)))
}

/// Placeholder diagnostics: each lane's starts from these elastic fields
/// (not plastic, no iterations) and gets its η, J^e, coefficients and
/// residual written over them.
const UNSET: UpdateInfo = UpdateInfo::elastic(
    0.0,
    0.0,
    YieldCoefficients {
        a1: 0.0,
        a2: 0.0,
        a2_clamped: false,
    },
    0.0,
);

/// Whether every lane passes [`check_input`] ([`input_is_valid`]). A lane
/// of F with an entry that is not finite makes its lane of Σ F_ab·0 NaN;
/// finite entries leave it +0 ([`non_finite_probe`]).
#[allow(non_snake_case)]
#[inline(always)]
fn inputs_valid<const W: usize>(F: &Rows<Lanes<W>>, t: &Trial<Lanes<W>>) -> bool {
    let probe = non_finite_probe(F.as_flattened());
    let mut valid = true;
    for l in 0..W {
        valid &= input_is_valid(
            !probe.0[l].is_nan(),
            t.j.0[l],
            t.det_cp_inv.0[l],
            t.eta.0[l],
        );
    }
    valid
}

/// Σ v·0 over `values`, lane by lane: NaN in exactly the lanes where some
/// value is not finite (∞·0 and NaN·0 are NaN), +0 elsewhere — one vector
/// expression whose lanes give a batch's verdict (F in [`inputs_valid`],
/// the new C_p⁻¹ in [`return_lanes`]).
#[inline(always)]
fn non_finite_probe<const W: usize>(values: &[Lanes<W>]) -> Lanes<W> {
    let zero = Lanes::splat(0.0);
    let mut probe = zero;
    for &v in values {
        probe = probe + v * zero;
    }
    probe
}

/// The node coordinates, nodal forces and returned state of a batch in
/// lanes, kept from batch to batch: a batch writes all of `x` before it
/// reads it, all of `forces` (in [`nodal_forces_into`]) and of `returned`
/// (in [`return_lanes`]) before it reads them, so nothing of an earlier
/// batch is seen. Arrays made afresh per batch were zeroed by a
/// call of `memset` each, and the nodal forces handed back copied by
/// `memcpy` (about 7 % of the elastic element: BENCHMARKS.md, session 31).
struct BatchLanes {
    /// x_I, `[node][xyz]`, m.
    x: [[Lanes<BATCH>; 3]; 8],
    /// f_I, `[node][xyz]`, N.
    forces: [[Lanes<BATCH>; 3]; 8],
    /// The returned state of all lanes, of which only the yielding ones
    /// are read ([`return_lanes`]).
    returned: Returned<Lanes<BATCH>>,
}

impl BatchLanes {
    const ZERO: Self = {
        let zero = Lanes([0.0; BATCH]);
        Self {
            x: [[zero; 3]; 8],
            forces: [[zero; 3]; 8],
            returned: Returned {
                tau: [zero; 6],
                cp_inv: [zero; 6],
                theta: zero,
                je: zero,
                gamma: zero,
            },
        }
    };
}

/// The inputs shared by every element of a loop.
struct Job<'a> {
    mat: &'a Material,
    opts: &'a UpdateOptions,
    kappa: Real,
    hexes: &'a [[u32; 8]],
    refs: &'a [HexReference],
    batches: &'a [ElementBatch],
    x: &'a [[Real; 3]],
}

impl Job<'_> {
    /// Elements `first..first + cp_inv.len()` one by one.
    fn scalar<S: Sink + ?Sized>(
        &self,
        first: usize,
        cp_inv: &mut [Voigt],
        sink: &mut S,
    ) -> Result<(), (usize, UpdateError)> {
        for (k, c) in cp_inv.iter_mut().enumerate() {
            let e = first + k;
            let hex = &self.hexes[e];
            let xe = core::array::from_fn(|i| self.x[hex[i] as usize]);
            let out = hex_forces(self.mat, self.opts, self.kappa, &self.refs[e], &xe, c)
                .map_err(|error| (e, error))?;
            sink.element(e, hex, &out);
        }
        Ok(())
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    /// # Safety
    /// The processor must support AVX2 ([`has_avx2`]).
    unsafe fn batched_avx2<S: Sink + ?Sized>(
        &self,
        cp_inv: &mut [Voigt],
        sink: &mut S,
    ) -> Result<(), (usize, UpdateError)> {
        self.batched(cp_inv, sink)
    }

    /// All elements in batches of [`BATCH`], the remainder one by one.
    #[inline(always)]
    fn batched<S: Sink + ?Sized>(
        &self,
        cp_inv: &mut [Voigt],
        sink: &mut S,
    ) -> Result<(), (usize, UpdateError)> {
        let full = batch_count(cp_inv.len()) * BATCH;
        let (head, tail) = cp_inv.split_at_mut(full);
        let (states, _) = head.as_chunks_mut::<BATCH>();
        let mut lanes = BatchLanes::ZERO;
        for (b, c) in states.iter_mut().enumerate() {
            if !self.batch(b, c, &mut lanes, sink) {
                self.scalar(b * BATCH, c, sink)?;
            }
        }
        self.scalar(full, tail, sink)
    }

    /// Batch `b` (elements `b·BATCH…`) side by side: updates the states and
    /// hands the outputs to `sink`, in element order. Returns `false`,
    /// having changed no state and called no sink (only the scratch
    /// `lanes`), if any lane fails (the caller redoes the
    /// batch element by element). Plain loops, but for `core::array::from_fn`
    /// making one lane vector from its scalars: `array::map` and `from_fn`
    /// over whole structs were left out of line and copied through memory.
    #[allow(non_snake_case)]
    #[inline(always)]
    fn batch<S: Sink + ?Sized>(
        &self,
        b: usize,
        cp_inv: &mut [Voigt; BATCH],
        lanes: &mut BatchLanes,
        sink: &mut S,
    ) -> bool {
        const W: usize = BATCH;
        let first = b * W;
        let hexes = &self.hexes[first..first + W];
        let refs = &self.refs[first..first + W];
        let gathered;
        let g = match self.batches.get(b) {
            Some(g) => g,
            None => {
                let (chunk, _) = refs.as_chunks::<W>();
                gathered = ElementBatch::gather(&chunk[0]);
                &gathered
            }
        };
        let zero = Lanes::<W>::splat(0.0);
        // Each lane vector is made whole from its W scalars (written lane
        // by lane into memory and read back as one vector, it stalled on
        // store forwarding: BENCHMARKS.md). The coordinates go through
        // `Lanes::from_scalars`: made from the array, they were still
        // stored one scalar at a time into the scratch (session 37).
        let BatchLanes {
            x,
            forces,
            returned,
        } = lanes;
        for (i, xi) in x.iter_mut().enumerate() {
            let p: [&[Real; 3]; W] = core::array::from_fn(|l| &self.x[hexes[l][i] as usize]);
            for (a, xia) in xi.iter_mut().enumerate() {
                *xia = Lanes::from_scalars(core::array::from_fn(|l| p[l][a]));
            }
        }
        let mut c = [zero; 6];
        for (k, ck) in c.iter_mut().enumerate() {
            *ck = Lanes(core::array::from_fn(|l| cp_inv[l][k]));
        }
        // C_p⁻¹'s lanes are read back whole from memory (`black_box`, a
        // best-effort hint): seen as 24 loose scalars, they led the
        // compiler to compute the push-forward F C_p⁻¹ Fᵀ partly in
        // two-lane and scalar code, with spills — 43 instructions per
        // element-step more (BENCHMARKS.md, session 37). Only the code
        // generated changes, never a value.
        let c = *core::hint::black_box(&c);

        let F = mean_gradient_rows(&g.b0, x);
        let t = trial(self.mat, &F, &c);
        let mut tau = elastic::kirchhoff(self.mat, &t.b, t.je);
        // The yield test of `check_trial` for all lanes at once: the
        // porous coefficients' formula, then η ≥ 1 and the clamp (selected
        // per lane), then the scale, φ and φ/scale (the scalar bits).
        let params = &self.mat.params;
        let (a1_formula, a2_formula) = yield_surface::porous_formula(params, t.eta);
        let coefficients = yield_surface::coefficients_in_lanes(t.eta, a1_formula, a2_formula);
        let (a1, a2) = (coefficients.a1, coefficients.a2);
        let scale = yield_surface::yield_scale_of(a2, params.yield_stress_pa);
        let phi = yield_surface::yield_function_of(a1, scale, t.beta, t.alpha);
        let residual = phi / scale;
        // The input checks for all lanes; then per lane the diagnostics and
        // whether it yields; then the corrector's solution and the returned
        // state of the yielding lanes, in lanes.
        let mut info = [UNSET; W];
        let mut solutions: [Option<ReturnSolution>; W] = [None; W];
        let mut dissipation = [0.0; W];
        if !inputs_valid(&F, &t) {
            return false;
        }
        let system = corrector(self.mat, &t, a1, scale);
        let mut yielding = 0;
        for l in 0..W {
            // `check_trial`'s elastic diagnostics, written field by field
            // into the placeholder (building the struct and copying it in
            // stalled on store forwarding: BENCHMARKS.md).
            let i = &mut info[l];
            (i.eta, i.je) = (t.eta.0[l], t.je.0[l]);
            i.coefficients = coefficients.lane(l);
            i.residual = residual.0[l];
            // V0 × 0 as the scalar element computes it (−0 or NaN for a
            // malformed volume, like the scalar path).
            dissipation[l] = g.volume.0[l] * 0.0;
            yielding |= u64::from(yields(self.opts, phi.0[l], scale.0[l])) << l;
        }
        // A solved batch has a solution in every yielding lane.
        if yielding != 0
            && (!system.solve_lanes(yielding, &mut solutions)
                || !return_lanes(
                    self.mat,
                    self.opts,
                    &F,
                    &t,
                    &system,
                    g.volume,
                    &solutions,
                    &mut tau,
                    &mut info,
                    &mut dissipation,
                    cp_inv,
                    returned,
                ))
        {
            return false;
        }
        // det F̄, as the trial state took it.
        let j = t.j;
        let geometry = ElementGeometry {
            volume: g.volume,
            b0: &g.b0,
            gamma0: &g.gamma0,
            hourglass_geometry: g.hourglass_geometry,
        };
        let kappa_modulus = self.kappa * self.mat.p_wave_modulus();
        let hourglass_energy = nodal_forces_into(kappa_modulus, &geometry, x, &F, j, &tau, forces);
        let (hexes, _) = hexes.as_chunks::<W>();
        sink.batch(
            first,
            &hexes[0],
            &BatchOutput {
                forces,
                hourglass_energy,
                j,
                tau: &tau,
                info: &info,
                plastic_dissipation: &dissipation,
            },
        );
        true
    }
}

/// The returned state of a batch's yielding lanes (`solutions[l]` is
/// `Some`), in lanes: their τ, diagnostics, dissipation and new C_p⁻¹.
/// `false` if a yielding lane's new C_p⁻¹ is not finite: then nothing of
/// `tau`, `info`, `dissipation` or `cp_inv` is written (only the scratch
/// `returned`, the whole returned state of all lanes). A lane that does not
/// yield is computed along at ε = δ = 0 and dropped, its C_p⁻¹ unchecked.
#[allow(non_snake_case, clippy::too_many_arguments)]
#[inline(never)]
fn return_lanes<const W: usize>(
    mat: &Material,
    opts: &UpdateOptions,
    F: &Rows<Lanes<W>>,
    t: &Trial<Lanes<W>>,
    system: &ReturnMapSystem<Lanes<W>>,
    volume: Lanes<W>,
    solutions: &[Option<ReturnSolution>; W],
    tau: &mut [Lanes<W>; 6],
    info: &mut [UpdateInfo; W],
    dissipation: &mut [Real; W],
    cp_inv: &mut [Voigt],
    returned: &mut Returned<Lanes<W>>,
) -> bool {
    let a1 = system.a1;
    // `plastic_return` for every lane at once: ε = δ = 0 in the
    // lanes that do not yield, whose results are dropped.
    let of = |pick: fn(&ReturnSolution) -> Real| {
        Lanes(core::array::from_fn(|l| {
            solutions[l].as_ref().map_or(0.0, pick)
        }))
    };
    let (eps, delta) = (of(|s| s.eps), of(|s| s.delta));
    // The state is stored whole, as lane vectors, into the scratch and the
    // lanes are read back from there (`black_box`, a best-effort hint, in
    // practice keeps rustc from forwarding the stored values to the reads).
    // Only single lanes are read below, and with the state in registers
    // the compiler computed it lane by lane in scalar code: 1 736
    // instructions per call in the bed, 1 058 with the two changes below
    // (BENCHMARKS.md, session 35; a later rustc may do otherwise, and the
    // callgrind count there is the check). Only the code generated
    // changes, never a value.
    *returned = returned_state(mat, opts, F, t, system, eps, delta, |l| {
        solutions[l].is_some()
    });
    let r = core::hint::black_box(&*returned);
    // One verdict for the batch, without branches: a test that stops at
    // the first failing lane had the probe computed lane by lane.
    let probe = non_finite_probe(&r.cp_inv);
    let mut finite = true;
    for (l, sol) in solutions.iter().enumerate() {
        finite &= sol.is_none() | !probe.0[l].is_nan();
    }
    if !finite {
        return false;
    }
    for (l, sol) in solutions.iter().enumerate() {
        let Some(sol) = sol else { continue };
        for (tk, rk) in tau.iter_mut().zip(&r.tau) {
            tk.0[l] = rk.0[l];
        }
        info[l].record_return(sol, r.gamma.0[l], r.je.0[l]);
    }
    // V0 × the density for all lanes, each lane's kept or not by a
    // select: behind a branch per lane, the compiler moved the density
    // into the branches and computed it lane by lane in scalar code
    // (BENCHMARKS.md, session 37).
    let lane_dissipation = volume * dissipation_density(&r.tau, r.gamma, a1);
    for (l, sol) in solutions.iter().enumerate() {
        dissipation[l] = if sol.is_some() {
            lane_dissipation.0[l]
        } else {
            dissipation[l]
        };
    }
    for (l, sol) in solutions.iter().enumerate() {
        if sol.is_some() {
            for (c, rk) in cp_inv[l].iter_mut().zip(&r.cp_inv) {
                *c = rk.0[l];
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::GranuleType;
    use crate::tensor::VOIGT_IDENTITY;

    /// F's finiteness is what rejects a lane whose F has an infinite entry
    /// but whose J, det C_p⁻¹ and η pass: F = diag(∞, 1, 1) gives J = +∞
    /// and η = η0/∞ = 0. A NaN entry is rejected too, and so is a lane of
    /// an otherwise valid batch.
    #[test]
    #[allow(non_snake_case)]
    fn an_infinite_entry_of_f_fails_the_batch_although_j_and_eta_pass() {
        let mat = GranuleType::B2.params().validate().unwrap();
        let identity: Rows<Real> = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let lanes_of = |bad: Option<Real>| -> Rows<Lanes<BATCH>> {
            core::array::from_fn(|a| {
                core::array::from_fn(|b| {
                    Lanes(core::array::from_fn(|l| match bad {
                        Some(v) if l == 2 && a == 0 && b == 0 => v,
                        _ => identity[a][b],
                    }))
                })
            })
        };
        let c: [Lanes<BATCH>; 6] = VOIGT_IDENTITY.map(Lanes::splat);
        let valid = lanes_of(None);
        assert!(inputs_valid(&valid, &trial(&mat, &valid, &c)));
        let infinite = lanes_of(Some(Real::INFINITY));
        let t = trial(&mat, &infinite, &c);
        assert_eq!(t.j.0[2], Real::INFINITY);
        assert!(t.eta.0[2].is_finite() && t.det_cp_inv.0[2] > 0.0);
        assert!(input_is_valid(
            true,
            t.j.0[2],
            t.det_cp_inv.0[2],
            t.eta.0[2]
        ));
        assert!(!inputs_valid(&infinite, &t));
        let nan = lanes_of(Some(Real::NAN));
        assert!(!inputs_valid(&nan, &trial(&mat, &nan, &c)));
    }

    /// A new C_p⁻¹ that is not finite fails the batch only in a yielding
    /// lane: then nothing of the states is written; in a lane that does not
    /// yield (computed along and dropped) it is ignored, and only the
    /// yielding lanes' states are written. J = 0 in the trial state makes
    /// F̄⁻¹, and with it the lane's C_p⁻¹, infinite.
    #[test]
    #[allow(non_snake_case)]
    fn a_returned_state_that_is_not_finite_fails_the_batch_only_where_it_yields() {
        use crate::constitutive::return_map::ReturnMethod;
        let mat = GranuleType::B2.params().validate().unwrap();
        let opts = UpdateOptions::default();
        let squeeze = [[0.97, 0.0, 0.01], [0.0, 0.95, 0.0], [0.0, -0.02, 0.96]];
        let F: Rows<Lanes<BATCH>> = squeeze.map(|row| row.map(Lanes::splat));
        let c: [Lanes<BATCH>; 6] = VOIGT_IDENTITY.map(Lanes::splat);
        let solution = Some(ReturnSolution {
            eps: 1.0e-4,
            delta: 2.0e-4,
            iterations: 3,
            method: ReturnMethod::Newton,
            residual: 0.0,
        });
        // Lanes 0 and 2 yield.
        let solutions = [solution, None, solution, None];
        let run = |zero_j: &[usize]| {
            let mut t = trial(&mat, &F, &c);
            for &l in zero_j {
                t.j.0[l] = 0.0;
            }
            let system = corrector(&mat, &t, Lanes::splat(0.5), Lanes::splat(1.0e6));
            let mut tau = c;
            let mut states = [[7.0; 6]; BATCH];
            let mut returned = BatchLanes::ZERO.returned;
            let ok = return_lanes(
                &mat,
                &opts,
                &F,
                &t,
                &system,
                Lanes::splat(1.0e-12),
                &solutions,
                &mut tau,
                &mut [UNSET; BATCH],
                &mut [0.0; BATCH],
                &mut states,
                &mut returned,
            );
            let finite = returned.cp_inv.map(|k| k.0.map(Real::is_finite));
            (ok, states, finite)
        };
        // A dropped lane with an infinite state: ignored.
        let (ok, states, finite) = run(&[1]);
        assert!(!finite.iter().all(|k| k[1]), "lane 1's state is not finite");
        assert!(ok);
        for (l, state) in states.iter().enumerate() {
            let written = solutions[l].is_some();
            assert_eq!(state != &[7.0; 6], written, "lane {l}");
            assert!(state.iter().all(|v| v.is_finite()));
        }
        // A yielding lane with an infinite state: the batch fails, and no
        // state is written (lane 0, before it, neither).
        let (ok, states, finite) = run(&[1, 2]);
        assert!(!finite.iter().all(|k| k[2]));
        assert!(!ok);
        assert_eq!(states, [[7.0; 6]; BATCH]);
    }
}
