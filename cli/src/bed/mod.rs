//! `granbed-cli bed`: the main job. Pour a bed of spheres (as `pack`),
//! turn every sphere into a finite-element granule, press the upper punch
//! down to the final strain and write the compression profile and a
//! summary with the Kawakita fit.
//!
//! * [`scene`]: the TOML scene format and the embedded published scene;
//! * [`run`](mod@run): the run itself, sampled every output interval;
//! * [`outputs`]: `compression.csv` and `summary.json`;
//! * [`snapshots`]: the VTU snapshots (`vtk/`) and, by [`section`], their
//!   section pictures; [`plots`]: the SVG plots (`plots/`), [`report`]:
//!   `report.html`;
//! * [`compare`]: `--types`, several granule types from one pour; [`seeds`]:
//!   `--seeds`; [`series`]: either kept resumable as a whole;
//!   [`series_report`]: the series' `report.html`.

use std::path::PathBuf;

use anyhow::Context as _;
use clap::Args;
use granbed_kernel::material::GranuleType;

use crate::granule::{ElementArg, TypeList};
use crate::model::MeshLevel;
use crate::output::Streams;

/// The rate check's run at half the punch speed, under the output
/// directory.
pub const HALF_SPEED_DIR: &str = "half_speed";

pub mod checkpoint;
pub mod compare;
pub mod density_map;
pub mod network;
pub mod outputs;
pub mod plots;
pub mod report;
pub mod run;
pub mod scene;
pub mod section;
pub mod seeds;
pub mod series;
pub mod series_report;
pub mod snapshot_tables;
pub mod snapshots;
pub mod stress_profile;
pub mod unloading;

pub use scene::{DEFAULT_SCENE, Scene};

