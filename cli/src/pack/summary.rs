//! The measures of one pour (`summary.json`): bed height, packing fractions,
//! contacts, force balance, cost, and every parameter for provenance.

use crate::output::finite_ratio as ratio;
use granbed_kernel::Real;
use granbed_kernel::dem::pour::{PourParams, PourStatus};
use serde::Serialize;

use super::measures::{self, Region};
use super::run::{CHECK_EVERY, PourResult};

/// Name of the `summary.json` format (its `format` field).
pub const FORMAT: &str = "granbed-pack-summary";
/// Version of the `summary.json` format; bumped when a field changes
/// meaning or disappears (adding a field does not bump it).
pub const FORMAT_VERSION: u32 = 1;

/// Distance of the interior region from the die wall, the floor and the bed
/// top, in granule diameters (physics.md §6 oracle 3).
pub const INTERIOR_MARGIN_DIAMETERS: Real = 2.0;

/// What was poured: the inputs of a summary that are not in [`PourParams`].
#[derive(Clone, Copy, Debug)]
pub struct PackSetup<'a> {
    /// Granule type name the material preset came from, e.g. `B2`.
    pub granule_type: &'a str,
    /// Initial relative density η0 of the granules.
    pub eta0: Real,
    /// True (solid) density, kg/m³.
    pub true_density_kg_m3: Real,
    /// The pour's parameters.
    pub params: &'a PourParams,
}

/// The interior region of `summary.json`.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RegionSummary {
    /// Radius of the region's cylinder (die radius − 2d), m.
    pub radius_m: Real,
    /// Bottom of the region (2d), m.
    pub z_lo_m: Real,
    /// Top of the region (bed height − 2d), m.
    pub z_hi_m: Real,
}

/// `summary.json`: one pour's inputs and measures. Units are in the field
/// names; a measure that cannot be computed is `null`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Always [`FORMAT`].
    pub format: &'static str,
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Version of granbed that wrote the file.
    pub granbed_version: &'static str,

    /// Granule type of the material preset, e.g. `B2` (overrides below).
    pub granule_type: String,
    /// Initial relative density η0 of the granules.
    pub eta0: Real,
    /// True (solid) density, kg/m³.
    pub true_density_kg_m3: Real,
    /// Sphere density η0 × true density, kg/m³.
    pub density_kg_m3: Real,
    /// Sphere mass, kg.
    pub mass_kg: Real,
    /// Number of granules N.
    pub granules: usize,
    /// Granule diameter d, m.
    pub diameter_m: Real,
    /// Die diameter, m.
    pub die_diameter_m: Real,
    /// Contact Young's modulus E_DE, Pa.
    pub youngs_modulus_pa: Real,
    /// Contact Poisson's ratio.
    pub poisson_ratio: Real,
    /// Sphere–sphere friction coefficient.
    pub friction_particle: Real,
    /// Sphere–wall (floor and die) friction coefficient.
    pub friction_wall: Real,
    /// Gravity, m/s² (in −z).
    pub gravity_m_s2: Real,
    /// Spacing of the initial square lattice, m.
    pub lattice_spacing_m: Real,
    /// Jitter of the initial positions, ± m per component.
    pub jitter_m: Real,
    /// Height of the initial lattice (top of the highest sphere), m.
    pub insertion_height_m: Real,
    /// Initial velocities, ± m/s per component.
    pub initial_speed_m_s: Real,
    /// Coefficient of restitution before the dissipation ramp.
    pub restitution_start: Real,
    /// Coefficient of restitution after the ramp.
    pub restitution_end: Real,
    /// Global damping after the ramp, 1/s.
    pub damping_max_per_s: Real,
    /// Start and end of the dissipation ramp, s.
    pub ramp_s: [Real; 2],
    /// At rest when every speed is below this, m/s …
    pub rest_speed_m_s: Real,
    /// … and the kinetic energy per sphere below this, J.
    pub rest_kinetic_energy_j: Real,
    /// Simulated time limit, s.
    pub max_time_s: Real,
    /// Time step as a fraction of the Hertz contact time at 0.1 m/s.
    pub time_step_fraction: Real,
    /// Neighbour-list skin, m.
    pub skin_m: Real,
    /// Random seed of the lattice jitter and the initial velocities.
    pub seed: u64,
    /// Steps between rest checks (the resolution of `settle_time_s`).
    pub check_every_steps: u64,

    /// True if the spheres came to rest within `max_time_s`.
    pub settled: bool,
    /// Bed height H = max(z + r), m.
    pub bed_height_m: Real,
    /// Packing fraction of the whole bed, N (4/3)π r³ / (π R_die² H).
    pub packing_fraction: Real,
    /// Packing fraction of the interior region (`interior_region`): the
    /// sphere volume inside it over its volume; `null` if the bed is too
    /// low or the die too narrow to leave a region.
    pub interior_packing_fraction: Option<Real>,
    /// The region at least 2d from the die wall, the floor and the bed top.
    pub interior_region: Option<RegionSummary>,
    /// Overlapping sphere–sphere pairs (centre distance < d).
    pub sphere_contacts: usize,
    /// Coordination number 2 × sphere contacts / N (walls excluded).
    pub coordination_number: Real,
    /// Spheres touching the floor.
    pub floor_contacts: usize,
    /// Spheres touching the die wall.
    pub die_contacts: usize,
    /// (2 × sphere contacts + floor and die contacts) / N.
    pub coordination_number_with_walls: Real,
    /// Largest overlap of any contact (sphere or wall), m.
    pub max_overlap_m: Real,
    /// Largest sphere–sphere overlap, m.
    pub max_sphere_overlap_m: Real,
    /// Largest sphere–wall (floor or die) overlap, m.
    pub max_wall_overlap_m: Real,

    /// Simulated time at rest (first rest check that passed), s; `null`
    /// if not settled.
    pub settle_time_s: Option<Real>,
    /// Simulated time at the end of the run, s.
    pub time_s: Real,
    /// Time steps taken.
    pub steps: u64,
    /// Time step, s.
    pub dt_s: Real,
    /// Wall time of the pour (setup and stepping), s.
    pub wall_time_s: f64,
    /// Sphere-steps per wall second.
    pub sphere_steps_per_s: Option<f64>,
    /// Kinetic energy at the end, J.
    pub kinetic_energy_j: Real,
    /// Largest sphere speed at the end, m/s.
    pub max_speed_m_s: Real,
    /// Floor reaction at the end, N.
    pub floor_force_n: Real,
    /// Vertical friction force of the die wall at the end (upward
    /// positive), N.
    pub wall_friction_z_n: Real,
    /// Bed weight N m g, N.
    pub weight_n: Real,
    /// (floor force + wall friction)/(N m g) − 1: zero for a bed at rest.
    pub force_balance_rel: Real,
    /// The kernel error that stopped the pour, or `null`.
    pub error: Option<String>,
}

