//! The quasi-static certificate of a loading run (issue #8): whether the
//! inertia — physical or added by mass scaling — left the answer alone.
//!
//! Judged over the loaded part of a run, the second half of its samples
//! ([`judged`]): before it, a bed's rearrangement is dynamic at any mass
//! and a granule is barely loaded.
//! **Choices**, fixed before they were measured against any run:
//! * kinetic energy below [`KINETIC_TO_INTERNAL_LIMIT`] of the internal work
//!   at every sample;
//! * the force imbalance |F_in − F_out| / F_in (F_in the driving platen or
//!   punch, F_out what the other side and the walls take up), averaged over
//!   the loaded samples, below [`FORCE_IMBALANCE_LIMIT`] — where it is
//!   measured: an octant granule's lower platen is the mirror image of the
//!   upper one, so there is no imbalance to measure;
//! * when the rate check ran (the same run at half the loading speed), the
//!   load curve moved by less than [`RATE_CHANGE_LIMIT`] (relative L2).

use crate::Real;

/// Largest kinetic / internal work ratio allowed at any judged sample.
pub const KINETIC_TO_INTERNAL_LIMIT: Real = 0.01;
/// Largest mean force imbalance allowed, relative to the driving force.
pub const FORCE_IMBALANCE_LIMIT: Real = 0.05;
/// Largest relative L2 change of the load curve at half the speed (a curve
/// that moves by 5 % when the loading is twice as slow is not a
/// quasi-static answer).
pub const RATE_CHANGE_LIMIT: Real = 0.05;

/// One sample as the certificate reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadSample {
    /// Kinetic energy, J.
    pub kinetic_j: Real,
    /// Internal work (elastic + plastic + hourglass), J.
    pub internal_work_j: Real,
    /// Force of the driving platen or punch, N (≤ 0: not loaded yet).
    pub force_in_n: Real,
    /// Force taken up by the other side (lower punch plus die-wall
    /// friction), N; `None` where it is not measured (octant symmetry).
    pub force_out_n: Option<Real>,
}

/// The certificate's figures and verdict.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Certificate {
    /// Largest kinetic / internal work ratio over the judged samples
    /// (`None`: no sample had internal work).
    pub max_kinetic_to_internal: Option<Real>,
    /// Mean |F_in − F_out| / F_in over the loaded samples (`None`: not
    /// measured, or no sample loaded).
    pub force_imbalance_rel: Option<Real>,
    /// Relative L2 change of the load curve at half the speed (`None`: the
    /// rate check did not run).
    pub rate_change_rel: Option<Real>,
    /// Every figure below its limit. The kinetic ratio is required; the
    /// imbalance is required where any sample measured it (so a bed whose
    /// punch never took load fails); the rate change only if checked.
    pub passed: bool,
}

/// The judged part of a run's samples (in time order): the second half.
pub fn judged<T>(samples: &[T]) -> &[T] {
    &samples[samples.len() / 2..]
}

/// The certificate of the judged `samples`, with the rate check's change
/// if it ran.
pub fn certificate(
    samples: impl IntoIterator<Item = LoadSample>,
    rate_change_rel: Option<Real>,
) -> Certificate {
    let mut max_ratio: Option<Real> = None;
    let (mut measured, mut imbalance_sum, mut loaded) = (false, 0.0, 0_usize);
    for s in samples {
        // NaN figures are judged (and fail), not skipped.
        if s.internal_work_j > 0.0 || s.internal_work_j.is_nan() {
            // A NaN ratio sticks (and fails the certificate).
            let r = s.kinetic_j / s.internal_work_j;
            max_ratio = Some(match max_ratio {
                Some(m) if m.is_nan() || r <= m => m,
                _ => r,
            });
        }
        if let Some(out) = s.force_out_n {
            measured = true;
            if s.force_in_n > 0.0 || s.force_in_n.is_nan() {
                imbalance_sum += crate::math::abs(s.force_in_n - out) / s.force_in_n;
                loaded += 1;
            }
        }
    }
    let force_imbalance_rel = (loaded > 0).then(|| imbalance_sum / loaded as Real);
    let passed = max_ratio.is_some_and(|r| r < KINETIC_TO_INTERNAL_LIMIT)
        && (!measured || force_imbalance_rel.is_some_and(|r| r < FORCE_IMBALANCE_LIMIT))
        && rate_change_rel.is_none_or(|r| r < RATE_CHANGE_LIMIT);
    Certificate {
        max_kinetic_to_internal: max_ratio,
        force_imbalance_rel,
        rate_change_rel,
        passed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(kinetic: Real, work: Real, f_in: Real, f_out: Option<Real>) -> LoadSample {
        LoadSample {
            kinetic_j: kinetic,
            internal_work_j: work,
            force_in_n: f_in,
            force_out_n: f_out,
        }
    }

    #[test]
    fn figures_and_limits() {
        let quiet = [
            sample(0.0, 0.0, 0.0, Some(0.0)),
            sample(1e-3, 1.0, 10.0, Some(9.8)),
            sample(4e-3, 2.0, 20.0, Some(19.0)),
        ];
        let c = certificate(quiet, None);
        assert_eq!(c.max_kinetic_to_internal, Some(4e-3 / 2.0));
        assert!((c.force_imbalance_rel.unwrap() - 0.5 * (0.02 + 0.05)).abs() < 1e-15);
        assert!(c.passed);
        // Each limit on its own fails the certificate.
        assert!(!certificate([sample(0.02, 1.0, 10.0, Some(10.0))], None).passed);
        assert!(!certificate([sample(0.0, 1.0, 10.0, Some(9.0))], None).passed);
        assert!(!certificate(quiet, Some(RATE_CHANGE_LIMIT)).passed);
        assert!(certificate(quiet, Some(0.01)).passed);
    }

    #[test]
    fn unmeasured_imbalance_is_not_required_but_unloaded_is_a_failure() {
        let octant = [sample(1e-4, 1.0, 5.0, None)];
        let c = certificate(octant, None);
        assert_eq!(c.force_imbalance_rel, None);
        assert!(c.passed);
        let never_loaded = [sample(1e-4, 1.0, 0.0, Some(0.0))];
        assert!(!certificate(never_loaded, None).passed);
        assert!(!certificate([], None).passed);
        // A NaN ratio does not pass, wherever it is.
        let ok = sample(1e-4, 1.0, 5.0, None);
        let nan = sample(Real::NAN, 1.0, 5.0, None);
        assert!(!certificate([nan, ok], None).passed);
        assert!(!certificate([ok, nan, ok], None).passed);
        let nan_work = sample(1e-4, Real::NAN, 5.0, None);
        assert!(!certificate([ok, nan_work], None).passed);
        let nan_force = sample(1e-4, 1.0, Real::NAN, Some(5.0));
        let loaded = sample(1e-4, 1.0, 5.0, Some(5.0));
        assert!(certificate([loaded], None).passed);
        assert!(!certificate([loaded, nan_force], None).passed);
    }
}