/// The output description shown at the end of `bed --help`.
const OUTPUT_HELP: &str = "\
Output, in --out DIR (created if missing):
  compression.csv  one row per output interval: time_s, strain (C = (H0 - H)/H0
                   at the row), mean_strain (the interval's mean C, to which
                   its averages belong); averaged over the interval: upper/lower
                   punch force and pressure, die-wall axial friction, die-wall
                   normal force and pressure, coordination number (granule
                   pairs, and with walls); at the row: mean granule relative density (arithmetic
                   mean of eta0 V0/V, and solid/total), bed_solid_fraction D
                   (granule solid volume / (die area x H0 (1 - C)); Heckel:
                   ln(1/(1 - D)) against the pressure), mean Heywood coefficient
                   (d_V and nominal d), min Jacobian, steps, energies
  unloading.csv    (scene unload, on in the published scene) the same columns
                   while the upper punch withdraws after the final strain at
                   the punch speed, a row every tenth of the output interval,
                   strain falling, until its force falls below 1 % of its
                   largest (lift-off; at most 0.15 of strain)
  summary.json     the scene (and scene_toml, exact: --scene reads it),
                   Kawakita fit (a, 1/b, R^2, points; over the rows
                   with mean_strain >= kawakita_min_strain, 0.25, each
                   pressure at its interval's mean strain), Heckel fit of
                   ln(1/(1 - D)) = K P + A (yield pressure P_y = 1/K, A,
                   D_A = 1 - exp(-A), D_B = D_A - D0, R^2, points;
                   C >= heckel_min_strain, 0.25), the Kawakita fit again
                   over C >= 0.10, 0.15, 0.20
                   and 0.25 (kawakita_windows) and the Heckel fit likewise
                   (heckel_windows), the Heckel fit on the mean punch
                   pressure (heckel_mean_pressure), the granules' packing
                   fraction at the start and the end (their envelope volume /
                   die volume), the strains the certificate judged
                   (quasi_static_strains), the granules' mean
                   relative density in five layers of the compact at the end
                   (final_density_by_height), the poured bed's solid fraction
                   D0 and the final D in the die, the die wall at the end
                   (final_die_wall: radial pressure, radial-to-axial stress
                   ratio, mobilised friction |F_z|/F_n), the contact network
                   at each snapshot (contact_network, from vtk/network_<k>.csv),
                   the stress through the compact at each snapshot: the
                   elements' mean axial and lateral stress in ten layers
                   beside the walls' pressures and Janssen's share
                   (stress_by_height, from vtk/stress_<k>.csv), the
                   solid fraction and stresses in the compact's radial x
                   height section at the last snapshot, with its densest
                   and loosest cells and the top-to-bottom density ratios
                   at the wall and the axis (final_density_map, from
                   vtk/density_map_<k>.csv), the
                   withdrawal (unloading: lift-off strain, in-die elastic
                   recovery, residual die-wall and lower-punch pressure,
                   the punches' work, the work given back, net work and
                   plasticity factor net / punch work; with --rate-check the
                   recovery and plasticity factor of the cycle at half the
                   punch speed and their check, half_speed_*),
                   the material (every
                   parameter), final strain,
                   max pressure, initial bed height, counts, wall time, ns per
                   element-step, cost figures (over the whole run,
                   resumed segments included), threads, min Jacobian, max nodal
                   speed / punch speed, deepest overlap (m and / element size)
                   read by the contact detection and measured by geometry at
                   the end (final_hidden_overlap), hourglass / internal work,
                   energy residual, peak memory, the quasi-static certificate,
                   interrupted, warnings (also on stderr, with --quiet too: a
                   final strain past the target by more than an output
                   interval, overlap above 1 % of the element, an element
                   folded at a Gauss point (J <= 0), a Kawakita fit
                   with a outside (0, 1], 1/b <= 0 or R^2 < 0.9 (and a note
                   where a > 1 - D0), a Heckel fit with R^2 < 0.9, a failed
                   quasi-static certificate, a bed solid fraction D >= 1,
                   scene fields left out whose old values are not the
                   published ones, a withdrawal without lift-off or cut
                   short, an unloading whose rate check failed), version
  vtk/bed_<k>.vtu  VTU snapshots at the scene's snapshot_strains and of the
                   final state (a fresh run first removes those an earlier
                   run left): every granule's
                   surface quads (all hexes with --vtk-full-mesh), cell data
                   granule id, relative density eta0 V0/V, Heywood d_V S/V and d S/V
                   per granule; per element (a quad: the hex under it) the
                   Cauchy stress's pressure_pa (-tr/3), von_mises_pa and
                   axial_stress_pa (-sigma_zz), and element_relative_density
                   eta0/J
  vtk/bed.pvd      ParaView collection of the snapshots (timestep = strain)
  vtk/section_<k>.svg
                   each snapshot cut through the die axis (plane y = 0): the
                   cut hexes coloured by axial stress -sigma_zz, the granules'
                   outlines, the die wall and the punches
  vtk/contacts_<k>.csv
                   the snapshot's contact network: per granule pair in contact
                   in its step, the normal and friction forces, the force on
                   the first granule and the branch vector (none at C = 0,
                   before the first step)
  vtk/granules_<k>.csv
                   per granule: centre of mass, relative density, Heywood
                   coefficients and contacts (none at C = 0)
  vtk/network_<k>.csv
                   the contact network in figures: quantiles of f/<f>, the
                   strong pairs' shares, the fabric <n_z^2> by number, by
                   force, over the strong and the weak pairs, the pairs'
                   mobilised friction and those sliding, and the interior's
                   coordination number: the granules whose centres lie at
                   least a diameter from every wall (none at C = 0)
  vtk/stress_<k>.csv
                   the stress through the compact: per tenth of its height,
                   the elements' mean axial and lateral stress over the
                   layer and its solid fraction, with the punches' and the
                   die wall's pressures of the same step (none at C = 0)
  vtk/density_map_<k>.csv
                   the compact's radial x height section: in 5 rings of
                   equal width by 10 layers, each cell's solid fraction and
                   mean axial and lateral stress (at C = 0 too)
  plots/*.svg      pressure (and the curve back while the punch withdraws),
                   coordination number, relative density and Heywood
                   coefficient against strain; Kawakita plot P/C vs P and
                   Heckel plot ln(1/(1 - D)) vs P, each with its fit; the
                   compaction profile, the bed's solid fraction D vs P; Z vs
                   the granules' packing fraction;
                   the energy ledger vs strain; each granule's relative
                   density vs its height at the end; the die wall's
                   radial-to-axial stress ratio and mobilised friction vs
                   strain; the axial stress by height at each snapshot with
                   Janssen's curve; the density map (solid fraction and
                   axial stress by radius and height) at the last snapshot
  report.html      one page: the warnings (or that there are none), the key
                   results, the fits by window, the contact network, the
                   stress through the compact, the density map, the plots with
                   captions, the sections with their tables linked, the
                   summary table (rounded; hover a value for all its digits),
                   the tables' columns explained, and the scene
  checkpoint.bin   the state to continue from with --resume (every
                   checkpoint_interval_minutes and checkpoint_strain_interval,
                   and at the end)
  withdrawal.bin   a withdrawal in progress (every checkpoint_interval_minutes
                   and at an interrupt; removed when it is done)

`--resume DIR` on a finished run takes no step of the loading and writes its
outputs again: with --kawakita-min-strain or --heckel-min-strain it refits the
run, and its checkpoint keeps the new windows. Its withdrawal is kept unless
the scene changed what it would do; else (none in the checkpoint, or
--unload true on a run without one, as for checkpoints before format 10,
whose scenes read unload = false) the withdrawal runs from the finished state,
or goes on from withdrawal.bin where an interrupt stopped it.

A series (--types, --seeds) keeps DIR/series.json (its members, scene and,
for --types, its pour, exactly): `--resume DIR` on the series directory
continues every run from its checkpoint, starts the runs never started,
refits the finished ones (with the windows given) and writes DIR's tables
again; --resume DIR/<member> continues that run alone and leaves DIR's tables
as they were.

With --types, the files above go to DIR/<TYPE>/ per type (each resumable
alone with --resume DIR/<TYPE>), and DIR holds the comparison:
  comparison.csv   one row per type, in the order given: type, seed, yield
                   stress, eta0, Kawakita a, 1/b (Pa), R^2, points, kawakita_ok,
                   Heckel P_y (Pa), R^2, heckel_ok, D0, max pressure,
                   final strain, final pressure, final mean relative density,
                   final coordination number, in-die elastic recovery and
                   plasticity factor (NaN without a withdrawal's lift-off),
                   quasi_static_passed (1/0),
                   wall time; kawakita_ok / heckel_ok: 1 if the fit is a
                   material figure, 0 if absent or warned about (summary.json
                   says why)
  comparison.json  the same rows, the errors, and the type of the pour
  comparison_pressure.svg, comparison_density.svg, comparison_profile.svg
                   upper-punch pressure and mean relative density against
                   strain, and the compaction profile D against P (what
                   tells the types apart), one curve per type
  report.html      one page: the plots, a row per type linked to its report
                   (pressures in kPa, rejected fits marked), what to doubt
  series.json      the series (types, scene, the pour) for --resume DIR
With --seeds S1,S2,..., the scene is poured and compressed once per seed into
`DIR/seed_<S>/` (each resumable alone with --resume), and DIR holds the
run-to-run spread:
  seeds.csv        one row per seed, the columns of comparison.csv
  seeds_spread.csv per figure (Kawakita a and 1/b, Heckel P_y, D0, max and final
                   pressure, final relative density and Z, in-die elastic
                   recovery and plasticity factor): runs, left_out (no
                   fit, or a fit the run's summary warns about), mean, sample
                   standard deviation, min, max, spread = max - min
  seeds.json       both tables
  seeds_pressure.svg, seeds_density.svg, seeds_profile.svg
                   one curve per seed
  report.html      as for --types, with the spread as a second table
  series.json      the series (seeds, scene) for --resume DIR

All types start from ONE pour (as the published study compares the nine
types on one bed): the pour uses the sphere density of the scene's type if
it is listed, else of the first listed type; types with another eta0 (digit)
reuse that packing.

Without --scene the embedded published scene runs (print it with
--print-scene): 1000 B2 granules of 1 mm on the 8x2 mesh in an 11.3 mm die,
pressed to C = 0.3, about 19 minutes on 2 cores, and the upper punch's
withdrawal after it, about 3 more. The options marked
Override above change the scene's fields. A fresh run into a directory that
holds an unfinished run is refused (--resume continues it; --overwrite).

SIGINT (Ctrl-C) or SIGTERM: the run finishes its step, writes a checkpoint and
the outputs so far (summary.json \"interrupted\": true), prints how to resume and
exits with status 130 (during the pour, which has nothing to keep, it stops at
the pour's next rest check); a second signal quits at once.

Exit status: 0 success, 1 runtime failure (the run stopped early: the outputs
so far are written), 2 usage or validation error, 130 interrupted (resumable).";

/// Options of `granbed-cli bed`.
#[derive(Args, Debug, Clone, PartialEq)]
#[command(after_long_help = OUTPUT_HELP)]
pub struct BedArgs {
    /// Scene file (TOML, format version 1); default: the published scene.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,

    /// Print the scene (after the overrides) as TOML and exit.
    #[arg(long)]
    pub print_scene: bool,

    /// Output directory, created if missing.
    #[arg(long, value_name = "DIR", default_value = "out/bed")]
    pub out: PathBuf,

    /// Override: standard granule type A1…C3.
    #[arg(long = "type", value_name = "TYPE")]
    pub granule_type: Option<GranuleType>,

    /// Compress several granule types, one after the other (each on all
    /// the -j threads), from ONE pour: `all` (A1…C3) or a comma list such as
    /// `A2,B2,C2`. The pour uses the sphere density of the scene's type if
    /// listed, else of the first listed type. Writes `DIR/<TYPE>/` per type
    /// plus `DIR/comparison.csv`, `.json` and the `comparison_*.svg` plots.
    /// The scene's `[material]` overrides apply to every type: one that
    /// leaves two listed types the same material (the yield stress of
    /// types of one letter, η0 of one digit) is refused, one that replaces
    /// what they differ in is warned about.
    #[arg(long, value_name = "LIST", conflicts_with_all = ["granule_type", "resume", "stop_at_strain"])]
    pub types: Option<TypeList>,

    /// Pour and compress the scene once per seed, one after the other
    /// (each on all the -j threads), for the run-to-run spread: a comma list
    /// such as `1,2,3`. Writes `DIR/seed_<S>/` per seed (each resumable
    /// alone with --resume) plus `DIR/seeds.csv`, `seeds_spread.csv` (mean,
    /// standard deviation, min, max of the Kawakita, Heckel and final
    /// figures), `seeds.json` and the `seeds_*.svg` plots.
    #[arg(long, value_name = "LIST", conflicts_with_all = ["types", "seed", "resume", "stop_at_strain", "rate_check"])]
    pub seeds: Option<seeds::SeedList>,

    /// Override: number of granules (1 ≤ N ≤ 100000).
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(1, crate::bed::scene::MAX_GRANULES as u64))]
    pub granules: Option<usize>,

    /// Override: mesh level NxM (8x2 = 1280 hexes, 4x1 = 160). 4x1 is
    /// about 11 times faster (the bed study's rows, BENCHMARKS.md) but
    /// biased: its faceted granules hold 5 % less
    /// volume, and a bed's pressure at a given strain came 13–21 % lower
    /// at 30 % (Kawakita 1/b 19–46 %) than on 8x2 from the same pours
    /// (BENCHMARKS.md); compare beds on one mesh.
    #[arg(long, value_name = "NxM")]
    pub mesh: Option<MeshLevel>,

    /// Override: final axial strain (0 < C ≤ 0.9, at least the scene's
    /// output_strain_interval); the scene's snapshot strains beyond it are
    /// dropped. With --resume, a run already past it takes no step.
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub strain: Option<f64>,

    /// Override: seed of the pour and the rotations (a whole number
    /// 0 ≤ SEED < 2^64).
    #[arg(long, value_name = "SEED", allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u64>(0, u64::MAX))]
    pub seed: Option<u64>,

    /// Override: die diameter, mm (more than 4 granule diameters).
    #[arg(value_parser = crate::numbers::real, long, value_name = "MM", allow_negative_numbers = true)]
    pub die_diameter_mm: Option<f64>,

    /// Override: granule diameter, mm (0.001 ≤ d < 2000; the die must stay
    /// more than 4 granule diameters wide).
    #[arg(value_parser = crate::numbers::real, long, value_name = "MM", allow_negative_numbers = true)]
    pub diameter_mm: Option<f64>,

    /// Override: upper-punch speed, m/s (1e-4 ≤ v ≤ 10; published 0.05). A
    /// slower punch brings a run closer to quasi-static at the cost of
    /// proportionally more steps.
    #[arg(value_parser = crate::numbers::real, long, value_name = "M_S", allow_negative_numbers = true)]
    pub punch_speed_m_s: Option<f64>,

    /// Override: element formulation (one-point, or fbar for verification:
    /// about 8× the element cost).
    #[arg(long, value_enum, value_name = "KIND")]
    pub element: Option<ElementArg>,

    /// Override: hourglass coefficient κ of the one-point element
    /// (0 ≤ κ ≤ 1).
    #[arg(value_parser = crate::numbers::real, long, value_name = "KAPPA", allow_negative_numbers = true)]
    pub hourglass_kappa: Option<f64>,

    /// Override: after the final strain the upper punch withdraws at the
    /// same speed until it comes free of the bed, for the unloading curve
    /// and the in-die elastic recovery (true, the published scene's; scene
    /// files and checkpoints without the field read false), or the run ends
    /// at the final strain (false). Allowed with --resume: on a finished
    /// run, true runs the withdrawal if it has none, false drops it.
    #[arg(long, value_name = "BOOL")]
    pub unload: Option<bool>,

    /// Override: granules are rigid bodies, without element work, until
    /// their first contact (true, the default) or finite-element bodies
    /// from the start (false); the same motion up to round-off.
    #[arg(long, value_name = "BOOL")]
    pub rigid_until_touched: Option<bool>,

    /// Override: contact sweeps after the first search only near the pairs
    /// still deeper than the tolerance (true, the default) or every pair of
    /// a moved granule (false).
    #[arg(long, value_name = "BOOL")]
    pub local_sweeps: Option<bool>,

    /// Override: contact sweeps after the first re-measure the constraints
    /// the step's search found at their contact points (true, the
    /// published scene's) or search again (false). Allowed with --resume.
    #[arg(long, value_name = "BOOL")]
    pub hold_constraints: Option<bool>,

    /// Override: a further contact sweep runs while a granule–granule gap
    /// deeper than this fraction of the element size is left (0 < t ≤ 0.1;
    /// the published scene's is 0.01, 0.005 leaves half the overlap for a
    /// quarter more sweeps). Allowed with --resume.
    #[arg(value_parser = crate::numbers::real, long, value_name = "T", allow_negative_numbers = true)]
    pub sweep_tolerance: Option<f64>,

    /// Override: skin of the contact search's per-node face lists as a
    /// fraction of the mean surface-face diagonal (0 ≤ s ≤ 1, 0: none;
    /// default 0.05). Only the speed depends on it, so it may be given with
    /// --resume.
    #[arg(value_parser = crate::numbers::real, long, value_name = "S", allow_negative_numbers = true)]
    pub face_list_skin: Option<f64>,

    /// Override: the contact search runs every N steps (1..=10); the steps
    /// between re-measure the constraints it found and search only pairs
    /// new to the candidate list (with --contact-capture, nodes just in
    /// front of a face are held too). The published scene's is 5; 1
    /// searches every step. More than 1 needs --hold-constraints true.
    /// Allowed with --resume.
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u32>(1, u64::from(crate::assembly::MAX_CONTACT_SEARCH_INTERVAL)))]
    pub contact_search_interval: Option<u32>,

    /// Override: the contact search's capture distance as a fraction C of
    /// the element size (0 ≤ C ≤ 0.1; published 0.1): nodes this close in
    /// front of a face are held with the contacts, so that the steps
    /// between two searches (--contact-search-interval) see them close.
    /// Allowed with --resume.
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub contact_capture: Option<f64>,

    /// Override: where a pair re-measures the contacts it holds (later
    /// sweeps, and the steps between two searches), a held contact whose
    /// node has slid along its face by more than this fraction S of the
    /// element size is projected on the face afresh, and (with a capture
    /// distance) nodes just beside a face are watched (0 < S ≤ 1, or inf:
    /// neither; published 0.05). Allowed with --resume.
    #[arg(value_parser = crate::numbers::real, long, value_name = "S", allow_negative_numbers = true)]
    pub held_reprojection: Option<f64>,

    /// Override: a node behind faces it projects inside is held against
    /// the nearest of them whatever its own normal (true, published), or
    /// only against faces its normal opposes (false: physics.md's test,
    /// under which nodes at folds of a strongly compressed granule sank
    /// unseen). Allowed with --resume.
    #[arg(long, value_name = "BOOL")]
    pub nearest_penetrated_face: Option<bool>,

    /// Override: the sweep tolerance from the exact-contact strain
    /// (--exact-contact-from-strain) on, as a fraction of the element size
    /// (0 < t ≤ 0.1; published 0.005, scene files without the field:
    /// --sweep-tolerance's). Allowed with --resume.
    #[arg(value_parser = crate::numbers::real, long, value_name = "T", allow_negative_numbers = true)]
    pub exact_sweep_tolerance: Option<f64>,

    /// Override: from this axial strain on every contact sweep searches,
    /// as with --hold-constraints false --contact-search-interval 1
    /// (0 ≤ C ≤ 1, 1: never; published 0.3). Allowed with --resume.
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub exact_contact_from_strain: Option<f64>,

    /// Override: the Kawakita fit of summary.json takes the output rows
    /// with C ≥ this, C the mean strain of the row's output interval, to
    /// which its averaged pressure belongs (0 ≤ C ≤ 0.9; published 0.25,
    /// physics.md). Allowed
    /// with --resume: on a finished run it refits without a step.
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub kawakita_min_strain: Option<f64>,

    /// Override: the Heckel fit of summary.json (ln(1/(1 - D)) against P)
    /// takes the output rows with C ≥ this, C the row's interval mean
    /// strain, as for --kawakita-min-strain (0 ≤ C ≤ 0.9; published 0.25).
    /// Allowed with --resume: on a finished run it refits without a step.
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub heckel_min_strain: Option<f64>,

    /// Continue the run whose checkpoint is in DIR (its `checkpoint.bin`),
    /// or the series of --types or --seeds in DIR (its `series.json`: every
    /// run continued or started, the tables written again; --stop-at-strain
    /// and --rate-check are refused there); the outputs go to DIR. Only
    /// --strain, --stop-at-strain, --time-step-safety, --mass-scaling, --sweep-tolerance,
    /// --hold-constraints, --contact-search-interval, --contact-capture,
    /// --held-reprojection, --nearest-penetrated-face,
    /// --exact-sweep-tolerance,
    /// --exact-contact-from-strain, --face-list-skin,
    /// --time-step-floor, --max-mass-factor, --unload, --kawakita-min-strain,
    /// --heckel-min-strain, -j and --quiet may be given with it.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "out", "granule_type", "granules", "mesh", "seed", "die_diameter_mm", "diameter_mm", "punch_speed_m_s", "element", "hourglass_kappa", "rigid_until_touched", "local_sweeps", "selective_mass_scaling", "selective_mass_ratio"])]
    pub resume: Option<PathBuf>,

    /// Write a checkpoint and stop once the strain reaches C (continue
    /// later with --resume; 0 < C ≤ the final strain).
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub stop_at_strain: Option<f64>,

    /// Override: mass scaling F ≥ 1 for quasi-static runs (the stable step
    /// grows by √F; check the quasi-static certificate in summary.json).
    /// The published scene's is 20, selective (the rigid modes ×2, see
    /// --selective-mass-ratio); 1 gives physical masses; 10 takes 40 % more
    /// steps than 20, 30 a fifth fewer (and fails the certificate narrowly
    /// on the published scene; 1 ≤ F ≤ 1e6).
    #[arg(value_parser = crate::numbers::real, long, value_name = "F", allow_negative_numbers = true)]
    pub mass_scaling: Option<f64>,

    /// Override: the mass scaling acts on the granules' deformational modes,
    /// their translation and spin keep the physical inertia up to the ratio
    /// limit --selective-mass-ratio (true, the published scene's), or on
    /// every mode (false).
    #[arg(long, value_name = "BOOL")]
    pub selective_mass_scaling: Option<bool>,

    /// Override: with selective mass scaling, the largest ratio R ≥ 1 of
    /// the deformational modes' scaling F to the rigid modes' G: the
    /// granules' translation and spin carry G = max(1, F/R) × their physical
    /// inertia (the published scene's R is 10; inf: G = 1 for any F). Above
    /// 10 the contacts of a granule pressed on a punch can inject energy (the
    /// summary's contact loss and certificate show it).
    #[arg(value_parser = crate::numbers::real, long, value_name = "R", allow_negative_numbers = true)]
    pub selective_mass_ratio: Option<f64>,

    /// Override: safety factor on the stable time step 2/ω_max
    /// (0 < C ≤ 2; default 0.9; above 1 the run is unstable). Allowed with
    /// --resume, e.g. to continue a run that failed with a smaller step.
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub time_step_safety: Option<f64>,

    /// Override: variable mass scaling — a granule whose stable step falls
    /// below this fraction R of the undeformed granule's is given the
    /// least factor on its masses that lifts it back (at most
    /// --max-mass-factor); 0 ≤ R ≤ 1, 0: off. The published scene's is 1
    /// (a scene file without the field: 0). The summary reports the
    /// granules scaled and the mass added. Allowed with --resume (masses
    /// already added stay).
    #[arg(value_parser = crate::numbers::real, long, value_name = "R", allow_negative_numbers = true)]
    pub time_step_floor: Option<f64>,

    /// Override: the largest factor K variable mass scaling puts on a
    /// granule's masses (1 ≤ K ≤ 1e6; default 4).
    #[arg(value_parser = crate::numbers::real, long, value_name = "K", allow_negative_numbers = true)]
    pub max_mass_factor: Option<f64>,

    /// The quasi-static certificate's rate check: after the run, press the
    /// same bed again at half the punch speed (into DIR/half_speed; about
    /// twice the run's cost) and require P(C) to move by less than 5 %; a
    /// scene that unloads is withdrawn at half the speed too, and a change
    /// of its in-die elastic recovery of 5 % or more is a warning
    /// (summary.json's unloading.half_speed_*). With --resume DIR, a
    /// half-speed run an interrupt stopped goes on from its checkpoint.
    #[arg(long, conflicts_with_all = ["types", "stop_at_strain"])]
    pub rate_check: bool,

    /// Worker threads (0 = all cores; at most 4096). Results do not depend
    /// on it.
    #[arg(short = 'j', long, value_name = "N", default_value_t = 0, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(0, 4096))]
    pub threads: usize,

    /// VTU snapshots with every hex of every granule instead of the
    /// granule surfaces.
    #[arg(long)]
    pub vtk_full_mesh: bool,

    /// No progress line and no summary line on stderr (warnings are still
    /// printed).
    #[arg(short, long)]
    pub quiet: bool,

    /// Start afresh even where --out (or, with --types, `DIR/<TYPE>`) holds
    /// an unfinished run, whose checkpoint is then lost. Without it such a
    /// directory is refused (`--resume DIR` continues the run); a finished
    /// run is replaced either way. A series (--types, --seeds) into a
    /// directory holding a single run's files, or a single run into a
    /// series' directory, is refused too; with --overwrite the other's
    /// files there are removed first (a series' run directories are left).
    /// A series replaces an earlier series' tables and its members' old
    /// checkpoints either way.
    #[arg(long, conflicts_with = "resume")]
    pub overwrite: bool,
}

/// The scene field a `bed` override flag sets (`--die-diameter-mm` sets
/// `die_diameter_mm`; two flags are named otherwise).
fn field_of_flag(flag: &str) -> String {
    match flag {
        "--strain" => "final_strain".to_owned(),
        "--type" => "granule_type".to_owned(),
        other => other.trim_start_matches("--").replace('-', "_"),
    }
}

/// A scene that failed its checks (`e`), reported by the override flags
/// that set the failing field or a field its check depends on (`given`:
/// each flag applied and its value): "`--die-diameter-mm 0.001` is out of
/// range (allowed: …; scene field `die_diameter_mm`)". An error no flag
/// caused is returned as it is.
pub fn flag_error(e: anyhow::Error, given: &[(&'static str, String)]) -> anyhow::Error {
    let Some(f) = e.downcast_ref::<crate::error::FieldError>() else {
        return e;
    };
    // The fields a check reads besides its own.
    let related: &[&str] = match f.field {
        "output_strain_interval" | "snapshot_strains" => &["final_strain"],
        "contact_search_interval" => &["hold_constraints"],
        "die_diameter_mm" => &["diameter_mm"],
        _ => &[],
    };
    let own = given
        .iter()
        .find(|(flag, _)| field_of_flag(flag) == f.field);
    let others: Vec<String> = given
        .iter()
        .filter(|(flag, _)| related.contains(&field_of_flag(flag).as_str()))
        .map(|(flag, v)| format!("`{flag} {v}`"))
        .collect();
    let message = match (own, others.is_empty()) {
        (Some((flag, v)), true) => format!(
            "`{flag} {v}` is out of range (allowed: {}; scene field `{}`)",
            f.allowed, f.field
        ),
        (_, false) => {
            let mut flags: Vec<String> = own
                .iter()
                .map(|(flag, v)| format!("`{flag} {v}`"))
                .collect();
            flags.extend(others);
            format!("{} rejected: {f}", flags.join(" with "))
        }
        (None, true) => return e,
    };
    crate::error::input_error(message)
}

impl BedArgs {
    /// The scene: the checkpoint's, the file or the published one, with
    /// the overrides, validated.
    pub fn scene(&self, resume: Option<&checkpoint::Checkpoint>) -> anyhow::Result<Scene> {
        Ok(self.scene_with_notes(resume)?.0)
    }

    /// [`BedArgs::scene`] and the warnings about it (a scene file's
    /// omitted fields, [`Scene::read_with_notes`]).
    pub fn scene_with_notes(
        &self,
        resume: Option<&checkpoint::Checkpoint>,
    ) -> anyhow::Result<(Scene, Vec<String>)> {
        let (scene, notes) = match (&self.scene, resume) {
            (_, Some(c)) => (
                Scene::from_toml(&c.progress.scene_toml).context("the checkpoint's scene")?,
                Vec::new(),
            ),
            (Some(path), None) => Scene::read_with_notes(path)?,
            (None, None) => (Scene::published(), Vec::new()),
        };
        Ok((self.overridden(scene, resume.is_none())?, notes))
    }

    /// `scene` with the overrides given applied, validated; `fresh` for a
    /// run that starts from a pour (not from a checkpoint): its snapshot
    /// strains past the final strain are dropped and the rest checked.
    fn overridden(&self, mut scene: Scene, fresh: bool) -> anyhow::Result<Scene> {
        // Each override given is applied and remembered as the flag and
        // its value, so that a field it set that fails the scene's checks
        // is reported by the flag.
        let mut given: Vec<(&'static str, String)> = Vec::new();
        macro_rules! set {
            ($arg:ident, $flag:literal, |$v:ident| $apply:expr) => {
                if let Some($v) = self.$arg {
                    $apply;
                    given.push(($flag, crate::numbers::Shown::shown(&$v)));
                }
            };
            ($arg:ident, $flag:literal) => {
                set!($arg, $flag, |v| scene.$arg = v)
            };
        }
        set!(granule_type, "--type", |t| scene.granule_type =
            t.name().to_string());
        set!(granules, "--granules");
        set!(mesh, "--mesh", |m| scene.mesh = m.to_string());
        set!(strain, "--strain", |c| {
            scene.final_strain = c;
            // Snapshots past the end are never written: a fresh run's scene
            // (printed, or kept in its checkpoint) leaves them out, so that it
            // reads back as a scene file. A resumed run keeps its own list.
            if fresh {
                scene.snapshot_strains.retain(|&s| s <= c);
            }
        });
        set!(seed, "--seed");
        set!(die_diameter_mm, "--die-diameter-mm");
        set!(diameter_mm, "--diameter-mm");
        set!(punch_speed_m_s, "--punch-speed-m-s");
        // A value clap parsed from its list: no check can reject it.
        if let Some(e) = self.element {
            scene.element = scene::element_name(e.into()).to_owned();
        }
        set!(hourglass_kappa, "--hourglass-kappa");
        set!(mass_scaling, "--mass-scaling");
        set!(selective_mass_scaling, "--selective-mass-scaling");
        set!(selective_mass_ratio, "--selective-mass-ratio");
        set!(unload, "--unload");
        set!(rigid_until_touched, "--rigid-until-touched");
        set!(local_sweeps, "--local-sweeps");
        set!(hold_constraints, "--hold-constraints");
        set!(contact_search_interval, "--contact-search-interval");
        set!(contact_capture, "--contact-capture");
        set!(held_reprojection, "--held-reprojection");
        set!(nearest_penetrated_face, "--nearest-penetrated-face");
        set!(exact_sweep_tolerance, "--exact-sweep-tolerance", |t| {
            scene.exact_sweep_tolerance = Some(t)
        });
        set!(exact_contact_from_strain, "--exact-contact-from-strain");
        set!(time_step_safety, "--time-step-safety");
        set!(time_step_floor, "--time-step-floor");
        set!(max_mass_factor, "--max-mass-factor");
        set!(face_list_skin, "--face-list-skin");
        set!(sweep_tolerance, "--sweep-tolerance");
        set!(kawakita_min_strain, "--kawakita-min-strain");
        set!(heckel_min_strain, "--heckel-min-strain");
        scene.validate().map_err(|e| flag_error(e, &given))?;
        if fresh {
            scene
                .check_snapshots()
                .map_err(|e| flag_error(e, &given))
                .map_err(|e| match &self.scene {
                    Some(path) => e.context(format!("scene `{}`", path.display())),
                    None => e,
                })?;
        }
        Ok(scene)
    }

    /// Runs the command.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        if let Some(dir) = &self.resume
            && !dir.join(checkpoint::FILE_NAME).is_file()
            && series::SeriesFile::is_in(dir)
        {
            if self.print_scene {
                return self.print_series_scene(dir, streams);
            }
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(self.threads)
                .build()?;
            return self.resume_series(dir, &pool, streams);
        }
        if let Some(dir) = &self.resume {
            series::refuse_runs_without_series(dir)?;
        }
        let resume = match &self.resume {
            Some(dir) => Some(checkpoint::Checkpoint::read(dir)?),
            None => None,
        };
        let (scene, notes) = self.scene_with_notes(resume.as_ref())?;
        for note in &notes {
            writeln!(streams.stderr, "warning: {note}")?;
        }
        let out = self.resume.clone().unwrap_or_else(|| self.out.clone());
        if let Some(c) = self.stop_at_strain
            && !(c > 0.0 && c <= scene.final_strain)
        {
            return Err(anyhow::Error::new(crate::error::InputError(format!(
                "`--stop-at-strain {c}` is out of range (allowed: 0 < C <= the final strain {})",
                scene.final_strain
            ))));
        }
        // The rate check's run takes half the speed, which must be a
        // scene's speed too (its checkpoint resumes as one).
        if self.rate_check && 0.5 * scene.punch_speed_m_s < scene::MIN_PUNCH_SPEED_M_S {
            return Err(crate::error::input_error(format!(
                "`--rate-check` needs a punch speed of at least {} m/s (its second run takes \
                 half the speed, at least {} m/s); the scene's punch_speed_m_s is {}",
                2.0 * scene::MIN_PUNCH_SPEED_M_S,
                scene::MIN_PUNCH_SPEED_M_S,
                scene.punch_speed_m_s
            )));
        }
        if self.print_scene {
            let text = if self.scene.is_none() && scene == Scene::published() {
                DEFAULT_SCENE.to_string()
            } else {
                scene.to_toml()
            };
            write!(streams.stdout, "{text}")?;
            return Ok(());
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()?;
        if let Some(seeds) = &self.seeds {
            return self.run_seeds(&scene, &seeds.0, &notes, &pool, streams);
        }
        if let Some(types) = &self.types {
            return self.run_types(&scene, &types.0, &notes, &pool, streams);
        }
        if resume.is_none() {
            self.keep_unfinished(&out)?;
            series::clear_other_kind(&out, false, self.overwrite)?;
            // A bad --out is reported before the banner that names it.
            crate::output::create_out_dir(&out)?;
            if !self.quiet {
                writeln!(
                    streams.stderr,
                    "bed: {} x {} granules ({} mesh) in a {} mm die to C = {}, into `{}`",
                    scene.granules,
                    scene.granule_type,
                    scene.mesh,
                    scene.die_diameter_mm,
                    scene.final_strain,
                    out.display()
                )?;
            }
        }
        if let Some(c) = &resume {
            let reached = c.progress.die.strain_at(c.state.time);
            // The run loop's own test: no step once the time is reached.
            if c.state.time >= c.progress.die.time_of_strain(scene.final_strain) {
                let withdrawal = match (scene.unload, &c.progress.unloading) {
                    (true, None) => {
                        "; the upper punch's withdrawal after it, which the checkpoint does not \
                         hold, runs now (or goes on from withdrawal.bin)"
                    }
                    (false, _) => " (without the withdrawal: scene unload = false)",
                    (true, Some(_)) => "",
                };
                writeln!(
                    streams.stderr,
                    "note: the run in `{}` is already at C = {reached:.4}, at or past the final \
                     strain {}: no step of the loading to take; its outputs are written again \
                     from the checkpoint (a larger --strain continues it){withdrawal}",
                    out.display(),
                    scene.final_strain
                )?;
            }
        }
        let control = run::RunControl {
            resume,
            packing: None,
            checkpoint_dir: Some(out.clone()),
            stop_at_strain: self.stop_at_strain,
            interrupt: Some(&crate::signal::INTERRUPT),
            check_final_overlap: true,
        };
        let mut result = self.compress(&pool, &scene, control, &out, "bed", &notes, streams)?;
        if result.interrupted {
            return Err(interrupted(&result, &out, &out, ""));
        }
        if self.rate_check && result.error.is_none() && withdrawal_failure(&result).is_none() {
            self.rate_check(&pool, &scene, &out, &mut result, streams)?;
        }
        if result.stopped && !self.quiet {
            writeln!(
                streams.stderr,
                "stopped at C = {:.4}; continue with: granbed-cli bed --resume {}",
                result.samples.last().map_or(0.0, |s| s.strain),
                out.display()
            )?;
        }
        if let Some(e) = result.error {
            let strain = result.samples.last().map_or(0.0, |s| s.strain);
            let checkpoint = match result.checkpoint_strain {
                Some(c) => format!(
                    "a checkpoint from before the failure, at C = {c:.4}, continues with \
                     `granbed-cli bed --resume {}`",
                    out.display()
                ),
                None => "no checkpoint was written".to_owned(),
            };
            return Err(anyhow::Error::new(e).context(format!(
                "the bed compression stopped early after C = {strain:.4}; the outputs so far are \
                 in `{}`, {checkpoint}",
                out.display()
            )));
        }
        // A withdrawal whose step failed (an inverted element) or whose
        // checkpoint could not be written is a run gone wrong too: exit
        // status 1, after the loading's outputs and the withdrawal's rows
        // so far were written (an interrupt's is the status above).
        if withdrawal_failure(&result).is_some() {
            anyhow::bail!(
                "the upper punch's withdrawal failed (the warning above says where); the \
                 loading's outputs and the withdrawal's rows so far are in `{}`",
                out.display()
            );
        }
        Ok(())
    }

    /// One compression of `scene` on `pool` as `control` says, with its
    /// outputs in `out` (created; a fresh run first removes the snapshots
    /// an earlier run left there), the summary line and the warnings
    /// (`notes` about the scene, then the summary's own) on stderr; the
    /// progress bar starts with `label`.
    #[allow(clippy::too_many_arguments)]
    fn compress(
        &self,
        pool: &rayon::ThreadPool,
        scene: &Scene,
        control: run::RunControl,
        out: &std::path::Path,
        label: &str,
        notes: &[String],
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<run::BedRun> {
        if control.resume.is_none() {
            snapshots::remove_old(out)?;
        }
        let mut observer = Observer {
            pour: PourSpinner::new(self.quiet, scene)?,
            progress: outputs::Progress::new(self.quiet, scene.final_strain, label),
            snapshots: snapshots::SnapshotWriter::new(
                out,
                if self.vtk_full_mesh {
                    snapshots::SnapshotContent::Hexes
                } else {
                    snapshots::SnapshotContent::Surfaces
                },
                &scene.snapshot_strains,
                1e-3 * scene.diameter_mm,
            ),
        };
        crate::output::create_out_dir(out)?;
        let result = pool.install(|| run::run_bed(scene, &control, &mut observer));
        observer.pour.finish();
        observer.progress.finish();
        let mut result = result?;
        result.warnings.extend_from_slice(notes);
        outputs::write_all(out, scene, &result)?;
        if !self.quiet {
            writeln!(streams.stderr, "{}", outputs::summary_line(scene, &result))?;
        }
        // Scene notes were printed before the run; the rest now, --quiet
        // or not.
        for w in outputs::summary(scene, &result)
            .warnings
            .iter()
            .filter(|w| !notes.contains(w))
        {
            // Several runs in one command (`--types`, the rate check's
            // twin) say whose warning it is.
            if label == "bed" {
                writeln!(streams.stderr, "warning: {w}")?;
            } else {
                writeln!(streams.stderr, "warning: {label}: {w}")?;
            }
        }
        Ok(result)
    }

    /// `--rate-check`: the same scene (same pour) at half the punch speed
    /// into `out/half_speed` (continued from its checkpoint there if an
    /// interrupt stopped it); the change of P(C) goes into `result` and the
    /// outputs in `out` are written again with it.
    fn rate_check(
        &self,
        pool: &rayon::ThreadPool,
        scene: &Scene,
        out: &std::path::Path,
        result: &mut run::BedRun,
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<()> {
        // The twin withdraws its punch if the run does, for the
        // withdrawal's own check.
        let slow = Scene {
            punch_speed_m_s: 0.5 * scene.punch_speed_m_s,
            ..scene.clone()
        };
        let dir = out.join(HALF_SPEED_DIR);
        // With --resume, a twin an interrupt stopped (its checkpoint holds
        // this very scene at half speed) goes on from there: it takes about
        // twice the run. A fresh run, and any other checkpoint there
        // (another scene, unreadable), get a fresh twin.
        let resume = self
            .resume
            .as_ref()
            .and_then(|_| checkpoint::Checkpoint::read(&dir).ok())
            .filter(|c| c.progress.scene_toml == slow.to_toml());
        if let Some(c) = &resume
            && !self.quiet
        {
            writeln!(
                streams.stderr,
                "rate check: its run at half the punch speed goes on from its checkpoint at C = \
                 {:.4} in `{}`",
                c.progress.die.strain_at(c.state.time),
                dir.display()
            )?;
        }
        let control = run::RunControl {
            resume,
            checkpoint_dir: Some(dir.clone()),
            interrupt: Some(&crate::signal::INTERRUPT),
            ..run::RunControl::default()
        };
        let twin = self
            .compress(pool, &slow, control, &dir, "half speed", &[], streams)
            .context("the rate check's run at half the punch speed")?;
        // An interrupt during the twin's withdrawal leaves its loading
        // whole: the loading's check is made, the unloading's is not.
        let loading_done = twin.unloading.is_some();
        if twin.interrupted && !loading_done {
            return Err(anyhow::Error::new(crate::signal::Interrupted(format!(
                "interrupted during the rate check's run at half the punch speed (its outputs \
                 so far are in `{}`); the run's own outputs in `{}` are complete, without the \
                 rate check: `granbed-cli bed --resume {} --rate-check` continues it",
                dir.display(),
                out.display(),
                out.display()
            ))));
        }
        if let Some(e) = twin.error {
            return Err(anyhow::Error::new(e).context(format!(
                "the rate check's run at half the punch speed failed (its outputs are in `{}`)",
                dir.display()
            )));
        }
        // The two curves at their rows' end strains: both runs have the
        // same output interval, so their pressures are paired alike, and
        // the compared window reaches the final strain (the mean strains
        // stop half an interval short of it).
        let curve = |r: &run::BedRun| -> Vec<(f64, f64)> {
            r.samples
                .iter()
                .map(|s| (s.strain, s.upper_pressure_pa))
                .collect()
        };
        let before = outputs::summary(scene, result).warnings;
        result.rate_change_rel =
            crate::quasi_static::rate_change(&curve(result), &curve(&twin), scene.final_strain);
        result.half_speed_unloading = twin
            .unloading
            .as_ref()
            .filter(|u| u.cut_short.is_none())
            .map(|u| unloading::UnloadingSummary::of(&twin, u));
        outputs::write_all(out, scene, result)?;
        let summary = outputs::summary(scene, result);
        // The checks' own warnings, which the run's were printed before
        // (with --quiet too, as every warning).
        for w in summary.warnings.iter().filter(|w| !before.contains(w)) {
            writeln!(streams.stderr, "warning: {w}")?;
        }
        if !self.quiet {
            let q = summary.quasi_static;
            writeln!(
                streams.stderr,
                "rate check: half the punch speed changes P(C) by {} (limit {}); quasi-static \
                 certificate {}",
                result
                    .rate_change_rel
                    .map_or("n/a (too short a run)".to_owned(), |r| format!("{r:.4}")),
                granbed_kernel::analysis::quasi_static::RATE_CHANGE_LIMIT,
                if q.passed { "passed" } else { "FAILED" }
            )?;
            if let Some(u) = summary
                .unloading
                .filter(|_| result.half_speed_unloading.is_some())
            {
                let check = u.rate_check;
                writeln!(
                    streams.stderr,
                    "rate check of the unloading: half the punch speed changes the in-die \
                     elastic recovery by {} (limit {}): {}",
                    check
                        .half_speed_recovery_change_rel
                        .map_or("n/a".to_owned(), |r| format!("{r:.4}")),
                    granbed_kernel::analysis::quasi_static::RATE_CHANGE_LIMIT,
                    match check.half_speed_passed {
                        Some(true) => "passed",
                        Some(false) => "FAILED (see the warning)",
                        None => "not judged (no lift-off in either run)",
                    }
                )?;
            }
        }
        if twin.interrupted {
            return Err(anyhow::Error::new(crate::signal::Interrupted(format!(
                "interrupted during the withdrawal of the rate check's run at half the punch \
                 speed (its outputs so far are in `{}`); the run's own outputs in `{}` are \
                 complete, with the loading's rate check, without the unloading's: \
                 `granbed-cli bed --resume {} --rate-check` continues it",
                dir.display(),
                out.display(),
                out.display()
            ))));
        }
        Ok(())
    }

    /// `--types`: pour once, compress every type in `types` from that
    /// packing into `DIR/<TYPE>/`, then write the comparison into `DIR`.
    fn run_types(
        &self,
        base: &Scene,
        types: &[GranuleType],
        notes: &[String],
        pool: &rayon::ThreadPool,
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<()> {
        // Every type's scene is validated (the material overrides apply to
        // each) before anything runs.
        let members: Vec<series::Member> = types
            .iter()
            .map(|&t| series::Member::of_type(&self.out, t, base))
            .collect();
        for m in &members {
            m.scene.validate().with_context(|| m.name.clone())?;
            // Before the one pour the types share.
            run::check_feasible(&m.scene).with_context(|| m.name.clone())?;
            self.keep_unfinished(&m.dir)?;
        }
        let scenes: Vec<Scene> = members.iter().map(|m| m.scene.clone()).collect();
        let mut notes = notes.to_vec();
        let given = series::type_overrides(base);
        if let Some(w) = crate::material_args::check_type_overrides(types, given)? {
            writeln!(streams.stderr, "warning: {w}")?;
            notes.push(w);
        }
        let dirs: Vec<std::path::PathBuf> = members.iter().map(|m| m.dir.clone()).collect();
        series::prepare_fresh(&self.out, &dirs, self.overwrite)?;
        // One pour for all types, as the published study compares the nine
        // types on one bed. The pour depends on the type only through the
        // sphere density (η0, the type's digit): it uses the scene's own
        // type if listed, else the first listed, and the types with another
        // η0 reuse that packing as it is.
        let pour_index = types
            .iter()
            .position(|t| base.granule_type().is_ok_and(|b| b == *t))
            .unwrap_or(0);
        let pour_type = types[pour_index];
        crate::output::create_out_dir(&self.out)?;
        let mut spinner = PourSpinner::new(self.quiet, &scenes[pour_index])?;
        let packing = pool.install(|| {
            run::pour(
                &scenes[pour_index],
                Some(&crate::signal::INTERRUPT),
                &mut |s, t| spinner.update(s, t),
            )
        });
        spinner.finish();
        let packing =
            packing.with_context(|| format!("the pour (sphere density of type {pour_type})"))?;
        if crate::signal::INTERRUPT.load(core::sync::atomic::Ordering::SeqCst) {
            return Err(anyhow::Error::new(crate::signal::Interrupted(
                "interrupted during the pour: nothing was compressed".to_owned(),
            )));
        }
        if !self.quiet {
            writeln!(
                streams.stderr,
                "poured {} spheres (density of {pour_type}) in {:.1} s; compressing {} types",
                packing.centres.len(),
                packing.wall_time_s,
                types.len()
            )?;
        }
        series::SeriesFile {
            format: series::FORMAT,
            kind: series::SeriesKind::Types,
            members: types.iter().map(|t| t.name().to_owned()).collect(),
            scene_toml: base.to_toml(),
            pour: Some(series::StoredPacking::new(pour_type, &packing)),
        }
        .write(&self.out)?;
        let mut series: Vec<SeriesRun> = members
            .iter()
            .zip(&scenes)
            .map(|(m, scene)| m.run(scene, Some(packing.clone()), None))
            .collect();
        let runs =
            self.compress_series(pool, &mut series, &self.out, "comparison", &notes, streams)?;
        write_types_tables(&self.out, &scenes, &runs, pour_type, packing.wall_time_s)?;
        series_failures(&series, runs)
    }
}

/// The comparison of a `--types` series in `dir` ([`compare::write_comparison`]):
/// `scenes` and `runs` per type, in order; the pour was of `pour_type`'s
/// sphere density and took `pour_wall_time_s`.
fn write_types_tables(
    dir: &std::path::Path,
    scenes: &[Scene],
    runs: &[run::BedRun],
    pour_type: GranuleType,
    pour_wall_time_s: f64,
) -> anyhow::Result<()> {
    let rows: Vec<compare::ComparisonRow> = scenes
        .iter()
        .zip(runs)
        .map(|(scene, r)| {
            Ok(compare::ComparisonRow::new(
                scene.granule_type()?,
                &outputs::summary(scene, r),
            ))
        })
        .collect::<anyhow::Result<_>>()?;
    let run_refs: Vec<&run::BedRun> = runs.iter().collect();
    let comparison = compare::Comparison {
        version: env!("CARGO_PKG_VERSION"),
        pour_granule_type: pour_type.name(),
        pour_wall_time_s,
        types: &rows,
    };
    compare::write_comparison(dir, &comparison, &run_refs)
}

/// One run of a series (`--types`, `--seeds`): what it is called in
/// messages, its progress label, output directory, scene and, for runs
/// that share one pour, the packing.
struct SeriesRun<'a> {
    name: String,
    label: String,
    dir: std::path::PathBuf,
    scene: &'a Scene,
    packing: Option<run::Packing>,
    /// The checkpoint to continue from (a resumed series), else a fresh run.
    resume: Option<checkpoint::Checkpoint>,
}

impl BedArgs {
    /// Compresses the runs of `series` one after the other (each fresh or
    /// from its checkpoint, which is taken out of it, on all of `pool`'s
    /// threads, with its checkpoints and outputs in its directory). A run
    /// the kernel stopped does not stop the others (see
    /// [`series_failures`]); an interrupt stops the series with an error
    /// naming the runs not made and the `what` (the series' own output in
    /// `series_dir`) left unwritten, and how to resume the series.
    fn compress_series(
        &self,
        pool: &rayon::ThreadPool,
        series: &mut [SeriesRun<'_>],
        series_dir: &std::path::Path,
        what: &str,
        notes: &[String],
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<Vec<run::BedRun>> {
        let mut runs = Vec::with_capacity(series.len());
        for k in 0..series.len() {
            let resume = series[k].resume.take();
            let item = &series[k];
            let rest: Vec<&str> = series[k + 1..].iter().map(|r| r.name.as_str()).collect();
            let rest = if rest.is_empty() {
                String::new()
            } else {
                format!("; not run: {}", rest.join(", "))
            };
            let control = run::RunControl {
                resume,
                packing: item.packing.clone(),
                checkpoint_dir: Some(item.dir.clone()),
                stop_at_strain: None,
                interrupt: Some(&crate::signal::INTERRUPT),
                check_final_overlap: true,
            };
            let result = self
                .compress(
                    pool,
                    item.scene,
                    control,
                    &item.dir,
                    &item.label,
                    notes,
                    streams,
                )
                .map_err(|e| {
                    // Stopped in its pour: the runs before it are kept,
                    // and the series goes on from them.
                    if e.downcast_ref::<crate::signal::Interrupted>().is_some() {
                        anyhow::Error::new(crate::signal::Interrupted(format!(
                            "interrupted during the pour of {} (nothing of it compressed; no \
                             {what} written{rest}); the runs before it are kept: continue the \
                             series with: granbed-cli bed --resume {}",
                            item.name,
                            series_dir.display()
                        )))
                    } else {
                        e.context(item.name.clone())
                    }
                })?;
            if result.interrupted {
                return Err(interrupted(
                    &result,
                    &item.dir,
                    series_dir,
                    &format!(" ({}; no {what} written{rest})", item.name),
                ));
            }
            runs.push(result);
        }
        Ok(runs)
    }
}

/// Why a run's punch withdrawal stopped short, if it failed: a step that
/// failed or a checkpoint that could not be written (an interrupt is not a
/// failure: its run is resumable).
fn withdrawal_failure(r: &run::BedRun) -> Option<&run::CutShort> {
    r.unloading
        .as_ref()
        .and_then(|u| u.cut_short.as_ref())
        .filter(|why| !matches!(why, run::CutShort::Interrupted { .. }))
}

/// The runs of a series the kernel stopped, or whose withdrawal failed,
/// each named with its strain and directory (the others ran on): all
/// reported, or `Ok`.
fn series_failures(series: &[SeriesRun<'_>], runs: Vec<run::BedRun>) -> anyhow::Result<()> {
    let failed = series.iter().zip(runs).filter_map(|(item, r)| {
        let strain = r.samples.last().map_or(0.0, |s| s.strain);
        let withdrawal = withdrawal_failure(&r).map(|why| {
            anyhow::anyhow!(
                "{}: the upper punch's withdrawal failed ({why}); the loading's outputs and the \
                 withdrawal's rows so far are in `{}`",
                item.name,
                item.dir.display()
            )
        });
        r.error
            .map(|e| {
                anyhow::Error::new(e).context(format!(
                    "{}: the bed compression stopped early after C = {strain:.4} (outputs so \
                     far and the last checkpoint in `{}`)",
                    item.name,
                    item.dir.display()
                ))
            })
            .or(withdrawal)
    });
    crate::output::all_failures(failed, "stopped early")
}

/// The error of a run stopped by SIGINT/SIGTERM, its outputs and
/// checkpoint in `dir`, continued by `--resume resume_dir` (`dir`, or the
/// directory of the series it belongs to); `what` adds to the message.
fn interrupted(
    result: &run::BedRun,
    dir: &std::path::Path,
    resume_dir: &std::path::Path,
    what: &str,
) -> anyhow::Error {
    anyhow::Error::new(crate::signal::Interrupted(format!(
        "interrupted at {}{what}: the checkpoint and the outputs so far are in `{}`; continue \
         with: granbed-cli bed --resume {}",
        result.stopped_at(),
        dir.display(),
        resume_dir.display()
    )))
}

impl BedArgs {
    /// Refuses a fresh run into `dir` when it holds an unfinished run
    /// (readable `checkpoint.bin` short of its final strain), unless
    /// `--overwrite`: its checkpoint would be lost. A finished run, a
    /// directory without a checkpoint and an unreadable checkpoint (which
    /// no resume could use) are no reason to stop.
    fn keep_unfinished(&self, dir: &std::path::Path) -> anyhow::Result<()> {
        if self.overwrite {
            return Ok(());
        }
        let Some((reached, last)) = unfinished_run(dir) else {
            return Ok(());
        };
        Err(crate::error::input_error(format!(
            "`{}` holds an unfinished run (checkpoint at C = {reached:.4} of {last}): \
             `granbed-cli bed --resume {}` continues it; choose another --out, or pass \
             --overwrite to start afresh there and lose it",
            dir.display(),
            dir.display()
        )))
    }
}

/// The strain an unfinished bed run in `dir` has reached and its final
/// strain: `Some` when `dir` holds a readable `checkpoint.bin` whose scene
/// parses and whose state is short of its final strain. A finished run, a
/// directory without a checkpoint and an unreadable checkpoint (which no
/// resume could use) give `None`.
pub fn unfinished_run(
    dir: &std::path::Path,
) -> Option<(granbed_kernel::Real, granbed_kernel::Real)> {
    if !dir.join(checkpoint::FILE_NAME).is_file() {
        return None;
    }
    let c = checkpoint::Checkpoint::read(dir).ok()?;
    let scene = Scene::from_toml(&c.progress.scene_toml).ok()?;
    (c.state.time < c.progress.die.time_of_strain(scene.final_strain))
        .then(|| (c.progress.die.strain_at(c.state.time), scene.final_strain))
}

/// Refuses a `command` (`granule`, `pack`) whose outputs would go into a
/// directory holding an unfinished bed run: its `summary.json` and
/// `report.html` would replace the run's, beside the checkpoint that
/// `--resume` continues from.
pub fn refuse_unfinished(dir: &std::path::Path, command: &str) -> anyhow::Result<()> {
    match unfinished_run(dir) {
        None => Ok(()),
        Some((reached, last)) => Err(crate::error::input_error(format!(
            "`{}` holds an unfinished bed run (checkpoint at C = {reached:.4} of {last}), whose \
             summary and report this {command} run would replace: choose another --out \
             (`granbed-cli bed --resume {}` continues that run)",
            dir.display(),
            dir.display()
        ))),
    }
}

/// What the command does with the run as it goes.
struct Observer {
    pour: PourSpinner,
    progress: outputs::Progress,
    snapshots: snapshots::SnapshotWriter,
}

impl run::BedObserver for Observer {
    fn sample(&mut self, sample: &run::BedSample, elapsed_s: f64) {
        self.pour.finish();
        self.progress.update(sample, elapsed_s);
    }

    fn withdrawal(&mut self, row: &run::BedSample, elapsed_s: f64) {
        self.pour.finish();
        self.progress.withdrawing(row, elapsed_s);
    }

    fn pour(&mut self, status: &granbed_kernel::dem::pour::PourStatus, elapsed_s: f64) {
        self.pour.update(status, elapsed_s);
    }

    fn snapshot(
        &mut self,
        strain: f64,
        assembly: &crate::assembly::Assembly<'_>,
        mesh: &crate::model::OwnedReference,
    ) -> anyhow::Result<()> {
        self.snapshots.write(strain, assembly, mesh)
    }
}

/// `pack`'s progress line for the pour of a bed (on stderr when it is a
/// terminal and not `--quiet`), drawn from the pour's first rest check and
/// removed when the compression's bar takes over.
struct PourSpinner {
    quiet: bool,
    granules: usize,
    max_time_s: f64,
    bar: Option<crate::pack::progress::Progress>,
}

impl PourSpinner {
    /// The spinner of `scene`'s pour, not drawn yet.
    fn new(quiet: bool, scene: &Scene) -> anyhow::Result<Self> {
        Ok(Self {
            quiet,
            granules: scene.granules,
            max_time_s: run::pour_params(scene, &scene.material()?).max_time,
            bar: None,
        })
    }

    /// Shows the pour's state `status`, `elapsed_s` into it.
    fn update(&mut self, status: &granbed_kernel::dem::pour::PourStatus, elapsed_s: f64) {
        let (quiet, granules, max_time_s) = (self.quiet, self.granules, self.max_time_s);
        self.bar
            .get_or_insert_with(|| {
                crate::pack::progress::Progress::new(quiet, granules, max_time_s)
            })
            .update(status, elapsed_s);
    }

    /// Removes the line, if drawn.
    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish();
        }
    }
}
