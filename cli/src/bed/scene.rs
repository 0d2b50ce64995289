//! The scene of a bed compression: a TOML file (format `version` 1, every
//! quantity with its unit in the field name, unknown fields rejected), the
//! embedded default (the published scene) and its validation.

use anyhow::{Context as _, bail};
use granbed_kernel::granule::forces::{ElementKind, ElementSettings};
use granbed_kernel::material::{GranuleType, Material, MaterialParams};
use serde::{Deserialize, Serialize};

use crate::assembly::MAX_CONTACT_SEARCH_INTERVAL;
use crate::error::{FieldError, InputError};
use crate::model::{MeshLevel, OwnedReference};
use crate::numbers::Shown;

/// The format version this build reads and writes.
pub const SCENE_VERSION: u32 = 1;

/// The fastest punch accepted, m/s: the platen speed limit of
/// `granbed-cli granule` (10000 mm/s). Far below it a step already moves
/// the punch by more than an output interval on a small bed (the run says
/// so); a bed is quasi-static only far below it (the published 0.05).
pub const MAX_PUNCH_SPEED_M_S: f64 = 10.0;

/// The slowest punch accepted, m/s (the published scene's speed / 500):
/// the run's steps grow as 1/v (the published scene at this speed would
/// take about 500 × its 17 minutes), and the speed watchdog's limit,
/// `watchdog_speed_ratio` × v, falls below the speeds the granules still
/// settle at after the pour (at 1e-6 m/s a 15-granule bed stopped at step
/// 26 on a node at 2.1 mm/s; at 1e-4 it ran).
pub const MIN_PUNCH_SPEED_M_S: f64 = 1.0e-4;

/// The widest die, in granule diameters: the pour's lattice and neighbour
/// grid grow with its square (a die a million diameters wide was accepted
/// and ran the pour out of memory).
pub const MAX_DIE_DIAMETERS: f64 = 1000.0;

/// The most granules a bed (and `pack`, and the studies' beds) takes; the
/// pour's insertion lattice must also stand at most
/// [`crate::pack::MAX_INSERTION_HEIGHT_M`] tall in its die.
pub const MAX_GRANULES: usize = 100_000;
// Spelled out in the scene's `granules` range.
const _: () = assert!(MAX_GRANULES == 100_000);

/// The largest final strain of a bed, also the bound of the fits' strain
/// windows.
pub const MAX_FINAL_STRAIN: f64 = 0.9;
// Spelled out in the checks' allowed ranges.
const _: () = assert!(MAX_FINAL_STRAIN == 0.9);

/// The Heckel fit's default strain window starts where the Kawakita fit's
/// does (physics.md §7 item 3's C ≥ 0.25): past the rearrangement, in the
/// dense stage where both laws are meant to hold. physics.md names no Heckel
/// window; the scene field `heckel_min_strain` sets another.
pub const HECKEL_MIN_STRAIN: f64 = granbed_kernel::analysis::bed::KAWAKITA_MIN_STRAIN;

/// The smallest granule diameter, mm (`granule`'s and `pack`'s floor,
/// [`crate::granule::DIAMETER_RANGE_MM`]): the pour's time step scales with
/// the diameter while its ramp and time limit are absolute, so far smaller
/// granules would pour for ever (at 10⁻⁶⁰ mm the step underflows to 0).
pub const MIN_DIAMETER_MM: f64 = crate::granule::DIAMETER_RANGE_MM[0];
const _: () = assert!(MIN_DIAMETER_MM == 0.001, "spelled out in the range");

/// The smallest output and checkpoint strain interval: the run steps its
/// next output strain forward by the interval, and an interval below the
/// round-off of the strain never got past it.
pub const MIN_STRAIN_INTERVAL: f64 = 1e-6;

/// The published scene (physics.md §6 and the paper's bed): 1000 B2
/// granules of 1280 hexes poured into an 11.3 mm die (seed 1), the upper
/// punch at 50 mm/s to 30 % axial strain, friction 0.1, ξ = 0.5.
pub const DEFAULT_SCENE: &str = r#"# granbed bed scene (format version 1). Units are in the field names.
# A field left out takes its value from before the field existed: for the
# fields below (mass scaling, time_step_floor, hold_constraints,
# contact_search_interval, contact_capture, held_reprojection,
# nearest_penetrated_face, sweep_tolerance, exact_sweep_tolerance,
# exact_contact_from_strain, unload, snapshot_strains) that is not the
# published value, and granbed-cli bed warns with the values it uses.
version = 1

# Granules: a standard type A1...C3 (A/B/C: yield stress 10/30/100 kPa;
# 1/2/3: initial relative density 0.6/0.8/1.0), and [material] overrides.
granule_type = "B2"
granules = 1000
diameter_mm = 1.0
# Mesh level NxM of the cubed sphere: 8x2 = 1280 hexes (4x1 = 160, 16x4).
mesh = "8x2"

# The pour (granbed-cli pack) and the random rotations of the meshes.
seed = 1
die_diameter_mm = 11.3

# Compression: upper punch speed and the axial strain C = (H0 - H)/H0 to reach.
punch_speed_m_s = 0.05
final_strain = 0.3
# Output rows (time averages) every this much strain.
output_strain_interval = 0.005
# VTU snapshots of the granules at these strains (vtk/ in the output).
snapshot_strains = [0.0, 0.1, 0.2, 0.3]
# After the final strain the upper punch withdraws at the same speed until it
# comes free of the bed: the unloading curve (unloading.csv), the in-die
# elastic recovery, the die wall's residual pressure and the work the bed gives
# back. false (the value of scene files without this field): the run ends at
# the final strain.
unload = true

# Checkpoints (checkpoint.bin in the output) every this many minutes of wall
# time and every this much strain; resume with granbed-cli bed --resume DIR.
checkpoint_interval_minutes = 10.0
checkpoint_strain_interval = 0.05

