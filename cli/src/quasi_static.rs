//! The quasi-static certificate as the summaries of `granbed-cli bed` and
//! `granbed-cli granule` write it (issue #8): the kernel's [`certificate`]
//! over the [`judged`] samples, with the rate check's curve change if it
//! ran.

use granbed_kernel::Real;
use granbed_kernel::analysis::quasi_static::{Certificate, LoadSample, certificate, judged};
use serde::Serialize;

/// `quasi_static` in `summary.json`: the certificate's figures and verdict
/// (limits in [`granbed_kernel::analysis::quasi_static`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct QuasiStatic {
    /// Largest kinetic / internal work ratio over the second half.
    pub max_kinetic_to_internal: Option<Real>,
    /// The same with the kinetic energy relative to the compression the
    /// punches impose: a diagnostic, not judged, over the judged samples
    /// that recorded it (`null`: nothing imposed, as between platens, or
    /// none recorded; a run resumed from a checkpoint before format 5 has
    /// it for the samples after the resume only).
    pub max_relative_kinetic_to_internal: Option<Real>,
    /// Mean |F_in − F_out| / F_in over the loaded samples of the second
    /// half (`null` where not measured: an octant granule).
    pub force_imbalance_rel: Option<Real>,
    /// Relative L2 change of the load curve at half the loading speed
    /// (`null`: the rate check did not run).
    pub rate_change_rel: Option<Real>,
    /// Every figure below its limit.
    pub passed: bool,
}

impl QuasiStatic {
    /// Its figures against their limits, for the warning of a run that
    /// failed it: "kinetic/internal work up to … [limit …], force
    /// imbalance … [limit …], change at half speed … [limit …]" (n/a where
    /// not measured).
    pub fn figures(&self) -> String {
        use granbed_kernel::analysis::quasi_static::{
            FORCE_IMBALANCE_LIMIT, KINETIC_TO_INTERNAL_LIMIT, RATE_CHANGE_LIMIT,
        };
        let fmt = |x: Option<Real>| x.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.3e}"));
        format!(
            "kinetic/internal work up to {} [limit {}], force imbalance {} [limit {}], change at \
             half speed {} [limit {}]",
            fmt(self.max_kinetic_to_internal),
            KINETIC_TO_INTERNAL_LIMIT,
            fmt(self.force_imbalance_rel),
            FORCE_IMBALANCE_LIMIT,
            fmt(self.rate_change_rel),
            RATE_CHANGE_LIMIT,
        )
    }
}

impl From<Certificate> for QuasiStatic {
    fn from(c: Certificate) -> Self {
        Self {
            max_kinetic_to_internal: c.max_kinetic_to_internal,
            max_relative_kinetic_to_internal: c.max_relative_kinetic_to_internal,
            force_imbalance_rel: c.force_imbalance_rel,
            rate_change_rel: c.rate_change_rel,
            passed: c.passed,
        }
    }
}

/// The certificate of a run whose samples, in time order, read as
/// `samples`.
pub fn judge(samples: &[LoadSample], rate_change_rel: Option<Real>) -> QuasiStatic {
    certificate(judged(samples).iter().copied(), rate_change_rel).into()
}

/// The start of the rate check's strain window: below 2 %, the load is
/// the contact's and the rearrangement's noise.
pub const RATE_CHECK_FROM_STRAIN: Real = 0.02;

/// The rate check's strain window for a run to `final_strain`.
fn rate_check_window(final_strain: Real) -> [Real; 2] {
    [RATE_CHECK_FROM_STRAIN, final_strain]
}

/// The rate check's figure: the relative L2 distance of the load curve
/// `curve` from `half_speed`, the same run at half the loading speed (both
/// (strain, load) in strain order), over 2 % ≤ C ≤ `final_strain`; `None`
/// if either curve does not cover that window.
pub fn rate_change(
    curve: &[(Real, Real)],
    half_speed: &[(Real, Real)],
    final_strain: Real,
) -> Option<Real> {
    crate::study::work_precision::curve_error(curve, half_speed, rate_check_window(final_strain))
}
