//! The pour: rigid spheres dropped from a loose lattice with random
//! velocities into the die settle under gravity while dissipation is ramped
//! up until they are at rest (physics.md §6). Velocity Verlet with a fixed
//! step; forces summed in the sorted pair order, so a seed gives the same
//! bed bit for bit.

use core::fmt;
use core::ops::ControlFlow;

use crate::Real;
use crate::dem::contact::{ContactLanes, ContactLaw, hertz_beta, hertz_mindlin_lanes};

/// Contacts evaluated side by side ([`hertz_mindlin_lanes`]).
const LANES: usize = 4;
use crate::dem::neighbors::{DIE, FLOOR, Grid, GridScratch, Pair, PairOverflow, build_pairs};
use crate::math;
use crate::rng::Rng;

/// The widest die a pour accepts, in lattice spacings of its radius: the
/// checks walk one layer of the lattice (about 3·10⁸ sites at this bound),
/// and an infinite die would be walked without end.
pub const MAX_DIE_LATTICE_SPACINGS: Real = 1.0e4;

/// Parameters of the pour (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PourParams {
    /// Number of spheres; 1 ≤ N ≤ 100 000.
    pub granules: usize,
    /// Sphere radius, m; 0 < r < 1.
    pub radius: Real,
    /// Sphere density, kg/m³ (η0 × true density); > 0.
    pub density: Real,
    /// Contact Young's modulus E_DE, Pa (stiffer than the granule so resting
    /// overlaps stay below 0.3 µm); > 0.
    pub youngs_modulus_pa: Real,
    /// Contact Poisson's ratio; −1 < ν < 0.5.
    pub poisson_ratio: Real,
    /// Sphere–sphere friction; ≥ 0 (`+∞`: no sliding).
    pub friction_particle: Real,
    /// Sphere–wall friction; ≥ 0 (`+∞`: no sliding).
    pub friction_wall: Real,
    /// Die radius, m; > 2·radius and ≤ [`MAX_DIE_LATTICE_SPACINGS`] ×
    /// `lattice_spacing`.
    pub die_radius: Real,
    /// Gravity, m/s² (in −z); > 0.
    pub gravity_m_s2: Real,
    /// Spacing of the initial square lattice, m; ≥ 2·radius + 2·jitter.
    pub lattice_spacing: Real,
    /// Random jitter of the initial positions, ± m per component; ≥ 0 (and
    /// within the lattice spacing's room, above).
    pub jitter: Real,
    /// Random initial velocity, ± m/s per component; finite, ≥ 0.
    pub initial_speed: Real,
    /// Coefficient of restitution before the dissipation ramp; (0, 1].
    pub restitution_start: Real,
    /// Coefficient of restitution after the ramp; (0, 1].
    pub restitution_end: Real,
    /// Global damping coefficient after the ramp, 1/s (0 before it); finite,
    /// ≥ 0.
    pub damping_max: Real,
    /// Ramp start and end times, s; 0 ≤ start < end < `max_time`.
    pub ramp: (Real, Real),
    /// At rest when every speed is below this, m/s; finite, > 0.
    pub rest_speed: Real,
    /// … and the kinetic energy per sphere below this, J; finite, > 0.
    pub rest_kinetic_energy: Real,
    /// Give up (error) after this simulated time, s; finite, past the ramp.
    pub max_time: Real,
    /// Time step as a fraction of the Hertz contact time at 0.1 m/s;
    /// 0 < f ≤ 0.2.
    pub time_step_fraction: Real,
    /// Neighbour-list skin, m; > 0 and ≤ `radius` (see [`Self::validate`]).
    pub skin: Real,
    /// Random seed.
    pub seed: u64,
}

impl PourParams {
    /// The published setup (physics.md §6): 1000 spheres of d = 1 mm and
    /// density `density` into the 11.3 mm die, E_DE = 100 MPa, ν = 0.3,
    /// μ = 0.1, lattice 1.15 mm ± 0.05 mm, velocities ± 0.1 m/s, restitution
    /// 0.9 → 0.3 and damping 0 → 200 /s over 0.10–0.30 s, Δt = t_c/50.
    ///
    /// **Choice:** physics.md §6 ramps over 0.05–0.25 s; the top of the
    /// 20 mm column needs 64 ms to land, and damping it on the way left beds
    /// of 9.67 / 9.82 / 9.92 mm (seeds 1/2/3) against the published
    /// 9.5 ± 0.3 mm. Starting the ramp at 0.10 s gives 9.62 / 9.71 / 9.70 mm
    /// (and 9.72 mm for seed 4) at the same cost.
    pub fn standard(density: Real, seed: u64) -> Self {
        Self {
            granules: 1000,
            radius: 0.5e-3,
            density,
            youngs_modulus_pa: 100e6,
            poisson_ratio: 0.3,
            friction_particle: 0.1,
            friction_wall: 0.1,
            die_radius: 5.65e-3,
            gravity_m_s2: 9.81,
            lattice_spacing: 1.15e-3,
            jitter: 0.05e-3,
            initial_speed: 0.1,
            restitution_start: 0.9,
            restitution_end: 0.3,
            damping_max: 200.0,
            ramp: (0.10, 0.30),
            rest_speed: 1e-5,
            rest_kinetic_energy: 1e-13,
            max_time: 3.0,
            time_step_fraction: 1.0 / 50.0,
            skin: 0.1e-3,
            seed,
        }
    }

