//! One explicit step of an assembly (see the module docs of `assembly`),
//! its errors and its energy ledger.

use core::fmt;

use granbed_kernel::Real;
use granbed_kernel::contact::pair::ContactError;
use granbed_kernel::contact::rigid::RigidShift;
use granbed_kernel::contact::wall::{PredictedNodes, WallForce, wall_contact};
use granbed_kernel::granule::damping::{RigidFrame, selective_contact_masses};
use granbed_kernel::granule::dynamics::{
    Loads, StepSizes, StepWork, correct_in, predict_in, predict_rigid,
};
use granbed_kernel::granule::forces::{ForceSummary, ForcesError, elastic_energy};
use granbed_kernel::granule::quality::worst_element;
use granbed_kernel::granule::timestep::{Linearisation, PowerIterationBuffers, TimeStepMethod};
use rayon::prelude::*;

use super::{Assembly, AssemblyParams, MAX_CONTACT_SEARCH_INTERVAL, granule_kinetic, set_masses};

/// Why an assembly cannot be set up or stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum AssemblyError {
    /// A parameter is out of range.
    InvalidParameter {
        /// The parameter.
        field: &'static str,
        /// Its value.
        value: Real,
        /// The allowed range.
        allowed: &'static str,
    },
    /// An element failed (inverted, no convergence).
    Element {
        /// Granule index.
        granule: usize,
        /// Step.
        step: u64,
        /// The element and what went wrong.
        failure: ForcesError,
    },
    /// The contact phase could not proceed.
    Contact {
        /// Step.
        step: u64,
        /// What went wrong.
        error: ContactError,
    },
    /// The watchdog: a node moved faster than
    /// [`AssemblyParams::max_node_speed_m_s`] — the run is going unstable.
    Runaway {
        /// Step.
        step: u64,
        /// The first granule over the limit (in granule order).
        granule: usize,
        /// Its fastest node's speed, m/s.
        speed_m_s: Real,
        /// The limit, m/s.
        limit_m_s: Real,
    },
    /// The energy watchdog: the kinetic energy exceeds
    /// [`AssemblyParams::kinetic_energy_limit`] × all the energy ever put in (punch or,
    /// where larger, contact work — the release of initial overlaps —,
    /// gravity work, initial motion). Physically it cannot exceed it once;
    /// a growing numerical instability makes it do so within a few steps.
    EnergyRunaway {
        /// Step.
        step: u64,
        /// The granule with the most kinetic energy.
        granule: usize,
        /// Kinetic energy of the assembly, J.
        kinetic_j: Real,
        /// Energy put in so far, J.
        supplied_j: Real,
        /// The limit's factor.
        limit: Real,
    },
    /// An element folded: a Gauss-point Jacobian of its trilinear map is
    /// not positive (the one-point element's centre may still be fine;
    /// found when the stable step is estimated).
    Folded {
        /// Step.
        step: u64,
        /// Granule.
        granule: usize,
        /// Element (hex) index.
        element: usize,
        /// Its smallest Gauss-point Jacobian ratio J_g(x)/J_g(X).
        ratio: Real,
    },
    /// The stable step could not be estimated or the motion blew up.
    Unstable {
        /// Step.
        step: u64,
        /// The first granule found inverted or non-finite, if known.
        granule: Option<usize>,
    },
}

impl fmt::Display for AssemblyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParameter {
                field,
                value,
                allowed,
            } => write!(f, "{field} = {value} is out of range (allowed: {allowed})"),
            Self::Element {
                granule,
                step,
                failure,
            } => write!(f, "granule {granule}, step {step}: {failure}"),
            Self::Contact { step, error } => write!(f, "step {step}: {error}"),
            Self::Runaway {
                step,
                granule,
                speed_m_s,
                limit_m_s,
            } => write!(
                f,
                "step {step}: granule {granule} has a node moving at {speed_m_s:.4e} m/s, over \
                 the watchdog limit of {limit_m_s:.4e} m/s: the motion is going unstable (is the \
                 time-step safety factor too large?)"
            ),
            Self::EnergyRunaway {
                step,
                granule,
                kinetic_j,
                supplied_j,
                limit,
            } => write!(
                f,
                "step {step}: the kinetic energy {kinetic_j:.4e} J (most of it in granule \
                 {granule}) exceeds {limit} × the {supplied_j:.4e} J put in by the \
                 punches (or contacts), gravity and the initial motion: the motion is going unstable (is the \
                 time-step safety factor too large?)"
            ),
            Self::Folded {
                step,
                granule,
                element,
                ratio,
            } => write!(
                f,
                "granule {granule}, step {step}: element {element} folded (Gauss-point Jacobian \
                 ratio {ratio:.3e} <= 0: hourglass distortion)"
            ),
            Self::Unstable { step, granule } => match granule {
                Some(g) => write!(
                    f,
                    "step {step}: granule {g} became unstable (inverted or non-finite)"
                ),
                None => write!(f, "step {step}: the motion became unstable"),
            },
        }
    }
}