# Element: "one-point" (uniform gradient, hourglass control with
# coefficient hourglass_kappa) or "fbar" (2x2x2 F-bar, about 8x the cost).
element = "one-point"
hourglass_kappa = 0.05
# Selective damping of the non-rigid modes, fraction of critical.
damping_ratio = 0.5
# Contact sweeps per step at most (physics.md 5.3); a further sweep runs while
# a granule overlap deeper than sweep_tolerance (below) is left.
contact_sweeps = 25
# Mass scaling F >= 1 for quasi-static runs (1 = physical inertia; the
# summary's quasi-static certificate says whether a run stayed quasi-static).
# The stable step grows by sqrt(F): the default x20 (selective, rigid modes x2
# by the ratio below) takes under a quarter of the steps of physical masses
# and moves P(C) by 3-7 %, inside the pour-to-pour spread; it passes the
# certificate on this scene (BENCHMARKS.md). x30 takes a fifth, with the
# rigid modes x3, but fails the certificate narrowly on this scene.
mass_scaling = 20.0
# false: the scaling is uniform (every mode of a granule is F times heavier).
# true: selective, on the granules' deformational modes; their translation
# and spin carry G = max(1, F/selective_mass_ratio) times their physical
# inertia (x1, physical, for F <= 10; x2 for F = 20; x3 for F = 30).
selective_mass_scaling = true
# The largest ratio F/G (>= 1; inf: G = 1 for any F). The contacts need 10 or
# less: a node's contact mass allows for a bounded share of its granule's
# rigid response, and with F/G = 30 the nodes pressed on a punch together
# reopen their gaps and inject energy.
selective_mass_ratio = 10.0
# Safety factor on the stable time step 2/omega_max (0 < C <= 2; above 1 the
# run is unstable, which only tests the failure handling).
time_step_safety = 0.9
# Variable mass scaling (0 = off; 0 < r <= 1): a granule whose stable step
# falls below this fraction of the undeformed granule's is given k times its
# masses, the least k that lifts it back (the step grows by sqrt(k)), at most
# max_mass_factor; masses never go back down. A few strongly pressed granules
# then no longer set the step of the whole bed. The summary reports the
# granules scaled and the mass added. The default 1.0 takes 8 % fewer steps
# on this scene (up to x1.9 on a granule, +14 % mass in all), moves P(C) by
# 0.2 % and passes the certificate (BENCHMARKS.md); a scene file without
# the field runs with 0.
time_step_floor = 1.0
max_mass_factor = 4.0
# Granules move as rigid bodies (no element work) from their placement until
# their first contact: the same motion up to round-off, cheaper while the bed
# settles onto its granules and walls. false: finite-element bodies from t = 0.
rigid_until_touched = true
# Contact sweeps after the first search only the neighbourhood of the pairs
# still deeper than the tolerance (false: every pair of a moved granule).
local_sweeps = true
# Contact sweeps after the first correct the contacts the step's search found,
# re-measuring each gap at its contact point, instead of searching again: a
# third of the searches in a dense bed; the pressure moved 0.4-1.2 % on a
# 125-granule bed and 0.24 % on this scene (BENCHMARKS.md). false (the value of scene files
# without this field): every later sweep searches.
hold_constraints = true
# The contact search runs every this many steps (1..=10); on the steps
# between, the first sweep too re-measures what the last search found (only
# pairs new to the candidate list are searched). 5 takes a fifth of the
# searches; P(C) moved by 0.2 % on this scene (BENCHMARKS.md). 1 (the value
# of scene files without this field): every step searches. More than 1
# needs the held constraints above.
contact_search_interval = 5
# Capture distance of the search, as a fraction of the element size
# (0 <= c <= 0.1): nodes this close in front of a face are held with the
# contacts, so that the steps between two searches see them close (without
# it a contact closing between two searches is found late and overlaps
# more). 0 (the value of scene files without this field): only overlapping
# nodes are held.
contact_capture = 0.1
# Where a pair re-measures the contacts it holds (later sweeps, and the steps
# between two searches), a held contact whose node has slid along its face by
# more than this fraction of the element size is projected on the face afresh
# (on a curved face the held gap misses ~s^2/2R), and, with a capture
# distance, a node that lay just beside a face at the search (coming over its
# edge) is watched and held once it crosses the face (0 < s <= 1; inf, the
# value of scene files without this field: neither). With 0.05 the 30-granule
# stability suite to 30 % keeps its overlaps below 1 % of the element
# (BENCHMARKS.md).
held_reprojection = 0.05
# A node behind faces it projects inside (within the gap window) is held
# against the nearest of them whatever its own averaged normal; false: only
# against faces its normal opposes (physics.md's test, the value of scene
# files without this field). Far past 30 % a compressed granule's surface
# folds at some nodes, whose normals then turn away from the face they press
# into: under the normal test they sank into their neighbours by up to half
# an element, unseen by the contact and by the overlap measure (BENCHMARKS.md).
nearest_penetrated_face = true
# From this axial strain on, every contact sweep searches: hold_constraints
# and contact_search_interval above apply before it only (0 <= C <= 1; 1:
# never, the value of scene files without this field). They are speed
# settings measured to keep this scene's answer to 30 %; far beyond, the
# contacts move within a step by much of an element, and beds compressed to
# 60 % with them overlapped by up to 44 % of the element (BENCHMARKS.md,
# "The 30-granule suite at 60 %").
exact_contact_from_strain = 0.3
# A further contact sweep runs (up to contact_sweeps) while a granule-granule
# gap deeper than this fraction of the element size is left (0 < t <= 0.1).
# The default 0.01 takes a fifth to a quarter fewer sweeps in a dense bed
# than 0.005 (the value of scene files without this field) and leaves
# overlaps of up to ~0.6 % of the element (BENCHMARKS.md).
sweep_tolerance = 0.01
# The sweep tolerance from exact_contact_from_strain (above) on (0 < t <= 0.1;
# the value of scene files without this field: sweep_tolerance). Far past
# 30 % the overlaps left reach the tolerance itself: with 0.01 two of the
# 30-granule suite's beds overlapped by 1.00 and 1.05 % at 60 %, with 0.005
# from 30 % on by 0.54 and 0.51 % (BENCHMARKS.md); the steps before the
# switch keep sweep_tolerance.
exact_sweep_tolerance = 0.005
# Skin of the contact search's per-node face lists, as a fraction of the mean
# surface-face diagonal: a pair's lists are rebuilt once a node has moved this
# far (0: try every face near the overlap every sweep). The results are the
# same bits either way; only the speed depends on it.
face_list_skin = 0.05
# The fits of summary.json over the output rows with C >= these strains
# (0 <= C <= 0.9): Kawakita (physics.md: C >= 0.25, the dense stage) and
# Heckel (ln(1/(1 - D)) against P, D the bed's solid fraction). Past the end
# of a run, `granbed-cli bed --resume DIR --kawakita-min-strain C` refits a
# finished run without a step.
kawakita_min_strain = 0.25
heckel_min_strain = 0.25
# Watchdogs: stop (with a checkpoint from before) when the kinetic energy
# exceeds this multiple of all the energy put in (punch or contact work,
# gravity, initial motion), or when a node moves faster than this multiple of
# the punch speed: the motion is going unstable. (Contact corrections in a
# dense bed move single surface nodes at up to ~400x the punch speed for a
# step, harmlessly: the speed limit is a backstop.)
watchdog_energy_ratio = 2.0
watchdog_speed_ratio = 2000.0

# Overrides of the type's preset (SI units), e.g. yield_stress_pa = 30e3.
[material]
friction = 0.1
"#;

/// Overrides of the granule type's preset; every field optional.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverrides {
    /// Young's modulus, Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub youngs_modulus_pa: Option<f64>,
    /// Poisson's ratio.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    /// Yield stress, Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yield_stress_pa: Option<f64>,
    /// Initial relative density η0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eta0: Option<f64>,
    /// Yield-surface constant cp.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cp: Option<f64>,
    /// Critical relative density ηc.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eta_c: Option<f64>,
    /// True density, kg/m³.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub true_density_kg_m3: Option<f64>,
    /// Coulomb friction (granule–granule and granule–wall).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
}