    /// Sphere mass, kg.
    pub fn mass(&self) -> Real {
        self.density * 4.0 / 3.0 * core::f64::consts::PI * self.radius * self.radius * self.radius
    }

    /// Lattice sites per layer: the square-lattice points whose jittered
    /// sphere stays inside the die. At most [`MAX_DIE_LATTICE_SPACINGS`]
    /// spacings from the axis: [`Self::validate`] refuses a wider die, and
    /// the cut keeps [`Self::fill_height`] and [`Self::grid`] finite for
    /// parameters it refuses (a lattice spacing of 0 or an infinite die
    /// made them walk 2¹²⁸ sites).
    fn sites(&self) -> impl Iterator<Item = [Real; 2]> + '_ {
        let reach = self.die_radius - self.radius - self.jitter * core::f64::consts::SQRT_2;
        // NaN (a NaN radius or spacing): no sites, as `as i64` gave before
        // the cut (`min` would take the bound).
        let k = match libm::floor(reach / self.lattice_spacing) {
            k if k.is_nan() => 0,
            k => k.min(MAX_DIE_LATTICE_SPACINGS) as i64,
        };
        (-k..=k)
            .flat_map(move |j| {
                (-k..=k).map(move |i| {
                    [
                        i as Real * self.lattice_spacing,
                        j as Real * self.lattice_spacing,
                    ]
                })
            })
            .filter(move |p| p[0] * p[0] + p[1] * p[1] <= reach * reach)
    }

    /// Height of the initial lattice (top of the highest sphere), m.
    pub fn fill_height(&self) -> Real {
        let per_layer = self.sites().count().max(1);
        let layers = self.granules.div_ceil(per_layer);
        self.radius
            + self.jitter
            + (layers as Real - 1.0) * self.lattice_spacing
            + self.radius
            + self.jitter
    }

    /// The neighbour grid (its `cells()` sizes the `head` buffer). Check
    /// the parameters with [`Self::validate`] first: for parameters it
    /// refuses the grid still comes back, but its cell count can be vast
    /// (it saturates at `usize::MAX`).
    pub fn grid(&self) -> Grid {
        Grid::new(
            self.die_radius,
            self.fill_height() + 2.0 * self.radius,
            2.0 * self.radius + self.skin,
        )
    }

    /// Hertz contact time of two spheres meeting at 0.1 m/s, s.
    pub fn contact_time(&self) -> Real {
        let law = ContactLaw::sphere_sphere(
            self.youngs_modulus_pa,
            self.poisson_ratio,
            self.radius,
            self.mass(),
            0.0,
        );
        let v = 0.1;
        2.87 * libm::pow(
            law.m_star * law.m_star / (law.r_star * law.e_star * law.e_star * v),
            0.2,
        )
    }

    /// Checks every parameter's range (what [`PourScene::new`] checks first):
    /// [`PourError::InvalidParameter`] naming the first field out of its
    /// range. Call it before sizing buffers from [`Self::grid`].
    pub fn validate(&self) -> Result<(), PourError> {
        let d = 2.0 * self.radius;
        let finite = |v: Real| v.is_finite();
        let checks: [(bool, &'static str, Real, &'static str); 18] = [
            (
                (1..=100_000).contains(&self.granules),
                "granules",
                self.granules as Real,
                "1 ..= 100000",
            ),
            (
                self.radius > 0.0 && self.radius < 1.0,
                "radius",
                self.radius,
                "0 < r < 1 m",
            ),
            (
                self.density > 0.0 && self.density.is_finite(),
                "density",
                self.density,
                "> 0",
            ),
            (
                self.youngs_modulus_pa > 0.0 && self.youngs_modulus_pa.is_finite(),
                "youngs_modulus_pa",
                self.youngs_modulus_pa,
                "> 0",
            ),
            (
                self.poisson_ratio > -1.0 && self.poisson_ratio < 0.5,
                "poisson_ratio",
                self.poisson_ratio,
                "-1 < nu < 0.5",
            ),
            (
                self.friction_particle >= 0.0 && self.friction_wall >= 0.0,
                "friction",
                self.friction_particle.min(self.friction_wall),
                ">= 0",
            ),
            (
                self.lattice_spacing >= d + 2.0 * self.jitter
                    && finite(self.lattice_spacing)
                    && self.jitter >= 0.0,
                "lattice_spacing",
                self.lattice_spacing,
                ">= diameter + 2 jitter, finite",
            ),
            // Bounded before `sites` walks the lattice: an infinite die
            // would walk it without end.
            (
                self.die_radius > 2.0 * d
                    && self.die_radius <= MAX_DIE_LATTICE_SPACINGS * self.lattice_spacing,
                "die_radius",
                self.die_radius,
                "> 2 diameters and <= 10000 lattice spacings",
            ),
            (
                self.gravity_m_s2 > 0.0 && finite(self.gravity_m_s2),
                "gravity_m_s2",
                self.gravity_m_s2,
                "> 0, finite",
            ),
            (
                self.initial_speed >= 0.0 && finite(self.initial_speed),
                "initial_speed",
                self.initial_speed,
                ">= 0, finite",
            ),
            (
                self.damping_max >= 0.0 && finite(self.damping_max),
                "damping_max",
                self.damping_max,
                ">= 0, finite",
            ),
            (
                self.rest_speed > 0.0 && finite(self.rest_speed),
                "rest_speed",
                self.rest_speed,
                "> 0, finite",
            ),
            (
                self.rest_kinetic_energy > 0.0 && finite(self.rest_kinetic_energy),
                "rest_kinetic_energy",
                self.rest_kinetic_energy,
                "> 0, finite",
            ),
            (
                self.restitution_start > 0.0
                    && self.restitution_start <= 1.0
                    && self.restitution_end > 0.0
                    && self.restitution_end <= 1.0,
                "restitution",
                self.restitution_end,
                "0 < e <= 1",
            ),
            (
                self.ramp.0 >= 0.0 && self.ramp.1 > self.ramp.0 && self.max_time > self.ramp.1,
                "ramp",
                self.ramp.1,
                "0 <= start < end < max_time",
            ),
            (finite(self.max_time), "max_time", self.max_time, "finite"),
            (
                self.time_step_fraction > 0.0 && self.time_step_fraction <= 0.2,
                "time_step_fraction",
                self.time_step_fraction,
                "0 < f <= 0.2",
            ),
            // At most the radius: the centres within 2r + skin ≤ 3r of a
            // sphere's are those of spheres inside a ball of 4r, at most
            // 0.7405 · 4³ ≈ 47 of them unless they overlap deeply, within
            // the 64 partners per sphere the pair search holds
            // (`neighbors::MAX_PARTNERS`).
            (
                self.skin > 0.0 && self.skin <= self.radius && finite(self.skin),
                "skin",
                self.skin,
                "> 0 and <= radius",
            ),
        ];
        for (ok, field, value, allowed) in checks {
            if !ok {
                return Err(PourError::InvalidParameter {
                    field,
                    value,
                    allowed,
                });
            }
        }
        if self.sites().count() == 0 {
            return Err(PourError::InvalidParameter {
                field: "die_radius",
                value: self.die_radius,
                allowed: "wide enough for one lattice site",
            });
        }
        Ok(())
    }
}