impl Summary {
    /// The summary of `result`, a pour of `setup`.
    pub fn new(setup: &PackSetup<'_>, result: &PourResult) -> Self {
        let p = setup.params;
        let s: &PourStatus = &result.status;
        let (x, r, n) = (&result.positions, p.radius, p.granules);
        let d = 2.0 * r;
        let height = measures::bed_height(x, r);
        let region = Region::interior(p.die_radius, height, INTERIOR_MARGIN_DIAMETERS * d);
        let spheres = measures::sphere_contacts(x, r, result.sphere_pairs.iter().copied());
        let walls = measures::wall_contacts(x, r, p.die_radius);
        let weight = n as Real * p.mass() * p.gravity_m_s2;
        Self {
            format: FORMAT,
            format_version: FORMAT_VERSION,
            granbed_version: env!("CARGO_PKG_VERSION"),
            granule_type: setup.granule_type.to_owned(),
            eta0: setup.eta0,
            true_density_kg_m3: setup.true_density_kg_m3,
            density_kg_m3: p.density,
            mass_kg: p.mass(),
            granules: n,
            diameter_m: d,
            die_diameter_m: 2.0 * p.die_radius,
            youngs_modulus_pa: p.youngs_modulus_pa,
            poisson_ratio: p.poisson_ratio,
            friction_particle: p.friction_particle,
            friction_wall: p.friction_wall,
            gravity_m_s2: p.gravity_m_s2,
            lattice_spacing_m: p.lattice_spacing,
            jitter_m: p.jitter,
            insertion_height_m: p.fill_height(),
            initial_speed_m_s: p.initial_speed,
            restitution_start: p.restitution_start,
            restitution_end: p.restitution_end,
            damping_max_per_s: p.damping_max,
            ramp_s: [p.ramp.0, p.ramp.1],
            rest_speed_m_s: p.rest_speed,
            rest_kinetic_energy_j: p.rest_kinetic_energy,
            max_time_s: p.max_time,
            time_step_fraction: p.time_step_fraction,
            skin_m: p.skin,
            seed: p.seed,
            check_every_steps: CHECK_EVERY,
            settled: result.error.is_none() && s.settled,
            bed_height_m: height,
            packing_fraction: measures::packing_fraction(n, r, p.die_radius, height),
            interior_packing_fraction: region.map(|g| g.packing_fraction(x, r)),
            interior_region: region.map(|g| RegionSummary {
                radius_m: g.radius,
                z_lo_m: g.z_lo,
                z_hi_m: g.z_hi,
            }),
            sphere_contacts: spheres.pairs,
            coordination_number: measures::coordination_number(spheres.pairs, n),
            floor_contacts: walls.floor,
            die_contacts: walls.die,
            coordination_number_with_walls: (2 * spheres.pairs + walls.floor + walls.die) as Real
                / n as Real,
            max_overlap_m: spheres.max_overlap.max(walls.max_overlap),
            max_sphere_overlap_m: spheres.max_overlap,
            max_wall_overlap_m: walls.max_overlap,
            settle_time_s: (result.error.is_none() && s.settled).then_some(s.time),
            time_s: s.time,
            steps: s.steps,
            dt_s: result.dt_s,
            wall_time_s: result.wall_time_s,
            sphere_steps_per_s: ratio(s.steps as f64 * n as f64, result.wall_time_s),
            kinetic_energy_j: s.kinetic_energy,
            max_speed_m_s: s.max_speed,
            floor_force_n: s.floor_force,
            wall_friction_z_n: s.wall_friction_z,
            weight_n: weight,
            force_balance_rel: (s.floor_force + s.wall_friction_z) / weight - 1.0,
            error: result.error.as_ref().map(ToString::to_string),
        }
    }

    /// The one-line stderr report of the pour.
    pub fn line(&self) -> String {
        let interior = self
            .interior_packing_fraction
            .map_or_else(|| "n/a".to_owned(), |f| format!("{f:.4}"));
        let state = match self.settle_time_s {
            Some(t) => format!("at rest after {t:.3} s"),
            None => format!("NOT at rest after {:.3} s", self.time_s),
        };
        format!(
            "pack {}: {} granules {state} ({} steps, {:.1} s): bed height {:.4} mm, packing \
             fraction {:.4} (interior {interior}), coordination number {:.3}",
            self.granule_type,
            self.granules,
            self.steps,
            self.wall_time_s,
            self.bed_height_m * 1e3,
            self.packing_fraction,
            self.coordination_number
        )
    }
}