impl core::error::Error for AssemblyError {}

pub(super) fn validate(p: &AssemblyParams) -> Result<(), AssemblyError> {
    let global = matches!(p.time_step_method, TimeStepMethod::Global { .. });
    let checks: [(bool, &'static str, Real, &'static str); 18] = [
        (
            p.exact_contact_from_s >= 0.0,
            "exact_contact_from_s",
            p.exact_contact_from_s,
            ">= 0 s (inf: never)",
        ),
        (
            (0.0..=1.0).contains(&p.face_list_skin),
            "face_list_skin",
            p.face_list_skin,
            "0 <= s <= 1 (0: no face lists)",
        ),
        (
            (1.0..=1e6).contains(&p.mass_scaling),
            "mass_scaling",
            p.mass_scaling,
            "1 <= F <= 1e6",
        ),
        (
            p.selective_mass_ratio >= 1.0,
            "selective_mass_ratio",
            p.selective_mass_ratio,
            ">= 1 (inf: physical rigid modes)",
        ),
        (
            (1..=50).contains(&p.contact_sweeps),
            "contact_sweeps",
            Real::from(p.contact_sweeps),
            "1..=50",
        ),
        (
            (1..=MAX_CONTACT_SEARCH_INTERVAL).contains(&p.contact_search_interval),
            "contact_search_interval",
            Real::from(p.contact_search_interval),
            "1..=10",
        ),
        (
            p.contact_search_interval == 1 || p.hold_constraints,
            "contact_search_interval",
            Real::from(p.contact_search_interval),
            "1 unless hold_constraints (the steps between searches hold their constraints)",
        ),
        (
            (0.0..=2.0).contains(&p.damping_ratio),
            "damping_ratio",
            p.damping_ratio,
            "0 <= xi <= 2",
        ),
        (
            p.gravity_m_s2 >= 0.0 && p.gravity_m_s2.is_finite(),
            "gravity_m_s2",
            p.gravity_m_s2,
            ">= 0",
        ),
        (
            p.wall_friction >= 0.0 && p.wall_friction.is_finite(),
            "wall_friction",
            p.wall_friction,
            ">= 0",
        ),
        (
            p.contact.friction >= 0.0 && p.contact.friction.is_finite(),
            "friction",
            p.contact.friction,
            ">= 0",
        ),
        (
            p.contact.window_fraction > 0.0 && p.contact.window_fraction <= 1.0,
            "window_fraction",
            p.contact.window_fraction,
            "0 < f <= 1",
        ),
        (
            p.contact.margin > 0.0 && p.contact.margin.is_finite(),
            "margin",
            p.contact.margin,
            "> 0 m",
        ),
        (
            p.time_step_safety > 0.0
                && p.time_step_safety <= granbed_kernel::granule::timestep::MAX_SAFETY
                && p.time_step_interval >= 1,
            "time_step_safety",
            p.time_step_safety,
            "0 < C <= 2 (and an interval >= 1)",
        ),
        (
            p.time_step_floor == 0.0
                || (p.time_step_floor > 0.0 && p.time_step_floor <= 1.0 && global),
            "time_step_floor",
            p.time_step_floor,
            "0 (off) or 0 < r <= 1, with the global time-step method",
        ),
        (
            p.max_mass_factor >= 1.0 && p.max_mass_factor.is_finite(),
            "max_mass_factor",
            p.max_mass_factor,
            ">= 1 and finite",
        ),
        (
            p.max_node_speed_m_s > 0.0,
            "max_node_speed_m_s",
            p.max_node_speed_m_s,
            "> 0 m/s (inf: no watchdog)",
        ),
        (
            p.kinetic_energy_limit >= 1.0,
            "kinetic_energy_limit",
            p.kinetic_energy_limit,
            ">= 1 (inf: no watchdog)",
        ),
    ];
    match checks.into_iter().find(|c| !c.0) {
        Some((_, field, value, allowed)) => Err(AssemblyError::InvalidParameter {
            field,
            value,
            allowed,
        }),
        None => Ok(()),
    }
}