/// Why the pour cannot go on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PourError {
    /// A parameter is out of range.
    InvalidParameter {
        /// Field of [`PourParams`].
        field: &'static str,
        /// Value given.
        value: Real,
        /// Allowed range.
        allowed: &'static str,
    },
    /// A buffer has the wrong length.
    BufferLength {
        /// Buffer name as in [`PourBuffers`].
        buffer: &'static str,
        /// Entries expected.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// The candidate-pair buffer is too small (grow it and call again), or
    /// a sphere has more partners than the search holds
    /// ([`PairOverflow::per_sphere`]: spheres overlapping far more than a
    /// pour lets them, which a larger buffer does not cure).
    Pairs(PairOverflow),
    /// The spheres did not come to rest within `max_time`.
    NotSettled {
        /// Simulated time, s.
        time: Real,
        /// Largest speed, m/s.
        max_speed: Real,
    },
    /// A position or velocity became non-finite.
    Unstable {
        /// Step number.
        step: u64,
    },
    /// The caller's `on_check` of [`PourScene::run_to_rest`] asked it to
    /// stop before the spheres came to rest (the scene keeps its state).
    Stopped {
        /// Simulated time, s.
        time: Real,
        /// Steps taken.
        steps: u64,
    },
}

impl fmt::Display for PourError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParameter {
                field,
                value,
                allowed,
            } => {
                write!(f, "invalid `{field}` = {value}: allowed range is {allowed}")
            }
            Self::BufferLength {
                buffer,
                expected,
                got,
            } => {
                write!(
                    f,
                    "buffer `{buffer}` has {got} entries, expected {expected}"
                )
            }
            Self::Pairs(e) => write!(f, "{e}"),
            Self::NotSettled { time, max_speed } => write!(
                f,
                "the spheres did not come to rest within {time} s (largest speed {max_speed:e} m/s)"
            ),
            Self::Unstable { step } => write!(f, "step {step}: the motion became non-finite"),
            Self::Stopped { time, steps } => write!(
                f,
                "stopped by the caller at {time} s ({steps} steps), before the spheres came to rest"
            ),
        }
    }
}

