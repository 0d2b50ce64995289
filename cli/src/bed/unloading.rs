//! The compaction cycle's second half: after the final strain the upper
//! punch withdraws at the punch speed until it comes free of the bed
//! (scene `unload`, [`super::run::Unloading`]). Its rows are written to
//! `unloading.csv` with `compression.csv`'s columns, and its figures to
//! `summary.json`'s `unloading` ([`UnloadingSummary`]):
//!
//! * the **in-die elastic recovery** (H_lift − H_min)/H_min: how far the
//!   compact expands against the withdrawing punch before it lets go
//!   (its force below [`super::run::LIFT_OFF_FORCE_FRACTION`] of the
//!   largest), the compact still in the die;
//! * the **residual die-wall pressure** at lift-off: the radial stress the
//!   die wall's friction locks in, which the ejection has to overcome;
//! * the **work of the cycle** (the force–displacement curve's areas, as a
//!   compaction simulator reports them): the punch's work up to the final
//!   strain, the work the bed gives back to the withdrawing punch (the
//!   elastic work), their difference (the net work, spent in plastic flow,
//!   friction and damping) and Stamm and Mathis's plasticity factor, net /
//!   (net + elastic).
//!
//! With `--rate-check` the same bed is pressed and withdrawn at half the
//! punch speed, and the recovery's change is the unloading's check
//! ([`UnloadingRateCheck`]): at the turn the punch reverses at once, and
//! the rate-dependent share of the load (inertia, damping) falls away
//! first (half the speed halves the first row's fall, BENCHMARKS.md), so
//! a punch too fast can shift the recovery.
//!
//! What the physics guarantees, and the tests check: the unloading curve
//! lies below the loading curve (what the bed dissipated it cannot give
//! back), and the work given back is at most the granules' elastic energy
//! at the final strain.

use granbed_kernel::Real;
use serde::Serialize;

use super::outputs::die_wall_pressure;
use super::run::{BedRun, Unloading};

/// File of the withdrawal's rows, in the output directory.
pub const UNLOADING_CSV: &str = "unloading.csv";

/// The withdrawal's figures in `summary.json`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct UnloadingSummary {
    /// Rows in `unloading.csv`.
    pub rows: usize,
    /// The strain the punch withdrew from: the loading's last row's.
    pub from_strain: Real,
    /// The nominal strain where the upper punch came free of the bed for
    /// good (`None`: it had not when the withdrawal stopped).
    pub lift_off_strain: Option<Real>,
    /// In-die elastic recovery (H_lift − H_min)/H_min = (C_max − C_lift)
    /// / (1 − C_max), H the height between the punches.
    pub elastic_recovery: Option<Real>,
    /// The die wall's pressure over the lift-off row's interval: the
    /// radial stress the compact keeps, Pa. This and the figures below that
    /// need the punch free are `None` without a lift-off.
    pub residual_die_wall_pressure_pa: Option<Real>,
    /// The lower punch's pressure over the lift-off row's interval, Pa:
    /// the bed's weight plus the die wall's friction, which, reversed as
    /// the compact expands upwards, presses it down.
    pub residual_lower_pressure_pa: Option<Real>,
    /// The punches' work on the bed up to the final strain, J.
    pub loading_work_j: Real,
    /// The work the bed did on the withdrawing punch up to lift-off, J:
    /// the elastic work of the cycle.
    pub returned_work_j: Option<Real>,
    /// Loading work less the returned work, J: what the plastic flow, the
    /// friction (the die wall's included: compaction simulators split it
    /// off as the friction work) and the damping took.
    pub net_work_j: Option<Real>,
    /// The plasticity factor net / (net + returned) = net / loading work
    /// (Stamm and Mathis's, with the die wall's friction work in the net
    /// work rather than split off).
    pub plasticity_factor: Option<Real>,
    /// The granules' elastic energy Ψ at the final strain, J: the most the
    /// bed could give back.
    pub elastic_energy_at_end_j: Real,
    /// Wall time of the withdrawal, s (not in the run's cost figures).
    pub wall_time_s: f64,
    /// The rate check (`--rate-check`; every field `None` without it): the
    /// same compaction cycle at half the punch speed.
    #[serde(flatten)]
    pub rate_check: UnloadingRateCheck,
}