/// Energy ledger of the whole assembly since the start, J.
///
/// Central differences balance exactly:
/// `kinetic − supplied_kinetic + internal_work + damping = contact_work +
/// gravity_work` to round-off ([`Energies::residual`]). `punch_work` is what the moving
/// walls put in (Σ F_n v Δt); kinematic contact can only take energy out,
/// so `contact_work ≤ punch_work` ([`Energies::contact_loss`] ≥ 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energies {
    /// Work of the internal + hourglass forces.
    pub internal_work: Real,
    /// Work of every contact force on the nodes (pairs and walls).
    pub contact_work: Real,
    /// Work of the moving walls, Σ F_n v Δt.
    pub punch_work: Real,
    /// Energy removed by damping.
    pub damping: Real,
    /// Work of gravity.
    pub gravity_work: Real,
    /// Kinetic energy at n+½.
    pub kinetic: Real,
    /// Kinetic energy not put in by a force: that of the initial
    /// velocities, plus what raising a moving granule's masses added
    /// (variable mass scaling, [`AssemblyParams::time_step_floor`], which
    /// keeps the velocities: (k − 1) × the granule's kinetic energy).
    pub supplied_kinetic: Real,
    /// Plastic dissipation.
    pub plastic: Real,
    /// Hourglass energy (current).
    pub hourglass: Real,
    /// Elastic energy Ψ (updated by [`Assembly::elastic_energy`]).
    pub elastic: Real,
}

impl Energies {
    /// ΔK + internal + damping − contact − gravity (round-off).
    pub fn residual(&self) -> Real {
        self.kinetic - self.supplied_kinetic + self.internal_work + self.damping
            - self.contact_work
            - self.gravity_work
    }

    /// Energy the contacts took out of what the walls put in:
    /// punch_work − contact_work (≥ 0: contact never injects energy).
    pub fn contact_loss(&self) -> Real {
        self.punch_work - self.contact_work
    }

    /// internal_work − (Ψ + D_p + E_hg): the return map's energy gap.
    pub fn return_map_gap(&self) -> Real {
        self.internal_work - (self.elastic + self.plastic + self.hourglass)
    }
}

/// Wall-clock time spent in each phase of the steps so far, s (for
/// benchmarks; not part of the physics).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    /// Element forces, damping and the predictor.
    pub predict_s: f64,
    /// Contact: broad phase, detection, forces, gather, walls (all sweeps).
    pub contact_s: f64,
    /// The corrector and the energy sums.
    pub correct_s: f64,
    /// Contact sweeps run (over all steps).
    pub sweeps: u64,
    /// Granule-steps taken as rigid bodies, without element work
    /// ([`super::AssemblyParams::rigid_until_touched`]).
    pub rigid_granule_steps: u64,
    /// Steps timed.
    pub steps: u64,
    /// Face-list builds (a pair's two passes count one); filled by
    /// `Assembly::times`.
    pub list_builds: u64,
    /// Face-list anchor renewals (a granule whose x̃ left its anchor by
    /// more than the skin).
    pub anchor_renewals: u64,
    /// Pair searches (detections) over all sweeps; filled by
    /// `Assembly::times`.
    pub pair_searches: u64,
}

/// The phase times and counters of two segments of a run, summed (a
/// resumed run adds its checkpoint's to its own).
impl core::ops::Add for PhaseTimes {
    type Output = Self;

    fn add(self, b: Self) -> Self {
        Self {
            predict_s: self.predict_s + b.predict_s,
            contact_s: self.contact_s + b.contact_s,
            correct_s: self.correct_s + b.correct_s,
            sweeps: self.sweeps + b.sweeps,
            rigid_granule_steps: self.rigid_granule_steps + b.rigid_granule_steps,
            steps: self.steps + b.steps,
            list_builds: self.list_builds + b.list_builds,
            anchor_renewals: self.anchor_renewals + b.anchor_renewals,
            pair_searches: self.pair_searches + b.pair_searches,
        }
    }
}

impl PhaseTimes {
    /// Share of the contact phase in the total.
    pub fn contact_share(&self) -> f64 {
        self.contact_s / (self.predict_s + self.contact_s + self.correct_s)
    }

    /// Share of the granule-steps that skipped the element work, of
    /// `granules` granules over the timed steps (None for none).
    pub fn rigid_share(&self, granules: usize) -> Option<f64> {
        let all = self.steps * granules as u64;
        (all > 0).then(|| self.rigid_granule_steps as f64 / all as f64)
    }

    /// Sweeps per step over `steps` steps (None for none).
    pub fn sweeps_per_step(&self) -> Option<f64> {
        self.per_step(self.sweeps)
    }