impl core::error::Error for PourError {}

/// Caller-owned buffers of the pour: sphere buffers have `granules`
/// entries, the two pair buffers the same capacity (≥ 8 × granules is
/// ample), `head` [`Grid::cells`] of [`PourParams::grid`].
pub struct PourBuffers<'a> {
    /// Centres, m.
    pub x: &'a mut [[Real; 3]],
    /// Velocities, m/s.
    pub v: &'a mut [[Real; 3]],
    /// Angular velocities, rad/s.
    pub omega: &'a mut [[Real; 3]],
    /// Forces of the last evaluation, N, turned into the half kick
    /// Δt/2 · F/m (m/s) once complete: both half kicks around a force
    /// evaluation add the same increment, so it is divided out once.
    pub f: &'a mut [[Real; 3]],
    /// Torques of the last evaluation, N m, turned into the half kick
    /// Δt/2 · T/I (rad/s) like `f`.
    pub torque: &'a mut [[Real; 3]],
    /// Centres when the pair list was built, m.
    pub x_built: &'a mut [[Real; 3]],
    /// Candidate pairs (current list).
    pub pairs: &'a mut [Pair],
    /// Candidate pairs (the previous list; scratch).
    pub pairs_old: &'a mut [Pair],
    /// Grid cell heads (scratch).
    pub head: &'a mut [u32],
    /// Grid chains (scratch, one per sphere).
    pub next: &'a mut [u32],
}

/// A snapshot of the pour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PourStatus {
    /// Simulated time, s.
    pub time: Real,
    /// Steps taken.
    pub steps: u64,
    /// Total kinetic energy (translation + rotation), J.
    pub kinetic_energy: Real,
    /// Largest sphere speed, m/s.
    pub max_speed: Real,
    /// Highest sphere top max(z) + r, m.
    pub height: Real,
    /// Floor reaction (upward), N.
    pub floor_force: Real,
    /// Vertical friction force of the die wall on the spheres (upward
    /// positive), N.
    pub wall_friction_z: Real,
    /// Candidate pairs in the list.
    pub pairs: usize,
    /// True once every sphere is at rest (checked after the ramp has begun).
    pub settled: bool,
}

/// The running pour.
pub struct PourScene<'a> {
    p: PourParams,
    buf: PourBuffers<'a>,
    grid: Grid,
    law_pp: ContactLaw,
    law_pw: ContactLaw,
    mass: Real,
    inertia: Real,
    /// Damping β at the start and the end of the ramp.
    beta: (Real, Real),
    dt: Real,
    time: Real,
    steps: u64,
    n_pairs: usize,
    floor_force: Real,
    wall_friction_z: Real,
}

impl<'a> PourScene<'a> {
    /// Places the spheres on the jittered lattice with random velocities
    /// (from `params.seed`), builds the pair list and the first forces.
    pub fn new(params: PourParams, buf: PourBuffers<'a>) -> Result<Self, PourError> {
        Self::start(params, buf, true)
    }

    /// Starts from the positions and velocities already in `buf.x` and
    /// `buf.v` (for tests and custom layouts); nothing is placed.
    pub fn from_state(params: PourParams, buf: PourBuffers<'a>) -> Result<Self, PourError> {
        Self::start(params, buf, false)
    }