/// A bed-compression scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Format version; must be [`SCENE_VERSION`].
    pub version: u32,
    /// Standard granule type A1…C3.
    pub granule_type: String,
    /// Number of granules, 1 ≤ N ≤ 100000.
    pub granules: usize,
    /// Granule diameter, mm, [`MIN_DIAMETER_MM`] ≤ d < 2000.
    pub diameter_mm: f64,
    /// Mesh level `NxM`.
    pub mesh: String,
    /// Seed of the pour and of the mesh rotations.
    pub seed: u64,
    /// Die diameter, mm.
    pub die_diameter_mm: f64,
    /// Upper-punch speed, m/s, [`MIN_PUNCH_SPEED_M_S`] ≤ v ≤
    /// [`MAX_PUNCH_SPEED_M_S`].
    pub punch_speed_m_s: f64,
    /// Axial strain at which the run ends, 0 < C ≤ 0.9.
    pub final_strain: f64,
    /// Strain between output rows, 0 < ΔC ≤ the final strain.
    pub output_strain_interval: f64,
    /// Strains at which VTU snapshots are written (each in [0, 0.9]; a
    /// scene file's within its final strain, [`Scene::read`]; beyond a
    /// final strain lowered by `--strain` they are not written).
    #[serde(default)]
    pub snapshot_strains: Vec<f64>,
    /// After the final strain, the upper punch withdraws at the same speed
    /// until it comes free of the bed (absent: false, the run ends at the
    /// final strain; the published scene's is true).
    #[serde(default)]
    pub unload: bool,
    /// Wall time between checkpoints, minutes (> 0).
    pub checkpoint_interval_minutes: f64,
    /// Strain between checkpoints (> 0).
    pub checkpoint_strain_interval: f64,
    /// Element formulation: `one-point` or `fbar` (absent: one-point).
    #[serde(default = "default_element")]
    pub element: String,
    /// Hourglass coefficient κ of the one-point element, 0 ≤ κ ≤ 1
    /// (absent: the kernel's default).
    #[serde(default = "default_hourglass_kappa")]
    pub hourglass_kappa: f64,
    /// Damping ratio ξ, 0 ≤ ξ ≤ 2.
    pub damping_ratio: f64,
    /// Contact sweeps per step at most, 1..=50 (a further one runs while a
    /// gap deeper than [`Self::sweep_tolerance`] × the element size is
    /// left).
    pub contact_sweeps: u32,
    /// Mass scaling F, 1 ≤ F ≤ 1e6 (absent: 1, so a scene file written
    /// before the published scene took 10 keeps its physical masses).
    #[serde(default = "unit_scaling")]
    pub mass_scaling: f64,
    /// The mass scaling acts on the deformational modes only (absent:
    /// false, uniform).
    #[serde(default)]
    pub selective_mass_scaling: bool,
    /// With selective scaling, the largest ratio R ≥ 1 of the deformational
    /// to the rigid modes' scaling: the rigid modes carry max(1, F/R) × their
    /// physical inertia (absent: ∞, physical rigid modes for any F;
    /// summary.json, being JSON, writes ∞ as null).
    #[serde(default = "unbounded_ratio")]
    pub selective_mass_ratio: f64,
    /// Safety factor on the stable step, 0 < C ≤ 2 (absent: 0.9; above 1
    /// unstable, for testing the failure handling).
    #[serde(default = "default_time_step_safety")]
    pub time_step_safety: f64,
    /// Variable mass scaling: the fraction of the undeformed granule's
    /// stable step below which a granule is given heavier masses
    /// (`AssemblyParams::time_step_floor`; absent: 0, off).
    #[serde(default)]
    pub time_step_floor: f64,
    /// The largest factor variable mass scaling puts on a granule's
    /// masses, ≥ 1 (absent: 4).
    #[serde(default = "default_max_mass_factor")]
    pub max_mass_factor: f64,
    /// Granules are rigid bodies until first touched (absent: true).
    #[serde(default = "default_true")]
    pub rigid_until_touched: bool,
    /// Later contact sweeps search only near the deep pairs (absent: true).
    #[serde(default = "default_true")]
    pub local_sweeps: bool,
    /// Later contact sweeps re-measure the first sweep's constraints
    /// instead of searching (absent: false, as before the field; the
    /// published scene's is true).
    #[serde(default)]
    pub hold_constraints: bool,
    /// The contact search runs every this many steps, 1..=10; the steps
    /// between re-measure what it found
    /// (`AssemblyParams::contact_search_interval`; absent: 1, every step,
    /// as before the field; more than 1 needs `hold_constraints`).
    #[serde(default = "default_contact_search_interval")]
    pub contact_search_interval: u32,
    /// Capture distance of the contact search as a fraction of the element
    /// size, 0 ≤ c ≤ 0.1 (`PairSettings::capture`; absent: 0).
    #[serde(default)]
    pub contact_capture: f64,
    /// Slide along its face, as a fraction of the element size, beyond
    /// which a held contact is projected afresh on the steps between
    /// searches; finite also watches the nodes just beside a face
    /// (`PairSettings::reproject_slide`, `PairSettings::watch_beside`),
    /// 0 < s ≤ 1 or ∞ (absent: ∞, neither, as before the field).
    #[serde(default = "never_reproject")]
    pub held_reprojection: f64,
    /// A node behind faces it projects inside is held against the nearest
    /// whatever its own normal (`PairSettings::nearest_penetrated_face`;
    /// absent: false, physics.md's normal test, as before the field).
    #[serde(default)]
    pub nearest_penetrated_face: bool,
    /// From this axial strain on every contact sweep searches
    /// (`AssemblyParams::exact_contact_from_s`), 0 ≤ C ≤ 1 (1 and absent:
    /// never).
    #[serde(default = "never_strain")]
    pub exact_contact_from_strain: f64,
    /// A further contact sweep runs while a granule–granule gap deeper than
    /// this fraction of the element size (the mesh's shortest surface edge)
    /// is left, 0 < t ≤ 0.1 (absent: [`super::run::SWEEP_TOLERANCE_REL`],
    /// 0.005, the tolerance before it was a field; the published scene's
    /// is 0.01).
    #[serde(default = "default_sweep_tolerance")]
    pub sweep_tolerance: f64,
    /// The sweep tolerance from `exact_contact_from_strain` on, 0 < t ≤ 0.1
    /// of the element size (`AssemblyParams::exact_sweep_tolerance_m`;
    /// absent: `sweep_tolerance`, as before the field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exact_sweep_tolerance: Option<f64>,
    /// Skin of the contact search's face lists, 0 ≤ s ≤ 1 of the mean
    /// surface-face diagonal, 0 = none (absent: the default); the same
    /// bits for any value.
    #[serde(default = "default_face_list_skin")]
    pub face_list_skin: f64,
    /// The Kawakita fit uses the output rows with C ≥ this (C the row's
    /// interval mean strain, the strain of its averaged pressure), 0 ≤ C ≤
    /// [`MAX_FINAL_STRAIN`] (absent: physics.md's 0.25).
    #[serde(default = "default_kawakita_min_strain")]
    pub kawakita_min_strain: f64,
    /// The Heckel fit uses the output rows with C ≥ this (the row's mean
    /// strain, as for Kawakita), 0 ≤ C ≤
    /// [`MAX_FINAL_STRAIN`] (absent: [`HECKEL_MIN_STRAIN`]).
    #[serde(default = "default_heckel_min_strain")]
    pub heckel_min_strain: f64,
    /// Watchdog limit on the kinetic energy as a multiple of the energy
    /// put in, 1 ≤ r ≤ 1e9 (absent: 2).
    #[serde(default = "default_watchdog_energy_ratio")]
    pub watchdog_energy_ratio: f64,
    /// Watchdog limit on any node's speed as a multiple of the punch
    /// speed, 1 ≤ r ≤ 1e9 (absent: 2000).
    #[serde(default = "default_watchdog_speed_ratio")]
    pub watchdog_speed_ratio: f64,
    /// Material overrides.
    #[serde(default)]
    pub material: MaterialOverrides,
}