    /// `count` per timed step (None for none).
    pub fn per_step(&self, count: u64) -> Option<f64> {
        (self.steps > 0).then(|| count as f64 / self.steps as f64)
    }
}

/// What the last step did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Step size Δt_{n+½}, s.
    pub dt: Real,
    /// Smallest element Jacobian ratio.
    pub min_j: Real,
    /// Per wall (in wall order), the summed contact result over granules.
    pub walls: Vec<WallForce>,
    /// Σ F_n of the granule–granule constraints (all sweeps), N.
    pub pair_normal: Real,
    /// Granule–granule constraints of the first sweep.
    pub constraints: usize,
    /// Distinct (granule, wall) pairs in contact in the step.
    pub wall_contacts: usize,
    /// Largest nodal speed |v_{n+½}| over all granules, m/s.
    pub max_node_speed_m_s: Real,
}

/// A granule's loads when variable mass scaling has put k on its masses:
/// gravity g/k keeps its weight, damping c/√k its damping ratio (c = 2ξω₁
/// and ω₁ falls by √k). k = 1: `loads` as they are.
fn loads_for_mass_factor(loads: &Loads, k: Real) -> Loads {
    if k == 1.0 {
        return *loads;
    }
    Loads {
        gravity_m_s2: loads.gravity_m_s2 / k,
        damping_c: loads.damping_c / k.sqrt(),
        ..*loads
    }
}

/// Adds the forces of `w` to `total`; the contact count is summed
/// (`sum_contacts`, over granules) or the larger is kept (over sweeps of
/// one granule, which see the same nodes again).
fn add_wall(total: &mut WallForce, w: &WallForce, sum_contacts: bool) {
    total.normal += w.normal;
    for (t, f) in total.tangential.iter_mut().zip(w.tangential) {
        *t += f;
    }
    total.contacts = if sum_contacts {
        total.contacts + w.contacts
    } else {
        total.contacts.max(w.contacts)
    };
    total.min_gap = total.min_gap.min(w.min_gap);
    for (t, v) in total.virial.iter_mut().zip(w.virial) {
        for (t, v) in t.iter_mut().zip(v) {
            *t += v;
        }
    }
}