    fn start(params: PourParams, buf: PourBuffers<'a>, place: bool) -> Result<Self, PourError> {
        params.validate()?;
        let n = params.granules;
        let grid = params.grid();
        let cap = buf.pairs.len();
        for (buffer, got, expected) in [
            ("x", buf.x.len(), n),
            ("v", buf.v.len(), n),
            ("omega", buf.omega.len(), n),
            ("f", buf.f.len(), n),
            ("torque", buf.torque.len(), n),
            ("x_built", buf.x_built.len(), n),
            ("next", buf.next.len(), n),
            ("head", buf.head.len(), grid.cells()),
            ("pairs_old", buf.pairs_old.len(), cap),
        ] {
            if got != expected {
                return Err(PourError::BufferLength {
                    buffer,
                    expected,
                    got,
                });
            }
        }
        let mut rng = Rng::new(params.seed);
        let sites = params.sites().count();
        let placed = if place { buf.x.len() } else { 0 };
        for (k, (x, v)) in buf
            .x
            .iter_mut()
            .zip(buf.v.iter_mut())
            .take(placed)
            .enumerate()
        {
            let site = params.sites().nth(k % sites).unwrap_or([0.0; 2]);
            let layer = (k / sites) as Real;
            let z = params.radius + params.jitter + layer * params.lattice_spacing;
            let j = params.jitter;
            *x = [
                site[0] + rng.uniform(-j, j),
                site[1] + rng.uniform(-j, j),
                z + rng.uniform(-j, j),
            ];
            let s = params.initial_speed;
            *v = [rng.uniform(-s, s), rng.uniform(-s, s), rng.uniform(-s, s)];
        }
        buf.omega.fill([0.0; 3]);
        let mass = params.mass();
        let law_pp = ContactLaw::sphere_sphere(
            params.youngs_modulus_pa,
            params.poisson_ratio,
            params.radius,
            mass,
            params.friction_particle,
        );
        let law_pw = ContactLaw::sphere_wall(
            params.youngs_modulus_pa,
            params.poisson_ratio,
            params.radius,
            mass,
            params.friction_wall,
        );
        let mut scene = Self {
            dt: params.time_step_fraction * params.contact_time(),
            p: params,
            buf,
            grid,
            law_pp,
            law_pw,
            mass,
            inertia: 0.4 * mass * params.radius * params.radius,
            beta: (
                hertz_beta(params.restitution_start),
                hertz_beta(params.restitution_end),
            ),
            time: 0.0,
            steps: 0,
            n_pairs: 0,
            floor_force: 0.0,
            wall_friction_z: 0.0,
        };
        scene.rebuild()?;
        scene.forces();
        Ok(scene)
    }

    /// The time step, s.
    pub fn time_step(&self) -> Real {
        self.dt
    }

    /// Sphere centres, m.
    pub fn positions(&self) -> &[[Real; 3]] {
        self.buf.x
    }

    /// The current candidate pairs (sorted by (i, j)).
    pub fn pairs(&self) -> &[Pair] {
        &self.buf.pairs[..self.n_pairs]
    }

    /// The parameters.
    pub fn params(&self) -> &PourParams {
        &self.p
    }

    fn rebuild(&mut self) -> Result<(), PourError> {
        let b = &mut self.buf;
        let old_len = self.n_pairs;
        b.pairs_old[..old_len].copy_from_slice(&b.pairs[..old_len]);
        let mut scratch = GridScratch {
            head: b.head,
            next: b.next,
        };
        self.n_pairs = build_pairs(
            &self.grid,
            b.x,
            self.p.radius,
            2.0 * self.p.radius + self.p.skin,
            &mut scratch,
            &b.pairs_old[..old_len],
            b.pairs,
        )
        .map_err(PourError::Pairs)?;
        b.x_built.copy_from_slice(b.x);
        Ok(())
    }

    fn ramp(&self, start: Real, end: Real) -> Real {
        let (t0, t1) = self.p.ramp;
        let s = ((self.time - t0) / (t1 - t0)).clamp(0.0, 1.0);
        start + (end - start) * s
    }