fn default_kawakita_min_strain() -> f64 {
    granbed_kernel::analysis::bed::KAWAKITA_MIN_STRAIN
}

fn default_heckel_min_strain() -> f64 {
    HECKEL_MIN_STRAIN
}

fn never_strain() -> f64 {
    1.0
}

fn default_contact_search_interval() -> u32 {
    1
}

fn never_reproject() -> f64 {
    f64::INFINITY
}

fn default_sweep_tolerance() -> f64 {
    super::run::SWEEP_TOLERANCE_REL
}

fn default_face_list_skin() -> f64 {
    crate::assembly::FACE_LIST_SKIN
}

fn unit_scaling() -> f64 {
    1.0
}

fn unbounded_ratio() -> f64 {
    f64::INFINITY
}

fn default_element() -> String {
    ELEMENT_ONE_POINT.to_owned()
}

fn default_hourglass_kappa() -> f64 {
    granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA
}

/// The allowed `granule_type`s, for messages.
const GRANULE_TYPES: &str = "A1, A2, A3, B1 ... C3";
/// The allowed `element`s, for messages.
const ELEMENTS: &str = "one-point, fbar";

/// The scene's name of the one-point element.
pub const ELEMENT_ONE_POINT: &str = "one-point";
/// The scene's name of the F-bar element.
pub const ELEMENT_FBAR: &str = "fbar";

/// The scene's name of `kind` (the inverse of [`Scene::element_kind`]).
pub fn element_name(kind: ElementKind) -> &'static str {
    match kind {
        ElementKind::OnePoint => ELEMENT_ONE_POINT,
        ElementKind::FBar => ELEMENT_FBAR,
    }
}

fn default_time_step_safety() -> f64 {
    0.9
}

fn default_max_mass_factor() -> f64 {
    4.0
}

fn default_true() -> bool {
    true
}

fn default_watchdog_energy_ratio() -> f64 {
    2.0
}

fn default_watchdog_speed_ratio() -> f64 {
    2000.0
}

fn invalid(field: &'static str, value: impl Shown, allowed: &str) -> anyhow::Error {
    anyhow::Error::new(FieldError {
        field,
        value: value.shown(),
        allowed: allowed.to_owned(),
    })
}

impl Scene {
    /// The embedded published scene.
    pub fn published() -> Self {
        Self::from_toml(DEFAULT_SCENE).expect("the embedded scene parses")
    }

    /// Parses and validates a scene file's text.
    pub fn from_toml(text: &str) -> anyhow::Result<Self> {
        // One message: the parser's, with its line, column and excerpt (as
        // the cause under a context of its own it was printed twice).
        let mut scene: Scene = toml::from_str(text).map_err(|e| {
            let problems = refused_fields(text);
            // The parser's located message, unless it is a missing field's
            // (located at the file's first line); then every field the
            // scene's types refuse, with the allowed ranges the parser
            // does not know.
            let located = problems.is_empty() || !e.message().starts_with("missing field");
            let mut message = if located {
                format!("invalid scene: {}", e.to_string().trim_end())
            } else {
                "invalid scene".to_owned()
            };
            // The list, unless it would only say again the one refusal
            // the located message says.
            if !located || problems.len() > 1 || problems.iter().any(|p| p.1) {
                message.push_str("\nevery field refused, with what it allows:");
                for p in &problems {
                    message.push_str("\n  - ");
                    message.push_str(&p.0);
                }
            }
            anyhow::Error::new(InputError(message))
        })?;
        scene.validate()?;
        // The type as it is spelt everywhere else (`b2` → `B2`): the
        // outputs name it so, and `--types` finds the scene's type by it.
        scene.granule_type = scene.granule_type()?.name().to_owned();
        Ok(scene)
    }

    /// The scene as TOML (for `summary.json` and `--print-scene` of an
    /// overridden scene).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// Checks every field; an error names the field and its allowed range.
    pub fn validate(&self) -> anyhow::Result<()> {
        if self.version != SCENE_VERSION {
            bail!(invalid("version", self.version, "1"));
        }
        self.granule_type()?;
        self.mesh_level()?;
        self.element_kind()?;
        if let Some((_, field, value, allowed)) = self.range_checks().into_iter().find(|c| !c.0) {
            bail!(invalid(field, value, &allowed));
        }
        if let Some(c) = self
            .snapshot_strains
            .iter()
            .find(|c| !(0.0..=MAX_FINAL_STRAIN).contains(*c))
        {
            bail!(invalid("snapshot_strains", c, "each 0 <= C <= 0.9"));
        }
        // The pour's insertion lattice must stand at most as tall as `pack`
        // allows (a taller column, e.g. 100000 granules in the published
        // die, 1.5 m, poured for hours).
        let material = self.material()?;
        let fill = crate::bed::run::pour_params(self, &material).fill_height();
        if fill.is_nan() || fill > crate::pack::MAX_INSERTION_HEIGHT_M {
            let allowed = format!(
                "as many as stand at most {} m tall on the pour's insertion lattice in this die \
                 (these would stand {} m)",
                crate::pack::MAX_INSERTION_HEIGHT_M,
                fill.shown()
            );
            bail!(invalid("granules", self.granules, &allowed));
        }
        Ok(())
    }