/// The rate check of the compaction cycle's unloading: the same bed
/// pressed and withdrawn at half the punch speed (`--rate-check`'s twin),
/// its figures and how far the in-die elastic recovery moved. The
/// recovery is the withdrawal's headline figure, so it is the one judged
/// (on the published scene it moved 1.9 %, the work given back 3.9 %,
/// BENCHMARKS.md). The twin is pressed at half speed too, so the change is
/// the whole cycle's rate dependence, the loading's included. Flattened
/// into `unloading` as `half_speed_*`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct UnloadingRateCheck {
    /// The in-die elastic recovery at half the punch speed (`None`: not
    /// checked, or no lift-off at half speed).
    pub half_speed_elastic_recovery: Option<Real>,
    /// The plasticity factor at half the punch speed.
    pub half_speed_plasticity_factor: Option<Real>,
    /// |recovery at half speed − recovery| / recovery (`None` unless both
    /// runs lifted off).
    pub half_speed_recovery_change_rel: Option<Real>,
    /// The change below the loading's rate-check limit
    /// ([`granbed_kernel::analysis::quasi_static::RATE_CHANGE_LIMIT`]);
    /// false too when only one of the two runs' punches came free (the
    /// strongest dependence on the speed); `None`: not checked, or neither
    /// came free.
    pub half_speed_passed: Option<bool>,
}

impl UnloadingRateCheck {
    /// The check of a withdrawal whose recovery is `recovery` against the
    /// figures `half` of its twin at half the speed.
    pub fn of(recovery: Option<Real>, half: &UnloadingSummary) -> Self {
        let change = recovery
            .zip(half.elastic_recovery)
            .filter(|(r, _)| *r > 0.0)
            .map(|(r, h)| (h - r).abs() / r);
        let limit = granbed_kernel::analysis::quasi_static::RATE_CHANGE_LIMIT;
        Self {
            half_speed_elastic_recovery: half.elastic_recovery,
            half_speed_plasticity_factor: half.plasticity_factor,
            half_speed_recovery_change_rel: change,
            half_speed_passed: match (recovery, half.elastic_recovery) {
                (Some(_), Some(_)) => change.map(|c| c < limit),
                (None, None) => None,
                _ => Some(false),
            },
        }
    }
}

impl UnloadingSummary {
    /// The figures of `run`'s withdrawal `u`, which followed its last row.
    pub fn of(run: &BedRun, u: &Unloading) -> Self {
        let at_end = run.samples.last().copied().unwrap_or_default();
        let loading = at_end.energies.punch_work;
        let lift_off = Some(u.lift_off_strain).filter(|c| c.is_finite());
        // The last row is the lift-off row when there is a lift-off.
        let free = u.samples.last().filter(|_| lift_off.is_some());
        let returned = free.map(|s| loading - s.energies.punch_work);
        let finite = |x: Real| Some(x).filter(|x| x.is_finite());
        let elastic_recovery = lift_off.map(|c| (at_end.strain - c) / (1.0 - at_end.strain));
        Self {
            rows: u.samples.len(),
            from_strain: at_end.strain,
            lift_off_strain: lift_off,
            elastic_recovery,
            residual_die_wall_pressure_pa: free.and_then(|s| finite(die_wall_pressure(run, s))),
            residual_lower_pressure_pa: free.map(|s| s.lower_pressure_pa),
            loading_work_j: loading,
            returned_work_j: returned,
            net_work_j: returned.map(|r| loading - r),
            plasticity_factor: returned
                .filter(|_| loading > 0.0)
                .map(|r| (loading - r) / loading),
            elastic_energy_at_end_j: at_end.energies.elastic,
            wall_time_s: u.wall_time_s,
            rate_check: run
                .half_speed_unloading
                .as_ref()
                .map_or_else(UnloadingRateCheck::default, |half| {
                    UnloadingRateCheck::of(elastic_recovery, half)
                }),
        }
    }
}