    /// Forces and torques at the current positions and velocities.
    ///
    /// Every force is summed in the order of the sorted pair list; sphere
    /// i's own sums are kept in registers over its run of pairs (the pairs
    /// (k, i) with k < i all come earlier), which adds in the same order.
    fn forces(&mut self) {
        let c = self.ramp(0.0, self.p.damping_max);
        // β is ramped linearly between the values that give the start and
        // end restitutions exactly.
        let beta = self.ramp(self.beta.0, self.beta.1);
        let (m, inertia, g, r, dt) = (
            self.mass,
            self.inertia,
            self.p.gravity_m_s2,
            self.p.radius,
            self.dt,
        );
        let (law_pp, law_pw, die_radius) = (&self.law_pp, &self.law_pw, self.p.die_radius);
        let b = &mut self.buf;
        let (cm, ci, mg) = (-c * m, -c * inertia, m * g);
        for (((f, t), v), w) in
            b.f.iter_mut()
                .zip(b.torque.iter_mut())
                .zip(b.v.iter())
                .zip(b.omega.iter())
        {
            *f = [cm * v[0], cm * v[1], cm * v[2] - mg];
            *t = [ci * w[0], ci * w[1], ci * w[2]];
        }
        let (x, v, omega) = (&*b.x, &*b.v, &*b.omega);
        let (f, torque) = (&mut *b.f, &mut *b.torque);
        let two_r = 2.0 * r;
        // Cheap rejections before any square root, with a margin far above
        // round-off: beyond these the exact tests below fail anyway.
        let apart2 = two_r * two_r * (1.0 + 1e-12);
        let inside = die_radius - r;
        let inside2 = if inside > 0.0 {
            inside * inside * (1.0 - 1e-12)
        } else {
            0.0
        };
        let (mut floor, mut wall_z) = (0.0, 0.0);
        // Sphere i of the current run of pairs and its running sums.
        let mut cur = usize::MAX;
        let (mut fi, mut ti) = ([0.0; 3], [0.0; 3]);
        // Contacts found in pair order wait in `lanes` (pair index in `at`)
        // until LANES of them can be evaluated together; their forces are
        // then added in pair order.
        let mut lanes = ContactLanes::<LANES>::ZERO;
        let mut at = [0usize; LANES];
        let mut filled = 0;
        let pairs = &mut b.pairs[..self.n_pairs];
        let last = pairs.len();
        for k in 0..=last {
            if k < last {
                let pair = &mut pairs[k];
                let i = pair.i as usize;
                let xi = x[i];
                let (n, delta, law, vj, wj) = match pair.j {
                    FLOOR => ([0.0, 0.0, 1.0], r - xi[2], law_pw, [0.0; 3], [0.0; 3]),
                    DIE => {
                        let rr2 = xi[0] * xi[0] + xi[1] * xi[1];
                        if rr2 < inside2 {
                            pair.xi = [0.0; 3];
                            continue;
                        }
                        let rr = math::sqrt(rr2);
                        let n = if rr > 0.0 {
                            [-xi[0] / rr, -xi[1] / rr, 0.0]
                        } else {
                            [1.0, 0.0, 0.0]
                        };
                        (n, rr + r - die_radius, law_pw, [0.0; 3], [0.0; 3])
                    }
                    j => {
                        let xj = x[j as usize];
                        let d = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
                        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        if d2 > apart2 {
                            pair.xi = [0.0; 3];
                            continue;
                        }
                        let dist = math::sqrt(d2);
                        let n = if dist > 0.0 {
                            d.map(|c| c / dist)
                        } else {
                            [0.0, 0.0, 1.0]
                        };
                        (n, two_r - dist, law_pp, v[j as usize], omega[j as usize])
                    }
                };
                if delta <= 0.0 {
                    pair.xi = [0.0; 3];
                    continue;
                }
                let (vi, wi) = (v[i], omega[i]);
                let l = filled;
                lanes.set_law(l, law);
                lanes.delta[l] = delta;
                for a in 0..3 {
                    lanes.n[a][l] = n[a];
                    lanes.dv[a][l] = vi[a] - vj[a];
                    lanes.w[a][l] = wi[a] + wj[a];
                    lanes.xi[a][l] = pair.xi[a];
                }
                at[l] = k;
                filled += 1;
                if filled < LANES {
                    continue;
                }
            } else if filled == 0 {
                break;
            }
            // Evaluate the waiting contacts (at the end, the unused lanes
            // repeat old inputs and are ignored).
            hertz_mindlin_lanes(&mut lanes, beta, r, dt);
            for l in 0..filled {
                let pair = &mut pairs[at[l]];
                let i = pair.i as usize;
                if i != cur {
                    if cur != usize::MAX {
                        f[cur] = fi;
                        torque[cur] = ti;
                    }
                    cur = i;
                    (fi, ti) = (f[i], torque[i]);
                }
                let force = [lanes.force[0][l], lanes.force[1][l], lanes.force[2][l]];
                let t = [lanes.torque[0][l], lanes.torque[1][l], lanes.torque[2][l]];
                pair.xi = [lanes.xi[0][l], lanes.xi[1][l], lanes.xi[2][l]];
                for a in 0..3 {
                    fi[a] += force[a];
                    ti[a] += t[a];
                }
                match pair.j {
                    FLOOR => floor += force[2],
                    DIE => wall_z += force[2],
                    j => {
                        let (fj, tj) = (&mut f[j as usize], &mut torque[j as usize]);
                        for a in 0..3 {
                            fj[a] -= force[a];
                            tj[a] += t[a];
                        }
                    }
                }
            }
            filled = 0;
        }
        if cur != usize::MAX {
            f[cur] = fi;
            torque[cur] = ti;
        }
        self.floor_force = floor;
        self.wall_friction_z = wall_z;
        // The half kicks Δt/2 · F/m and Δt/2 · T/I, as velocity Verlet adds
        // them (the same operations, so the same bits, as dividing in each
        // of the two kicks).
        let half = 0.5 * dt;
        for (fk, tk) in f.iter_mut().zip(torque.iter_mut()) {
            for a in 0..3 {
                fk[a] = half * fk[a] / m;
                tk[a] = half * tk[a] / inertia;
            }
        }
    }