impl Assembly<'_> {
    /// The stable step: the smallest of the granules' estimates
    /// (`time_step_method` × `time_step_safety`), reduced for the damping.
    pub(super) fn stable_step(&mut self) -> Result<Real, AssemblyError> {
        let view = self.mesh.view();
        let p = self.params;
        let (nodes, states) = (
            self.mesh.positions.len(),
            self.mesh.hexes.len() * p.elements.points_per_element(),
        );
        let per: Vec<Option<Real>> = self
            .granules
            .par_iter()
            .zip(self.time_steps.par_iter_mut())
            .zip(self.modes.par_iter_mut())
            .map_init(
                || PowerScratch::new(nodes, states),
                |scratch, ((g, control), mode)| {
                    let at = Linearisation {
                        mass: &g.mass,
                        x: &g.x,
                        cp_inv: &g.cp_inv,
                    };
                    let mut buffers = PowerIterationBuffers {
                        mode,
                        x_pert: &mut scratch.x_pert,
                        f_plus: &mut scratch.f_plus,
                        f_minus: &mut scratch.f_minus,
                        cp_scratch: &mut scratch.cp_scratch,
                    };
                    control.estimate(&view, &p.material, &p.elements, &at, &mut buffers)
                },
            )
            .collect();
        let mut steps = Vec::with_capacity(per.len());
        for (g, d) in per.into_iter().enumerate() {
            match d {
                Some(d) if d > 0.0 && d.is_finite() => steps.push(d),
                _ => {
                    let step = self.steps;
                    return Err(match worst_element(&view, &self.granules[g].x) {
                        Some(w) if w.ratio <= 0.0 => AssemblyError::Folded {
                            step,
                            granule: g,
                            element: w.element,
                            ratio: w.ratio,
                        },
                        _ => AssemblyError::Unstable {
                            step,
                            granule: Some(g),
                        },
                    });
                }
            }
        }
        if self.undeformed_step == 0.0 {
            // The first estimate, in `Assembly::new`: every granule is the
            // undeformed reference, placed.
            self.undeformed_step = steps.iter().copied().fold(Real::INFINITY, Real::min);
        } else if p.time_step_floor > 0.0 {
            self.lift_to_floor(&mut steps);
        }
        let dt = steps.iter().copied().fold(Real::INFINITY, Real::min);
        if !dt.is_finite() {
            return Ok(1.0);
        }
        // The lagged damping force shrinks the stable step of central
        // differences to Ω² < 4 − 2cΔt (Ω = ω_max Δt): scale by
        // √(1 − cΔt/2). Without it a regular hex cube diverged at C = 0.85.
        Ok(dt * (1.0 - 0.5 * self.damping_c * dt).max(0.25).sqrt())
    }

    /// Variable mass scaling ([`AssemblyParams::time_step_floor`]): gives
    /// each granule whose step in `steps` lies below the floor the least
    /// factor on its masses that lifts it there (at most
    /// `max_mass_factor`), and its new step. The velocities are kept; the
    /// kinetic energy the heavier masses give them is booked as supplied.
    /// Granules in index order, so the ledger's sums are the same for any
    /// thread count.
    pub(super) fn lift_to_floor(&mut self, steps: &mut [Real]) {
        let p = self.params;
        let floor = p.time_step_floor * self.undeformed_step;
        let selective = p.selective_mass_factor();
        for (g, d) in steps.iter_mut().enumerate() {
            let old = self.mass_factors[g];
            if *d >= floor || old >= p.max_mass_factor {
                continue;
            }
            let lift = floor / *d;
            let k = (old * lift * lift).min(p.max_mass_factor);
            if k <= old {
                continue;
            }
            let granule = &mut self.granules[g];
            let before = granule_kinetic(granule, selective);
            set_masses(granule, &self.base_mass, k);
            let added = granule_kinetic(granule, selective) - before;
            self.energies.supplied_kinetic += added;
            self.energies.kinetic += added;
            self.time_steps[g].scale_masses(k / old);
            self.mass_factors[g] = k;
            // The rigid frame the last corrector left holds the old masses.
            if let Some(current) = self.frame_motions.get_mut(g) {
                *current = None;
            }
            *d *= (k / old).sqrt();
        }
    }

    /// Elastic energy Ψ of every granule (summed in order), stored in the
    /// ledger and returned, J.
    pub fn elastic_energy(&mut self) -> Real {
        let view = self.mesh.view();
        let p = &self.params;
        let per: Vec<Real> = self
            .granules
            .par_iter()
            .map(|g| {
                elastic_energy(&view, &p.material, &p.elements, &g.x, &g.cp_inv)
                    .expect("every granule's buffers are sized from the mesh")
            })
            .collect();
        self.energies.elastic = per.iter().sum();
        self.energies.elastic
    }

    /// One contact sweep on the current x̃: broad phase, detection, mass
    /// sharing counts, pair forces and wall forces, added to every
    /// granule's f_c (pairs in list order, then walls in wall order) and
    /// the wall results added to `wall_totals` (per granule, per wall).
    fn contact_sweep(
        &mut self,
        step: u64,
        walls: &[granbed_kernel::contact::wall::Wall],
        dt2: Real,
        first: bool,
        wall_totals: &mut [Vec<WallForce>],
    ) -> Result<(), AssemblyError> {
        let p = self.params;
        let contact_error = |error| AssemblyError::Contact { step, error };
        let mesh = self.mesh;
        self.contact
            .broad(&self.granules, mesh, p.contact.margin, first)
            .map_err(contact_error)?;
        self.contact
            .detect(
                &self.granules,
                mesh,
                &p.contact,
                first,
                self.holds_constraints(),
                !self.searches_step(step),
            )
            .map_err(contact_error)?;
        let surface = mesh.surface_range();
        if p.mass_sharing {
            self.contact
                .count_contacts(&self.granules, mesh, walls)
                .map_err(contact_error)?;
        }
        self.contact
            .forces(&self.granules, mesh, &p.contact, dt2, p.mass_sharing, first)
            .map_err(contact_error)?;
        let contact = &self.contact;
        let touched: Vec<(bool, u64)> = self
            .granules
            .par_iter_mut()
            .zip(wall_totals.par_iter_mut())
            .enumerate()
            .map(|(gi, (g, totals))| {
                let touched = contact.gather(gi, &mut g.f_c);
                let mut on_wall = 0u64;
                let share: &[u16] = if p.mass_sharing {
                    &contact.share[gi]
                } else {
                    &[]
                };
                let body = PredictedNodes {
                    mass: &g.contact_mass,
                    x_n: &g.x,
                    x_pred: &g.x_pred,
                    rigid_shift: RigidShift::NONE,
                };
                let b = contact.bounds[gi];
                for (k, (w, total)) in walls.iter().zip(totals.iter_mut()).enumerate() {
                    if !w.may_touch(&b.centre, b.radius) {
                        continue;
                    }
                    let f = wall_contact(
                        w,
                        p.wall_friction,
                        dt2,
                        surface.clone(),
                        &body,
                        share,
                        &mut g.f_c,
                    )?;
                    if f.contacts > 0 {
                        on_wall |= 1 << (k % 64);
                    }
                    add_wall(total, &f, false);
                }
                Ok((touched || on_wall != 0, on_wall))
            })
            .collect::<Result<_, ContactError>>()
            .map_err(contact_error)?;
        self.contact.touched = touched.iter().map(|t| t.0).collect();
        self.contact.forced.clone_from(&self.contact.touched);
        if first {
            self.contact.on_wall = touched.iter().map(|t| t.1).collect();
        } else {
            for (w, t) in self.contact.on_wall.iter_mut().zip(&touched) {
                *w |= t.1;
            }
        }
        Ok(())
    }

    /// Advances every granule by one step.
    pub fn step(&mut self) -> Result<(), AssemblyError> {
        let step = self.steps;
        if step > 0 && step.is_multiple_of(u64::from(self.params.time_step_interval)) {
            self.dt_prev = self.dt;
            self.dt = self.stable_step()?;
        }
        let sizes = StepSizes {
            dt_prev: self.dt_prev,
            dt: self.dt,
        };
        let p = self.params;
        // g/F on the stored masses F m keeps the weight m g; with selective
        // scaling the rigid modes carry G m, so a granule falls at g/G (at g
        // when G = 1), as under uniform scaling by G.
        let loads = Loads {
            gravity_m_s2: p.gravity_m_s2 / p.mass_scaling,
            damping_c: self.damping_c,
            rigid_modes: true,
            selective_mass_factor: p.selective_mass_factor(),
        };
        let view = self.mesh.view();
        let clock = std::time::Instant::now();
        // Each granule's rigid frame at x_n, taken once for the damping, the
        // predictor and the corrector (a granule still rigid needs none
        // unless its contact masses do) — and under selective mass scaling
        // for the rigid response in the sweeps and the contact masses.
        // A frame the last corrector took at these positions is reused with
        // the rigid part of v it took in it (the same bits as taking both
        // again); the mark is consumed here, so a step that fails before
        // its corrector leaves none behind. (Marks are set only under
        // selective scaling, where every granule takes a frame, so every
        // mark is consumed.)
        let selective = p.selective_mass_factor();
        self.frames
            .resize(self.granules.len(), RigidFrame::default());
        self.frame_motions.resize(self.granules.len(), None);
        let surface = self.mesh.surface_range();
        let predicted: Vec<Result<ForceSummary, ForcesError>> = self
            .granules
            .par_iter_mut()
            .zip(self.frames.par_iter_mut())
            .zip(self.rigid.par_iter())
            .zip(self.frame_motions.par_iter_mut())
            .zip(self.mass_factors.par_iter())
            .map(|((((g, frame), &rigid), current), &k)| {
                let loads = loads_for_mass_factor(&loads, k);
                let velocity_motion = current.take();
                if selective > 1.0 || !rigid {
                    if velocity_motion.is_none() {
                        *frame = RigidFrame::of(&g.mass, &g.x);
                    }
                    if selective > 1.0 {
                        // Contact touches surface nodes only, so only
                        // theirs are taken (every buffer of a GranuleStore
                        // has one entry per node).
                        let s = surface.clone();
                        let written = selective_contact_masses(
                            frame,
                            &g.mass[s.clone()],
                            &g.x[s.clone()],
                            selective,
                            &mut g.contact_mass[s],
                        );
                        debug_assert!(written);
                    }
                }
                if rigid {
                    return predict_rigid(&mut g.buffers(), sizes, &loads);
                }
                predict_in(
                    frame,
                    velocity_motion.as_ref(),
                    &view,
                    &p.material,
                    &p.elements,
                    &mut g.buffers(),
                    sizes,
                    &loads,
                )
            })
            .collect();
        self.times.rigid_granule_steps += self.rigid.iter().filter(|&&r| r).count() as u64;

        let mut plastic = 0.0;
        let mut hourglass = 0.0;
        let mut min_j = Real::INFINITY;
        for (granule, r) in predicted.into_iter().enumerate() {
            let s = r.map_err(|failure| AssemblyError::Element {
                granule,
                step,
                failure,
            })?;
            plastic += s.plastic_dissipation;
            hourglass += s.hourglass_energy;
            min_j = min_j.min(s.min_j);
        }

        let predicted_at = clock.elapsed().as_secs_f64();
        // Contact on the predicted configuration, walls at t_{n+1}; each
        // further sweep moves x̃ by the forces of the last and corrects what
        // is left (physics.md §5.3's optional Jacobi sweeps).
        let dt2 = sizes.contact_dt_squared();
        let walls: Vec<_> = self
            .walls
            .iter()
            .map(|w| w.at(self.time + sizes.dt))
            .collect();
        let mut wall_totals = vec![vec![WallForce::default(); walls.len()]; self.granules.len()];
        let mut pair_normal = 0.0;
        let mut constraints = 0;
        // Contact forces act on surface nodes only, so only those move in
        // a sweep and only their f_c is kept from before it; a granule the
        // last sweep put no force on keeps its x̃ (its update would add
        // zeros). With selective mass scaling the surface also moves by the
        // granule's rigid response to Δf (M'⁻¹ as in `correct`, which also
        // projects at x_n); the interior's share of it is left to `correct`.
        // (No component is held in an assembly, so unlike `correct` the
        // response ignores `fixed`.) `surface` is the range taken above.
        // Taken for the sweeps (which borrow the assembly) and put back.
        let frames = core::mem::take(&mut self.frames);
        for sweep in 0..p.contact_sweeps {
            if sweep > 0 {
                self.granules
                    .par_iter_mut()
                    .zip(self.contact.f_before.par_iter())
                    .zip(self.contact.forced.par_iter())
                    .enumerate()
                    .filter(|(_, (_, forced))| **forced)
                    .for_each(|(gi, ((g, before), _))| {
                        let s = surface.clone();
                        let g = &mut *g;
                        let rigid = (selective > 1.0).then(|| {
                            let frame = &frames[gi];
                            frame.response(
                                g.x[s.clone()]
                                    .iter()
                                    .zip(&g.f_c[s.clone()])
                                    .zip(before)
                                    .map(|((x, f), f0)| {
                                        (*x, [f[0] - f0[0], f[1] - f0[1], f[2] - f0[2]])
                                    }),
                            )
                        });
                        let nodes = g.x_pred[s.clone()]
                            .iter_mut()
                            .zip(&g.f_c[s.clone()])
                            .zip(before)
                            .zip(&g.mass[s.clone()])
                            .zip(&g.x[s.clone()]);
                        match &rigid {
                            None => {
                                for ((((x, f), f0), m), _) in nodes {
                                    for a in 0..3 {
                                        x[a] += dt2 * (f[a] - f0[a]) / m;
                                    }
                                }
                            }
                            Some(r) => {
                                for ((((x, f), f0), m), xn) in nodes {
                                    let u = r.velocity_at(xn);
                                    for a in 0..3 {
                                        x[a] +=
                                            dt2 * ((f[a] - f0[a]) / m + (selective - 1.0) * u[a]);
                                    }
                                }
                            }
                        }
                    });
            }
            if sweep + 1 < p.contact_sweeps {
                // Reuse the buffers: this runs every sweep of every step.
                let before = &mut self.contact.f_before;
                before.resize_with(self.granules.len(), Vec::new);
                before
                    .par_iter_mut()
                    .zip(self.granules.par_iter())
                    .for_each(|(b, g)| {
                        b.clear();
                        b.extend_from_slice(&g.f_c[surface.clone()]);
                    });
            }
            self.contact_sweep(step, &walls, dt2, sweep == 0, &mut wall_totals)?;
            self.times.sweeps += 1;
            // A granule touched in any sweep is a deformable body from the
            // next step on (its predictor above saw it undeformed).
            for (rigid, &touched) in self.rigid.iter_mut().zip(&self.contact.touched) {
                *rigid &= !touched;
            }
            // Another sweep only if this one still found a gap deeper than
            // the tolerance (a minimum: the same for any thread count).
            let deepest = self
                .contact
                .work()
                .iter()
                .map(|w| w.result.min_gap)
                .fold(0.0, Real::min);
            let tolerance = self.sweep_tolerance_m();
            if deepest > -tolerance {
                break;
            }
            if p.local_sweeps {
                self.contact.narrow_to_deep_pairs(tolerance);
            }
        }
        self.frames = frames;
        for w in self.contact.work() {
            pair_normal += w.step.normal;
            constraints += w.step.constraints;
        }
        let contacted_at = clock.elapsed().as_secs_f64();
        let per: Vec<Result<StepWork, ForcesError>> = self
            .granules
            .par_iter_mut()
            .zip(self.frames.par_iter())
            .zip(self.mass_factors.par_iter())
            .map(|((g, frame), &k)| {
                correct_in(
                    frame,
                    &mut g.buffers(),
                    sizes,
                    &loads_for_mass_factor(&loads, k),
                )
            })
            .collect();
        // The buffers and step sizes passed the predictor's checks.
        let per = per
            .into_iter()
            .enumerate()
            .map(|(granule, r)| {
                r.map_err(|failure| AssemblyError::Element {
                    granule,
                    step,
                    failure,
                })
            })
            .collect::<Result<Vec<StepWork>, AssemblyError>>()?;
        for ((frame, current), w) in self
            .frames
            .iter_mut()
            .zip(&mut self.frame_motions)
            .zip(&per)
        {
            if let Some(next) = w.next_frame {
                *frame = next;
            }
            *current = w.next_frame.and(w.next_motion);
        }

        let mut report = StepReport {
            dt: sizes.dt,
            min_j,
            walls: vec![WallForce::default(); walls.len()],
            ..StepReport::default()
        };
        let e = &mut self.energies;
        let mut kinetic = 0.0;
        let mut max_speed_squared: Real = 0.0;
        for (granule, (w, wall_forces)) in per.iter().zip(&wall_totals).enumerate() {
            if !w.kinetic.is_finite() {
                return Err(AssemblyError::Unstable {
                    step,
                    granule: Some(granule),
                });
            }
            if w.max_speed_squared > p.max_node_speed_m_s * p.max_node_speed_m_s {
                return Err(AssemblyError::Runaway {
                    step,
                    granule,
                    speed_m_s: w.max_speed_squared.sqrt(),
                    limit_m_s: p.max_node_speed_m_s,
                });
            }
            max_speed_squared = max_speed_squared.max(w.max_speed_squared);
            e.internal_work += w.internal;
            e.contact_work += w.contact;
            e.damping += w.damping;
            e.gravity_work += w.gravity;
            kinetic += w.kinetic;
            for (total, wf) in report.walls.iter_mut().zip(wall_forces) {
                add_wall(total, wf, true);
            }
        }
        e.kinetic = kinetic;
        // Contact work counts where it exceeds the punch work: the release
        // of the overlaps a packing starts with.
        let supplied = e.punch_work.max(e.contact_work) + e.gravity_work + e.supplied_kinetic;
        if kinetic > p.kinetic_energy_limit * supplied.max(0.0) && kinetic > 0.0 {
            let granule = per
                .iter()
                .enumerate()
                .fold((0, Real::NEG_INFINITY), |best, (g, w)| {
                    if w.kinetic > best.1 {
                        (g, w.kinetic)
                    } else {
                        best
                    }
                })
                .0;
            return Err(AssemblyError::EnergyRunaway {
                step,
                granule,
                kinetic_j: kinetic,
                supplied_j: supplied,
                limit: p.kinetic_energy_limit,
            });
        }
        e.plastic += plastic;
        e.hourglass = hourglass;
        for (spec, w) in self.walls.iter().zip(&report.walls) {
            // The wall's displacement over the step, from its positions.
            let moved = spec.speed_m_s
                * ((self.time + sizes.dt).min(spec.stop_s) - self.time.min(spec.stop_s));
            e.punch_work += w.normal * moved;
        }
        report.pair_normal = pair_normal;
        report.constraints = constraints;
        report.max_node_speed_m_s = max_speed_squared.sqrt();
        report.wall_contacts = self
            .contact
            .on_wall
            .iter()
            .map(|w| w.count_ones() as usize)
            .sum();
        self.last = report;
        let done_at = clock.elapsed().as_secs_f64();
        self.times.predict_s += predicted_at;
        self.times.contact_s += contacted_at - predicted_at;
        self.times.correct_s += done_at - contacted_at;
        self.times.steps += 1;
        self.time += sizes.dt;
        self.steps += 1;
        self.dt_prev = sizes.dt;
        Ok(())
    }
}

/// Per-thread scratch of the power iteration (the mode itself is kept
/// per granule as the warm start).
struct PowerScratch {
    x_pert: Vec<[Real; 3]>,
    f_plus: Vec<[Real; 3]>,
    f_minus: Vec<[Real; 3]>,
    cp_scratch: Vec<[Real; 6]>,
}

impl PowerScratch {
    fn new(nodes: usize, states: usize) -> Self {
        Self {
            x_pert: vec![[0.0; 3]; nodes],
            f_plus: vec![[0.0; 3]; nodes],
            f_minus: vec![[0.0; 3]; nodes],
            cp_scratch: vec![[0.0; 6]; states],
        }
    }
}