/// The warning of a compaction cycle whose unloading's rate check failed:
/// the in-die elastic recovery moved by more than the limit at half the
/// speed, or the punch came free in one run only.
pub fn rate_warning(s: &UnloadingSummary) -> Option<String> {
    let check = s.rate_check;
    if check.half_speed_passed != Some(false) {
        return None;
    }
    let limit = granbed_kernel::analysis::quasi_static::RATE_CHANGE_LIMIT;
    let fmt = |x: Option<Real>| x.map_or("none (no lift-off)".to_owned(), |x| format!("{x:.4}"));
    Some(format!(
        "the unloading depends on the punch speed: pressed and withdrawn at half the speed, the \
         bed's in-die elastic recovery is {} against {}{} [limit {limit}]; a slower punch \
         (--punch-speed-m-s) gives figures nearer the material's",
        fmt(check.half_speed_elastic_recovery),
        fmt(s.elastic_recovery),
        check
            .half_speed_recovery_change_rel
            .map_or(String::new(), |c| format!(", a change of {c:.3}")),
    ))
}

/// The warning of a withdrawal that did not see the punch come free, or
/// was cut short; none otherwise.
pub fn warning(u: &Unloading) -> Option<String> {
    let at = u.samples.last().map_or(Real::NAN, |s| s.strain);
    match &u.cut_short {
        Some(why) => Some(format!(
            "the upper punch's withdrawal stopped before it came free of the bed ({why}): \
             unloading.csv has its rows so far; --resume goes on from its last checkpoint \
             (withdrawal.bin; without one, from the loading's end)"
        )),
        None if !u.lift_off_strain.is_finite() => Some(format!(
            "the bed still pushed the upper punch with {} % or more of its largest force at \
             C = {at:.4}, after a withdrawal of {} (the most allowed): no lift-off, so no \
             elastic recovery",
            100.0 * super::run::LIFT_OFF_FORCE_FRACTION,
            super::run::MAX_WITHDRAWAL_STRAIN
        )),
        None => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bed::run::BedSample;

    fn row(strain: Real, upper: Real, punch_work: Real, elastic: Real) -> BedSample {
        let mut s = BedSample {
            strain,
            mean_strain: strain,
            upper_force_n: upper,
            upper_pressure_pa: upper,
            lower_pressure_pa: 0.5 * upper,
            die_normal_force_n: 2.0,
            ..BedSample::default()
        };
        s.energies.punch_work = punch_work;
        s.energies.elastic = elastic;
        s
    }

    /// A bed pressed to C = 0.3 with 10 J that gives 2 J back and lets go
    /// at C = 0.286: recovery 0.014/0.7 = 2 %, net 8 J, plasticity 0.8.
    #[test]
    fn the_cycle_in_figures() {
        let mut run = BedRun::of_samples(vec![row(0.0, 0.0, 0.0, 0.0), row(0.3, 5.0, 10.0, 3.0)]);
        run.bed_height_m = 1.0;
        run.die_radius_m = 1.0;
        let u = Unloading {
            samples: vec![row(0.29, 1.0, 8.5, 1.0), row(0.285, 0.0, 8.0, 0.5)],
            lift_off_strain: 0.286,
            wall_time_s: 1.0,
            cut_short: None,
        };
        let s = UnloadingSummary::of(&run, &u);
        assert_eq!((s.rows, s.from_strain), (2, 0.3));
        assert!((s.elastic_recovery.unwrap() - 0.02).abs() < 1e-12);
        assert_eq!(
            (s.loading_work_j, s.returned_work_j, s.net_work_j),
            (10.0, Some(2.0), Some(8.0))
        );
        assert_eq!(s.plasticity_factor, Some(0.8));
        assert_eq!(s.elastic_energy_at_end_j, 3.0);
        // F_n 2 N on 2π R H, H = 1 − 0.285.
        let p = 2.0 / (2.0 * core::f64::consts::PI * 0.715);
        assert!((s.residual_die_wall_pressure_pa.unwrap() - p).abs() < 1e-12);
        assert_eq!(s.residual_lower_pressure_pa, Some(0.0));
        assert_eq!(warning(&u), None);
        // No lift-off: no recovery, and a warning; cut short: another.
        let none = Unloading {
            lift_off_strain: Real::NAN,
            ..u.clone()
        };
        // Without a lift-off nothing that needs the punch free is given.
        let s = UnloadingSummary::of(&run, &none);
        assert_eq!((s.elastic_recovery, s.returned_work_j), (None, None));
        assert_eq!(
            (s.plasticity_factor, s.residual_die_wall_pressure_pa),
            (None, None)
        );
        assert_eq!(s.loading_work_j, 10.0);
        assert!(warning(&none).unwrap().contains("no lift-off"));
        let cut = Unloading {
            cut_short: Some(crate::bed::run::CutShort::Interrupted { strain: 0.29 }),
            ..none
        };
        assert!(warning(&cut).unwrap().contains("interrupted at C = 0.2900"));
    }

    /// The withdrawal's rate check: the twin's recovery against the run's,
    /// judged against the limit 0.05: a change of 4 % passes, one of 6 %
    /// fails with a warning; a lift-off in one run only fails; none in
    /// either is not judged.
    #[test]
    fn the_withdrawal_rate_check() {
        let mut run = BedRun::of_samples(vec![row(0.0, 0.0, 0.0, 0.0), row(0.3, 5.0, 10.0, 3.0)]);
        run.bed_height_m = 1.0;
        run.die_radius_m = 1.0;
        let u = |lift_off_strain| Unloading {
            samples: vec![row(0.29, 1.0, 8.5, 1.0), row(0.285, 0.0, 8.0, 0.5)],
            lift_off_strain,
            wall_time_s: 1.0,
            cut_short: None,
        };
        // Recovery (0.3 − C_lift)/0.7: 0.02 for the run at 0.286; the twins
        // 0.0208 (+4 %) and 0.0212 (+6 %).
        let twin = |recovery: Real| UnloadingSummary::of(&run, &u(0.3 - 0.7 * recovery));
        let (near, far) = (twin(0.0208), twin(0.0212));
        run.half_speed_unloading = Some(near);
        let s = UnloadingSummary::of(&run, &u(0.286));
        let check = s.rate_check;
        assert_eq!(check.half_speed_elastic_recovery, near.elastic_recovery);
        assert_eq!(check.half_speed_plasticity_factor, near.plasticity_factor);
        assert!((check.half_speed_recovery_change_rel.unwrap() - 0.04).abs() < 1e-9);
        assert_eq!(check.half_speed_passed, Some(true));
        assert_eq!(rate_warning(&s), None);
        run.half_speed_unloading = Some(far);
        let s = UnloadingSummary::of(&run, &u(0.286));
        assert!((s.rate_check.half_speed_recovery_change_rel.unwrap() - 0.06).abs() < 1e-9);
        assert_eq!(s.rate_check.half_speed_passed, Some(false));
        let w = rate_warning(&s).unwrap();
        assert!(
            w.contains("0.0212 against 0.0200, a change of 0.060 [limit 0.05]"),
            "{w}"
        );
        // The punch free in one run only: failed; in neither: not judged.
        let stuck = UnloadingSummary::of(&run, &u(Real::NAN));
        let one = UnloadingRateCheck::of(Some(0.02), &stuck);
        assert_eq!(
            (one.half_speed_recovery_change_rel, one.half_speed_passed),
            (None, Some(false))
        );
        assert_eq!(
            UnloadingRateCheck::of(None, &far).half_speed_passed,
            Some(false)
        );
        assert_eq!(UnloadingRateCheck::of(None, &stuck).half_speed_passed, None);
        let s = UnloadingSummary {
            rate_check: one,
            ..s
        };
        assert!(
            rate_warning(&s)
                .unwrap()
                .contains("is none (no lift-off) against 0.0200 [")
        );
        // Without the check every field is None.
        let s = UnloadingSummary::of(&BedRun::of_samples(Vec::new()), &u(0.29));
        assert_eq!(s.rate_check, UnloadingRateCheck::default());
    }
}