    /// The numeric fields' range checks: (passes, field, value, the
    /// allowed range), in the order [`Scene::validate`] reports them.
    fn range_checks(&self) -> [(bool, &'static str, f64, String); 28] {
        let exact_sweep_tolerance = self.exact_sweep_tolerance();
        let d = self.diameter_mm;
        let die_range = format!(
            "more than 4 and at most {} granule diameters: {} < D <= {} mm for granules of \
             diameter_mm = {}",
            MAX_DIE_DIAMETERS.shown(),
            (4.0 * d).shown(),
            (MAX_DIE_DIAMETERS * d).shown(),
            d.shown()
        );
        [
            (
                self.sweep_tolerance > 0.0 && self.sweep_tolerance <= 0.1,
                "sweep_tolerance",
                self.sweep_tolerance,
                "0 < t <= 0.1".to_owned(),
            ),
            (
                exact_sweep_tolerance > 0.0 && exact_sweep_tolerance <= 0.1,
                "exact_sweep_tolerance",
                exact_sweep_tolerance,
                "0 < t <= 0.1".to_owned(),
            ),
            (
                (0.0..=1.0).contains(&self.face_list_skin),
                "face_list_skin",
                self.face_list_skin,
                "0 <= s <= 1 (0: no face lists)".to_owned(),
            ),
            (
                (0.0..=1.0).contains(&self.hourglass_kappa),
                "hourglass_kappa",
                self.hourglass_kappa,
                "0 <= kappa <= 1".to_owned(),
            ),
            (
                // Above 1 only to provoke an instability on purpose; the
                // kernel's estimate takes up to MAX_SAFETY (2).
                self.time_step_safety > 0.0
                    && self.time_step_safety <= granbed_kernel::granule::timestep::MAX_SAFETY,
                "time_step_safety",
                self.time_step_safety,
                "0 < C <= 2".to_owned(),
            ),
            (
                (1.0..=1e9).contains(&self.watchdog_energy_ratio),
                "watchdog_energy_ratio",
                self.watchdog_energy_ratio,
                "1 <= r <= 1e9".to_owned(),
            ),
            (
                (1.0..=1e9).contains(&self.watchdog_speed_ratio),
                "watchdog_speed_ratio",
                self.watchdog_speed_ratio,
                "1 <= r <= 1e9".to_owned(),
            ),
            (
                (1.0..=1e6).contains(&self.mass_scaling),
                "mass_scaling",
                self.mass_scaling,
                "1 <= F <= 1e6".to_owned(),
            ),
            (
                self.selective_mass_ratio >= 1.0,
                "selective_mass_ratio",
                self.selective_mass_ratio,
                ">= 1 (inf: physical rigid modes)".to_owned(),
            ),
            (
                (0.0..=1.0).contains(&self.time_step_floor),
                "time_step_floor",
                self.time_step_floor,
                "0 <= r <= 1 (0: off)".to_owned(),
            ),
            (
                (1.0..=1e6).contains(&self.max_mass_factor),
                "max_mass_factor",
                self.max_mass_factor,
                "1 <= k <= 1e6".to_owned(),
            ),
            (
                self.checkpoint_interval_minutes > 0.0,
                "checkpoint_interval_minutes",
                self.checkpoint_interval_minutes,
                "> 0".to_owned(),
            ),
            (
                self.checkpoint_strain_interval >= MIN_STRAIN_INTERVAL,
                "checkpoint_strain_interval",
                self.checkpoint_strain_interval,
                ">= 1e-6".to_owned(),
            ),
            (
                (1..=MAX_GRANULES).contains(&self.granules),
                "granules",
                self.granules as f64,
                "1..=100000".to_owned(),
            ),
            (
                self.diameter_mm >= MIN_DIAMETER_MM && self.diameter_mm < 2000.0,
                "diameter_mm",
                self.diameter_mm,
                "0.001 <= d < 2000".to_owned(),
            ),
            (
                self.die_diameter_mm > 4.0 * self.diameter_mm
                    && self.die_diameter_mm <= MAX_DIE_DIAMETERS * self.diameter_mm,
                "die_diameter_mm",
                self.die_diameter_mm,
                die_range,
            ),
            (
                (MIN_PUNCH_SPEED_M_S..=MAX_PUNCH_SPEED_M_S).contains(&self.punch_speed_m_s),
                "punch_speed_m_s",
                self.punch_speed_m_s,
                "1e-4 <= v <= 10 m/s (10: the platen speed limit of `granbed-cli granule`)"
                    .to_owned(),
            ),
            (
                self.final_strain > 0.0 && self.final_strain <= MAX_FINAL_STRAIN,
                "final_strain",
                self.final_strain,
                "0 < C <= 0.9".to_owned(),
            ),
            (
                (0.0..=MAX_FINAL_STRAIN).contains(&self.kawakita_min_strain),
                "kawakita_min_strain",
                self.kawakita_min_strain,
                "0 <= C <= 0.9".to_owned(),
            ),
            (
                (0.0..=MAX_FINAL_STRAIN).contains(&self.heckel_min_strain),
                "heckel_min_strain",
                self.heckel_min_strain,
                "0 <= C <= 0.9".to_owned(),
            ),
            (
                self.output_strain_interval >= MIN_STRAIN_INTERVAL
                    && self.output_strain_interval <= self.final_strain,
                "output_strain_interval",
                self.output_strain_interval,
                "1e-6 <= interval <= final_strain".to_owned(),
            ),
            (
                (0.0..=2.0).contains(&self.damping_ratio),
                "damping_ratio",
                self.damping_ratio,
                "0 <= xi <= 2".to_owned(),
            ),
            (
                (1..=MAX_CONTACT_SEARCH_INTERVAL).contains(&self.contact_search_interval),
                "contact_search_interval",
                f64::from(self.contact_search_interval),
                "1..=10".to_owned(),
            ),
            (
                (0.0..=0.1).contains(&self.contact_capture),
                "contact_capture",
                self.contact_capture,
                "0 <= c <= 0.1".to_owned(),
            ),
            (
                (self.held_reprojection > 0.0 && self.held_reprojection <= 1.0)
                    || self.held_reprojection == f64::INFINITY,
                "held_reprojection",
                self.held_reprojection,
                "0 < s <= 1, or inf (never)".to_owned(),
            ),
            (
                (0.0..=1.0).contains(&self.exact_contact_from_strain),
                "exact_contact_from_strain",
                self.exact_contact_from_strain,
                "0 <= C <= 1 (1: never)".to_owned(),
            ),
            (
                self.contact_search_interval == 1 || self.hold_constraints,
                "contact_search_interval",
                f64::from(self.contact_search_interval),
                "1 unless hold_constraints = true".to_owned(),
            ),
            (
                (1..=50).contains(&self.contact_sweeps),
                "contact_sweeps",
                f64::from(self.contact_sweeps),
                "1..=50".to_owned(),
            ),
        ]
    }

    /// The granule type.
    pub fn granule_type(&self) -> anyhow::Result<GranuleType> {
        self.granule_type
            .parse()
            .map_err(|_| invalid("granule_type", &self.granule_type, GRANULE_TYPES))
    }

    /// The element formulation.
    pub fn element_kind(&self) -> anyhow::Result<ElementKind> {
        match self.element.as_str() {
            ELEMENT_ONE_POINT => Ok(ElementKind::OnePoint),
            ELEMENT_FBAR => Ok(ElementKind::FBar),
            other => Err(invalid("element", other, ELEMENTS)),
        }
    }

    /// The mesh level.
    pub fn mesh_level(&self) -> anyhow::Result<MeshLevel> {
        self.mesh
            .parse()
            .map_err(|m: String| invalid("mesh", &self.mesh, &m))
    }

    /// The granules' radius, m.
    pub fn radius_m(&self) -> f64 {
        0.5e-3 * self.diameter_mm
    }

    /// The reference mesh of every granule (the whole sphere).
    pub fn granule_mesh(&self) -> anyhow::Result<OwnedReference> {
        Ok(OwnedReference::sphere(
            self.radius_m(),
            self.mesh_level()?,
            false,
        )?)
    }

    /// The element loop's settings: the element, the default constitutive
    /// switches and the hourglass coefficient.
    pub fn element_settings(&self) -> anyhow::Result<ElementSettings> {
        Ok(ElementSettings {
            kind: self.element_kind()?,
            update: Default::default(),
            hourglass_kappa: self.hourglass_kappa,
        })
    }

    /// The type's preset with the overrides (not validated).
    pub fn material_params(&self) -> anyhow::Result<MaterialParams> {
        let o = self.material;
        Ok(crate::material_args::MaterialArgs {
            granule_type: self.granule_type()?,
            youngs_modulus_pa: o.youngs_modulus_pa,
            poisson_ratio: o.poisson_ratio,
            yield_stress_pa: o.yield_stress_pa,
            eta0: o.eta0,
            cp: o.cp,
            eta_c: o.eta_c,
            true_density_kg_m3: o.true_density_kg_m3,
            friction: o.friction,
        }
        .params())
    }

    /// The validated material; a rejection names `material.<field>`, every
    /// refused one on a line of its own.
    pub fn material(&self) -> anyhow::Result<Material> {
        let p = self.material_params()?;
        p.validate().map_err(|first| {
            crate::material_args::every_refusal(&p, first, |e| {
                anyhow::Error::new(InputError(format!(
                    "scene field `material.{}` = {} is out of range (allowed: {}){}",
                    e.field,
                    e.value,
                    e.allowed,
                    crate::material_args::related_field(e.field, &p, false)
                )))
            })
        })
    }

    /// Reads a scene file: parsed and validated, and its snapshot strains
    /// within its final strain (a snapshot beyond it would never be
    /// written).
    pub fn read(path: &std::path::Path) -> anyhow::Result<Self> {
        let scene = Self::read_with_notes(path)?.0;
        scene
            .check_snapshots()
            .with_context(|| format!("scene `{}`", path.display()))?;
        Ok(scene)
    }

    /// [`Scene::read`] without the test of its snapshot strains against its
    /// final strain (`bed` makes it after its overrides), with the
    /// warnings about the file: the fields it
    /// omits whose value then differs from the published scene's
    /// ([`Scene::omitted_fields`]).
    pub fn read_with_notes(path: &std::path::Path) -> anyhow::Result<(Self, Vec<String>)> {
        // A scene that cannot be read is the user's to fix: a usage error.
        let text = std::fs::read_to_string(path).map_err(|e| {
            crate::error::input_error(format!("cannot read scene `{}`: {e}", path.display()))
        })?;
        // Its snapshot strains are checked against the final strain after
        // the command's overrides (`--strain` may move the end past them).
        let scene =
            Self::from_toml(&text).with_context(|| format!("scene `{}`", path.display()))?;
        let omitted = scene.omitted_fields(&text);
        let notes = if omitted.is_empty() {
            Vec::new()
        } else {
            vec![format!(
                "scene `{}` omits {}, which then take the values of scene files from before \
                 those fields existed, not the published scene's: {} (`granbed-cli bed --scene \
                 FILE --print-scene` prints every value; add the fields to choose)",
                path.display(),
                omitted
                    .iter()
                    .map(|o| o.field.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
                omitted
                    .iter()
                    .map(|o| format!("{} = {} (published {})", o.field, o.value, o.published))
                    .collect::<Vec<_>>()
                    .join(", ")
            )]
        };
        Ok((scene, notes))
    }

    /// The sweep tolerance from `exact_contact_from_strain` on, of the
    /// element size: `exact_sweep_tolerance`, or `sweep_tolerance` where
    /// the scene has none.
    pub fn exact_sweep_tolerance(&self) -> f64 {
        self.exact_sweep_tolerance.unwrap_or(self.sweep_tolerance)
    }

    /// Rejects snapshot strains beyond the final strain, naming the field.
    pub fn check_snapshots(&self) -> anyhow::Result<()> {
        if let Some(c) = self
            .snapshot_strains
            .iter()
            .find(|&&c| c > self.final_strain)
        {
            bail!(invalid(
                "snapshot_strains",
                c,
                &format!("each 0 <= C <= final_strain = {}", self.final_strain)
            ));
        }
        Ok(())
    }

    /// The fields that the scene file `text` (which parsed to `self`)
    /// leaves out and whose value then differs from the published scene's:
    /// the numerics fields added after the format, whose absent values
    /// keep the older files' runs as they were (`[material]` is not
    /// listed: absent, the type's preset applies).
    pub fn omitted_fields(&self, text: &str) -> Vec<OmittedField> {
        let (Ok(given), Ok(published), Ok(toml::Value::Table(mut own))) = (
            toml::from_str::<toml::Table>(text),
            toml::from_str::<toml::Table>(DEFAULT_SCENE),
            toml::Value::try_from(self),
        ) else {
            return Vec::new();
        };
        // An absent exact_sweep_tolerance is not written; its value is
        // sweep_tolerance's.
        own.entry("exact_sweep_tolerance")
            .or_insert(toml::Value::Float(self.exact_sweep_tolerance()));
        published
            .iter()
            .filter(|(field, _)| field.as_str() != "material" && !given.contains_key(*field))
            .filter_map(|(field, published)| {
                let value = own.get(field)?;
                (value != published).then(|| OmittedField {
                    field: field.clone(),
                    value: value.to_string(),
                    published: published.to_string(),
                })
            })
            .collect()
    }
}

/// What the scene's types refuse in the scene file `text`, every field at
/// once, with its allowed range where one is known: serde stops at the
/// first wrong or missing field and names only its Rust type ("expected
/// usize"). Each field of the file is put alone into the published scene
/// (a `[material]` field alone into its table), which is then read: a
/// field so refused has the wrong type or is unknown. A field of the
/// published scene that the file leaves out is required if the published
/// scene without it is refused. Each refusal is said with whether it
/// states an allowed range. Empty if `text` is not TOML.
fn refused_fields(text: &str) -> Vec<(String, bool)> {
    let (Ok(given), Ok(published)) = (
        toml::from_str::<toml::Table>(text),
        toml::from_str::<toml::Table>(DEFAULT_SCENE),
    ) else {
        return Vec::new();
    };
    let refusal = |table: toml::Table| {
        toml::Value::Table(table)
            .try_into::<Scene>()
            .err()
            .map(|e| e.message().to_owned())
    };
    let mut problems = Vec::new();
    let mut try_field = |name: String, value: &toml::Value, table: toml::Table| {
        if let Some(why) = refusal(table) {
            let allowed = allowed_range(&name);
            let ranged = allowed.is_some();
            let allowed = allowed.map_or(String::new(), |a| format!("; allowed: {a}"));
            problems.push((
                format!("`{name}` = {value}: {}{allowed}", plain_types(&why)),
                ranged,
            ));
        }
    };
    for (field, value) in &given {
        match (value, published.get(field)) {
            (toml::Value::Table(own), Some(toml::Value::Table(base))) => {
                for (inner, v) in own {
                    let mut table = published.clone();
                    let mut sub = base.clone();
                    sub.insert(inner.clone(), v.clone());
                    table.insert(field.clone(), toml::Value::Table(sub));
                    try_field(format!("{field}.{inner}"), v, table);
                }
            }
            _ => {
                let mut table = published.clone();
                table.insert(field.clone(), value.clone());
                try_field(field.clone(), value, table);
            }
        }
    }
    for field in published.keys().filter(|f| !given.contains_key(*f)) {
        let mut table = published.clone();
        table.remove(field);
        if refusal(table).is_some() {
            let allowed = allowed_range(field).map_or(String::new(), |a| format!(" ({a})"));
            problems.push((
                format!("`{field}` is missing: it is required{allowed}"),
                true,
            ));
        }
    }
    problems
}

/// The allowed values of a scene field, as [`Scene::validate`] states
/// them (a range that depends on another field is stated for the
/// published scene's), a `material.` field's as the material's validation
/// states it, or `None`.
fn allowed_range(field: &str) -> Option<String> {
    if let Some(inner) = field.strip_prefix("material.") {
        // The published scene with this one override NaN, which every
        // range refuses: the refusal names its range.
        let mut table = toml::Table::new();
        table.insert(inner.to_owned(), toml::Value::Float(f64::NAN));
        let material: MaterialOverrides = toml::Value::Table(table).try_into().ok()?;
        let scene = Scene {
            material,
            ..Scene::published()
        };
        let e = scene.material_params().ok()?.validate().err()?;
        return (e.field == inner).then(|| e.allowed.to_owned());
    }
    match field {
        "granule_type" => Some(GRANULE_TYPES.to_owned()),
        "element" => Some(ELEMENTS.to_owned()),
        "mesh" => Some("a level NxM such as \"8x2\"".to_owned()),
        _ => Scene::published()
            .range_checks()
            .into_iter()
            .find(|c| c.1 == field)
            .map(|c| c.3),
    }
}

/// Serde's refusal of a value in a user's words: what was expected (the
/// value itself is shown beside it), without the names of Rust types.
fn plain_types(message: &str) -> String {
    let expected = match message.split_once(", expected ") {
        Some((_, what)) if message.starts_with("invalid ") => format!("expected {what}"),
        _ => message.to_owned(),
    };
    [
        ("expected usize", "expected a whole number >= 0"),
        (
            "expected u32",
            "expected a whole number from 0 to 4294967295",
        ),
        ("expected u64", "expected a whole number >= 0"),
        ("expected f64", "expected a number"),
        (
            "expected struct MaterialOverrides",
            "expected a table [material]",
        ),
        ("expected a sequence", "expected a list [...]"),
    ]
    .iter()
    .fold(expected, |m, (rust, plain)| m.replace(rust, plain))
}

/// A field a scene file omits whose value then differs from the published
/// scene's ([`Scene::omitted_fields`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OmittedField {
    /// The field's name.
    pub field: String,
    /// The value the scene runs with (TOML).
    pub value: String,
    /// The published scene's value (TOML).
    pub published: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene the TOML parser refuses is an input error whose message —
    /// the whole chain, as the CLI prints it — holds the parser's text,
    /// with its line and excerpt, once (it was printed twice: as a context
    /// and again as its cause).
    #[test]
    fn a_scene_parse_error_is_said_once() {
        let e = Scene::from_toml("version = 1\ngranuels = 30\n").unwrap_err();
        assert!(e.downcast_ref::<InputError>().is_some(), "{e:#}");
        let text = format!("{e:#}");
        assert!(
            text.starts_with("invalid scene: TOML parse error at line 2"),
            "{text}"
        );
        // Once located, and once more in the list of every refusal (the
        // file lacks the required fields too).
        let (located, list) = text
            .split_once("\nevery field refused")
            .unwrap_or_else(|| panic!("no list:\n{text}"));
        for part in [located, list] {
            assert_eq!(
                part.matches("unknown field `granuels`").count(),
                1,
                "{text}"
            );
        }
        // A file whose one refusal the located message says has no list.
        let text = format!(
            "{:#}",
            Scene::from_toml(&format!("{DEFAULT_SCENE}\nx = 1\n")).unwrap_err()
        );
        assert_eq!(text.matches("unknown field `x`").count(), 1, "{text}");
    }

    /// A scene file with several fields of the wrong type or missing is
    /// refused with every one of them named, and its allowed range where
    /// the validation states one; serde alone named the first and its
    /// Rust type ("expected usize").
    #[test]
    fn every_refused_field_is_named_with_its_range() {
        let text = DEFAULT_SCENE
            .lines()
            .filter(|l| !l.starts_with("seed =") && !l.starts_with("mesh ="))
            .map(|l| match l.split_once(" = ") {
                Some(("granules", _)) => "granules = -5".to_owned(),
                Some(("contact_sweeps", _)) => "contact_sweeps = 99999999999".to_owned(),
                Some(("friction", _)) => "friction = \"high\"".to_owned(),
                _ => l.to_owned(),
            })
            .collect::<Vec<_>>()
            .join("\n");
        let e = Scene::from_toml(&text).unwrap_err();
        assert!(e.downcast_ref::<InputError>().is_some(), "{e:#}");
        let text = format!("{e:#}");
        for line in [
            "  - `granules` = -5: expected a whole number >= 0; allowed: 1..=100000",
            "  - `contact_sweeps` = 99999999999: expected a whole number from 0 to 4294967295; \
             allowed: 1..=50",
            "  - `material.friction` = \"high\": expected a number; allowed: 0 <= mu <= 10",
            "  - `seed` is missing: it is required",
            "  - `mesh` is missing: it is required (a level NxM such as \"8x2\")",
        ] {
            assert!(text.lines().any(|l| l == line), "{line:?} not in\n{text}");
        }
        // Only missing fields: no excerpt of the file's first line.
        let only_missing = DEFAULT_SCENE.replace("\nseed =", "\n# seed =");
        let text = format!("{:#}", Scene::from_toml(&only_missing).unwrap_err());
        assert_eq!(
            text,
            "invalid scene\nevery field refused, with what it allows:\n  - `seed` is missing: \
             it is required"
        );
    }

    /// A scene file without the ratio has none (∞), and ∞ survives the
    /// TOML a checkpoint stores.
    #[test]
    fn an_unbounded_mass_ratio_round_trips() {
        let s = Scene {
            selective_mass_ratio: f64::INFINITY,
            ..Scene::published()
        };
        assert!(s.to_toml().contains("selective_mass_ratio = inf"));
        assert_eq!(Scene::from_toml(&s.to_toml()).unwrap(), s);
    }

    /// A type spelt in lower case is read as the type and named as the
    /// outputs name it.
    #[test]
    fn a_lower_case_type_reads_as_the_type() {
        let text = Scene::published()
            .to_toml()
            .replace("granule_type = \"B2\"", "granule_type = \"c1\"");
        assert!(text.contains("\"c1\""));
        let s = Scene::from_toml(&text).unwrap();
        assert_eq!(s.granule_type, "C1");
        assert_eq!(s.granule_type().unwrap(), GranuleType::C1);
    }

    #[test]
    fn the_embedded_scene_is_the_published_one() {
        let s = Scene::published();
        assert_eq!(s.granules, 1000);
        assert_eq!(s.granule_type().unwrap(), GranuleType::B2);
        assert_eq!(s.mesh_level().unwrap(), MeshLevel::STANDARD);
        assert_eq!(s.die_diameter_mm, 11.3);
        assert_eq!(s.punch_speed_m_s, 0.05);
        assert_eq!(s.final_strain, 0.3);
        let m = s.material().unwrap();
        assert_eq!(m.params.yield_stress_pa, 30e3);
        assert_eq!(m.params.eta0, 0.8);
        // Selective mass scaling x20 with the contact-sweep tolerance 0.01
        // (BENCHMARKS.md, "Selective x20 and sweep tolerance 0.01 become
        // the bed's default"), the rigid modes physical up to F = 10 and
        // F/10 times heavier beyond ("Selective x30 with heavier rigid
        // modes"), later sweeps on the held constraints ("Later sweeps
        // re-measure the held constraints"), a contact search every fifth
        // step with a capture distance of 0.1 element ("A contact search
        // every k-th step").
        assert_eq!(
            (
                s.mass_scaling,
                s.selective_mass_scaling,
                s.selective_mass_ratio,
                s.sweep_tolerance,
                s.hold_constraints,
                s.contact_search_interval
            ),
            (20.0, true, 10.0, 0.01, true, 5)
        );
        assert_eq!(s.contact_capture, 0.1);
        // Beyond 30 % every contact sweep searches (BENCHMARKS.md, "The
        // 30-granule suite at 60 %"); a scene file without the field never
        // switches.
        assert_eq!(s.exact_contact_from_strain, 0.3);
        let old = DEFAULT_SCENE.replace("exact_contact_from_strain = 0.3\n", "");
        assert_eq!(
            Scene::from_toml(&old).unwrap().exact_contact_from_strain,
            1.0
        );
        // The TOML written back parses to the same scene.
        assert_eq!(Scene::from_toml(&s.to_toml()).unwrap(), s);
    }

    #[test]
    fn bad_scenes_name_the_field() {
        let bad = |from: &str, to: &str| {
            let text = DEFAULT_SCENE.replace(from, to);
            format!("{:#}", Scene::from_toml(&text).unwrap_err())
        };
        assert!(bad("granules = 1000", "granules = 0").contains("`granules`"));
        assert!(bad("version = 1", "version = 2").contains("`version`"));
        assert!(bad("mesh = \"8x2\"", "mesh = \"3x1\"").contains("`mesh`"));
        assert!(bad("friction = 0.1", "friction = -1").contains("material.friction"));
        // Two bad material values: both named, a line each.
        let two = bad("friction = 0.1", "friction = -1\npoisson_ratio = 0.5");
        assert_eq!(two.lines().count(), 2, "{two}");
        assert!(two.contains("`material.poisson_ratio` = 0.5"), "{two}");
        assert!(two.contains("`material.friction` = -1"), "{two}");
        assert!(bad("seed = 1", "seed = 1\ncolour = 3").contains("colour"));
        // A die a million granule diameters wide ran the pour out of
        // memory; intervals below the strain's round-off never ended.
        let e = bad("die_diameter_mm = 11.3", "die_diameter_mm = 1e6");
        assert!(
            e.contains("`die_diameter_mm`") && e.contains("at most 1000"),
            "{e}"
        );
        assert!(
            Scene::from_toml(
                &DEFAULT_SCENE.replace("die_diameter_mm = 11.3", "die_diameter_mm = 1000")
            )
            .is_ok()
        );
        for (from, to, field) in [
            (
                "output_strain_interval = 0.005",
                "output_strain_interval = 1e-12",
                "`output_strain_interval`",
            ),
            (
                "checkpoint_strain_interval = 0.05",
                "checkpoint_strain_interval = 1e-20",
                "`checkpoint_strain_interval`",
            ),
        ] {
            let e = bad(from, to);
            assert!(e.contains(field) && e.contains("1e-6"), "{e}");
        }
        // A granule so small that its pour would never end (the die kept at
        // ten diameters, inside its own range).
        let tiny = DEFAULT_SCENE
            .replace("diameter_mm = 1.0", "diameter_mm = 1e-60")
            .replace("die_diameter_mm = 11.3", "die_diameter_mm = 1e-59");
        let e = format!("{:#}", Scene::from_toml(&tiny).unwrap_err());
        assert!(
            e.contains("`diameter_mm`") && e.contains("0.001 <= d < 2000"),
            "{e}"
        );
        let e = bad(
            "exact_sweep_tolerance = 0.005",
            "exact_sweep_tolerance = 0.5",
        );
        assert!(
            e.contains("`exact_sweep_tolerance`") && e.contains("0 < t <= 0.1"),
            "{e}"
        );
        assert!(bad("final_strain = 0.3", "final_strain = 1.5").contains("`final_strain`"));
        for k in ["0", "11"] {
            let line = format!("contact_search_interval = {k}");
            let e = bad("contact_search_interval = 5", &line);
            assert!(
                e.contains("`contact_search_interval`") && e.contains("1..=10"),
                "{e}"
            );
        }
        // The steps between searches hold constraints: not without holding.
        let text = DEFAULT_SCENE.replace("hold_constraints = true", "hold_constraints = false");
        let e = format!("{:#}", Scene::from_toml(&text).unwrap_err());
        assert!(
            e.contains("`contact_search_interval`") && e.contains("hold_constraints"),
            "{e}"
        );
        let e = bad("contact_capture = 0.1", "contact_capture = 0.2");
        assert!(
            e.contains("`contact_capture`") && e.contains("0 <= c <= 0.1"),
            "{e}"
        );
        // A scene file without the fields searches every step and holds
        // only overlapping nodes.
        let text = DEFAULT_SCENE
            .replace("contact_search_interval = 5\n", "")
            .replace("contact_capture = 0.1\n", "");
        let old = Scene::from_toml(&text).unwrap();
        assert_eq!((old.contact_search_interval, old.contact_capture), (1, 0.0));
        // Held contacts re-projected after a slide of 0.05 element
        // (BENCHMARKS.md, "Held contacts projected afresh"); a scene file
        // without the field never re-projects, and ∞ is allowed.
        assert_eq!(Scene::published().held_reprojection, 0.05);
        let text = DEFAULT_SCENE.replace("held_reprojection = 0.05\n", "");
        assert_eq!(
            Scene::from_toml(&text).unwrap().held_reprojection,
            f64::INFINITY
        );
        let text = DEFAULT_SCENE.replace("held_reprojection = 0.05", "held_reprojection = inf");
        assert!(Scene::from_toml(&text).is_ok());
        // Penetrating nodes held against the nearest face whatever their
        // normal; a scene file without the field keeps physics.md's test.
        assert!(Scene::published().nearest_penetrated_face);
        let text = DEFAULT_SCENE.replace("nearest_penetrated_face = true\n", "");
        assert!(!Scene::from_toml(&text).unwrap().nearest_penetrated_face);
        // Past the exact-contact strain a tighter sweep tolerance; a scene
        // file without the field keeps its sweep_tolerance there too.
        assert_eq!(Scene::published().exact_sweep_tolerance(), 0.005);
        let text = DEFAULT_SCENE.replace("exact_sweep_tolerance = 0.005\n", "");
        assert_eq!(
            Scene::from_toml(&text).unwrap().exact_sweep_tolerance(),
            0.01
        );
        for wrong in ["0.0", "1.5", "-inf", "nan"] {
            let e = bad(
                "held_reprojection = 0.05",
                &format!("held_reprojection = {wrong}"),
            );
            assert!(
                e.contains("`held_reprojection`") && e.contains("0 < s <= 1, or inf"),
                "{e}"
            );
        }
    }
}