    /// Half a kick of the velocities and spins by the current forces
    /// (already turned into velocity increments by [`Self::forces`]).
    fn kick(&mut self) {
        let b = &mut self.buf;
        for (((v, w), dv), dw) in
            b.v.iter_mut()
                .zip(b.omega.iter_mut())
                .zip(b.f.iter())
                .zip(b.torque.iter())
        {
            for a in 0..3 {
                v[a] += dv[a];
                w[a] += dw[a];
            }
        }
    }

    /// One velocity-Verlet step.
    pub fn step(&mut self) -> Result<(), PourError> {
        let dt = self.dt;
        let b = &mut self.buf;
        let mut moved: Real = 0.0;
        // Half kick and drift.
        for (((x, v), (w, xb)), (dv, dw)) in
            b.x.iter_mut()
                .zip(b.v.iter_mut())
                .zip(b.omega.iter_mut().zip(b.x_built.iter()))
                .zip(b.f.iter().zip(b.torque.iter()))
        {
            // The new values from registers, not read back from `v` and `x`:
            // a vector load of scalars just stored stalls on store forwarding
            // (in an AVX2 build it doubled this loop's time). The same bits.
            let kicked: [Real; 3] = core::array::from_fn(|a| v[a] + dv[a]);
            *v = kicked;
            for a in 0..3 {
                w[a] += dw[a];
            }
            let moved_to: [Real; 3] = core::array::from_fn(|a| x[a] + dt * kicked[a]);
            *x = moved_to;
            let d: [Real; 3] = core::array::from_fn(|a| moved_to[a] - xb[a]);
            moved = moved.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
        if !moved.is_finite() {
            return Err(PourError::Unstable { step: self.steps });
        }
        self.time += dt;
        self.steps += 1;
        // Rebuild once any sphere may have crossed half the skin.
        if 4.0 * moved > self.p.skin * self.p.skin {
            self.rebuild()?;
        }
        self.forces();
        self.kick();
        Ok(())
    }

    /// The current state.
    pub fn status(&self) -> PourStatus {
        let b = &self.buf;
        let (mut ke, mut vmax, mut top) = (0.0, 0.0 as Real, Real::NEG_INFINITY);
        for ((v, w), x) in b.v.iter().zip(b.omega.iter()).zip(b.x.iter()) {
            let v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            ke += 0.5 * self.mass * v2
                + 0.5 * self.inertia * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
            vmax = vmax.max(math::sqrt(v2));
            top = top.max(x[2] + self.p.radius);
        }
        // At rest is at rest, whether or not the damping ramp has finished:
        // a falling or bouncing bed never has every speed below 1e-5 m/s.
        let settled = self.time > self.p.ramp.0
            && vmax < self.p.rest_speed
            && ke < self.p.rest_kinetic_energy * b.x.len() as Real;
        PourStatus {
            time: self.time,
            steps: self.steps,
            kinetic_energy: ke,
            max_speed: vmax,
            height: top,
            floor_force: self.floor_force,
            wall_friction_z: self.wall_friction_z,
            pairs: self.n_pairs,
            settled,
        }
    }

    /// Steps until the spheres are at rest (checked every `check` steps)
    /// or `max_time` passes. `on_check` sees the state at every check (for
    /// progress) and may stop the pour there by returning
    /// [`ControlFlow::Break`] ([`PourError::Stopped`]; a host's interrupt:
    /// a pour of many spheres runs for minutes), unless it is at rest
    /// there. A stopped scene keeps its state: `run_to_rest` again goes on
    /// as if it had not stopped.
    pub fn run_to_rest(
        &mut self,
        check: u64,
        on_check: &mut dyn FnMut(&PourStatus) -> ControlFlow<()>,
    ) -> Result<PourStatus, PourError> {
        loop {
            for _ in 0..check.max(1) {
                self.step()?;
            }
            let s = self.status();
            let flow = on_check(&s);
            if s.settled {
                return Ok(s);
            }
            if flow.is_break() {
                return Err(PourError::Stopped {
                    time: s.time,
                    steps: s.steps,
                });
            }
            if s.time > self.p.max_time {
                return Err(PourError::NotSettled {
                    time: s.time,
                    max_speed: s.max_speed,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The field a rejected parameter set names.
    fn rejected(p: PourParams) -> &'static str {
        match p.validate() {
            Err(PourError::InvalidParameter { field, .. }) => field,
            other => panic!("expected a rejection, got {other:?}"),
        }
    }

    /// Values no pour could finish with are refused by name before the
    /// lattice is walked: an infinite die (its sites were walked without
    /// end), an infinite lattice spacing (its grid's cell count
    /// overflowed), an infinite time limit, and non-finite forces, speeds
    /// and skins.
    #[test]
    fn infinite_and_vast_parameters_are_refused_by_name() {
        let standard = PourParams::standard(1200.0, 1);
        assert_eq!(standard.validate(), Ok(()));
        let with = |f: fn(&mut PourParams)| {
            let mut p = standard;
            f(&mut p);
            rejected(p)
        };
        assert_eq!(with(|p| p.die_radius = Real::INFINITY), "die_radius");
        assert_eq!(
            with(|p| p.die_radius = 2e4 * p.lattice_spacing),
            "die_radius"
        );
        assert_eq!(
            with(|p| p.lattice_spacing = Real::INFINITY),
            "lattice_spacing"
        );
        assert_eq!(with(|p| p.lattice_spacing = Real::NAN), "lattice_spacing");
        assert_eq!(with(|p| p.gravity_m_s2 = Real::INFINITY), "gravity_m_s2");
        assert_eq!(with(|p| p.max_time = Real::INFINITY), "max_time");
        assert_eq!(with(|p| p.skin = Real::INFINITY), "skin");
        assert_eq!(with(|p| p.skin = 0.0), "skin");
        assert_eq!(with(|p| p.skin = 1.01 * p.radius), "skin");
        assert_eq!(with(|p| p.initial_speed = Real::NAN), "initial_speed");
        assert_eq!(with(|p| p.damping_max = Real::INFINITY), "damping_max");
        assert_eq!(with(|p| p.rest_speed = 0.0), "rest_speed");
        assert_eq!(
            with(|p| p.rest_kinetic_energy = Real::NAN),
            "rest_kinetic_energy"
        );
        // A die of a thousand lattice spacings still validates (its layer
        // is walked; the bound is ten times wider).
        let mut wide = standard;
        wide.die_radius = 1e3 * wide.lattice_spacing;
        assert_eq!(wide.validate(), Ok(()));
    }

    /// The grid and the fill height come back for parameters `validate`
    /// refuses, as a host sizing its buffers before the pour asks for them
    /// (a lattice spacing of 0 or 1 nm, or an infinite die, walked the
    /// lattice without end: the kernel API review of session 55).
    #[test]
    fn the_grid_of_refused_parameters_comes_back() {
        let standard = PourParams::standard(1200.0, 1);
        for (p, field) in [
            (
                PourParams {
                    lattice_spacing: 0.0,
                    ..standard
                },
                "lattice_spacing",
            ),
            (
                PourParams {
                    lattice_spacing: 1e-9,
                    ..standard
                },
                "lattice_spacing",
            ),
            (
                PourParams {
                    die_radius: Real::INFINITY,
                    ..standard
                },
                "die_radius",
            ),
        ] {
            assert_eq!(rejected(p), field);
            // A hang here is the failure; the figures are what they can be.
            assert!(p.grid().cells() >= 1, "{field}");
            assert!(p.fill_height() > 0.0, "{field}");
        }
    }

    /// A grid too large to count says so with `usize::MAX` instead of
    /// overflowing.
    #[test]
    fn a_grid_too_large_to_count_saturates() {
        let g = Grid {
            cell: 1.0,
            nxy: usize::MAX / 2,
            nz: 3,
            half_width: 1.0,
        };
        assert_eq!(g.cells(), usize::MAX);
    }
}
