//! A single integration point driven along a prescribed deformation path:
//! the calibration tool behind `granbed-cli point` and the constitutive
//! oracles.
//!
//! Strain conventions (positive = compression, except shear):
//! * [`LoadPath::Hydrostatic`]: volumetric strain e, F = (1 − e)^{1/3} 1, J = 1 − e;
//! * [`LoadPath::UniaxialStrain`]: F = diag(1, 1, 1 − e);
//! * [`LoadPath::UniaxialStress`]: F = diag(λ, λ, 1 − e) with the lateral
//!   stretch λ solved so that τ_xx = τ_yy = 0;
//! * [`LoadPath::Shear`]: simple shear F = 1 + e e_x ⊗ e_y (e = γ).

use core::fmt;

use crate::constitutive::{UpdateError, UpdateInfo, UpdateOptions, update_point};
use crate::material::Material;
use crate::tensor::{Mat3, VOIGT_IDENTITY, Voigt, XX, YY};
use crate::{Real, math};

/// A prescribed deformation path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadPath {
    /// Equal compression in all directions; strain = volume reduction 1 − J.
    Hydrostatic,
    /// Axial compression with no lateral strain; strain = axial nominal strain.
    UniaxialStrain,
    /// Axial compression with stress-free lateral faces; strain = axial nominal strain.
    UniaxialStress,
    /// Simple shear in the x–y plane; strain = shear γ.
    Shear,
}

impl LoadPath {
    /// The open range of strains the path accepts: `(min, max)`.
    pub fn strain_range(self) -> (Real, Real) {
        match self {
            // J = 1 − e > 0 and the stretch 1 − e > 0.
            Self::Hydrostatic | Self::UniaxialStrain | Self::UniaxialStress => (-10.0, 1.0),
            Self::Shear => (-10.0, 10.0),
        }
    }

    /// The deformation gradient at `strain` (for [`LoadPath::UniaxialStress`]
    /// with lateral stretch `lateral`; ignored by the other paths).
    pub fn deformation(self, strain: Real, lateral: Real) -> Mat3 {
        match self {
            Self::Hydrostatic => Mat3::identity() * math::cbrt(1.0 - strain),
            Self::UniaxialStrain => Mat3::from_diagonal(&[1.0, 1.0, 1.0 - strain].into()),
            Self::UniaxialStress => Mat3::from_diagonal(&[lateral, lateral, 1.0 - strain].into()),
            Self::Shear => {
                let mut f = Mat3::identity();
                f[(0, 1)] = strain;
                f
            }
        }
    }
}

/// Why the driver could not reach a strain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriveError {
    /// The constitutive update failed.
    Update(UpdateError),
    /// The lateral-stress Newton of the uniaxial-stress path did not converge.
    LateralNoConvergence {
        /// Remaining lateral stress |τ_xx|, Pa.
        residual_pa: Real,
    },
}

impl fmt::Display for DriveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Update(e) => write!(f, "{e}"),
            Self::LateralNoConvergence { residual_pa } => write!(
                f,
                "uniaxial stress: lateral stress did not vanish (|tau_xx| = {residual_pa:e} Pa)"
            ),
        }
    }
}

impl core::error::Error for DriveError {}

impl From<UpdateError> for DriveError {
    fn from(e: UpdateError) -> Self {
        Self::Update(e)
    }
}

/// The state at one point of the path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointSample {
    /// Path strain (see the module docs).
    pub strain: Real,
    /// Deformation gradient.
    pub f: Mat3,
    /// Kirchhoff stress, Pa.
    pub tau: Voigt,
    /// Update diagnostics.
    pub info: UpdateInfo,
}

/// Lateral-stress tolerance of the uniaxial-stress path, relative to E.
const LATERAL_TOL: Real = 1.0e-13;
/// Newton iterations of the lateral-stress solve.
const LATERAL_MAX_ITERATIONS: u32 = 50;

/// One integration point and its loading history.
#[derive(Clone, Copy, Debug)]
pub struct MaterialPoint {
    mat: Material,
    opts: UpdateOptions,
    path: LoadPath,
    /// Stored state C_p⁻¹ (Voigt).
    cp_inv: Voigt,
    /// Current lateral stretch of the uniaxial-stress path.
    lateral: Real,
}

impl MaterialPoint {
    /// A virgin point (C_p⁻¹ = 1) on `path`.
    pub fn new(mat: Material, opts: UpdateOptions, path: LoadPath) -> Self {
        Self {
            mat,
            opts,
            path,
            cp_inv: VOIGT_IDENTITY,
            lateral: 1.0,
        }
    }

    /// The stored state C_p⁻¹.
    pub fn cp_inv(&self) -> &Voigt {
        &self.cp_inv
    }

    /// Advances the point to `strain` in one increment and commits the state.
    pub fn step_to(&mut self, strain: Real) -> Result<PointSample, DriveError> {
        if self.path == LoadPath::UniaxialStress {
            self.lateral = self.solve_lateral(strain)?;
        }
        let f = self.path.deformation(strain, self.lateral);
        let up = update_point(&self.mat, &self.opts, &f, &mut self.cp_inv)?;
        Ok(PointSample {
            strain,
            f,
            tau: up.tau,
            info: up.info,
        })
    }

    /// Lateral stress τ_xx for a trial lateral stretch, without committing.
    fn lateral_stress(&self, strain: Real, lateral: Real) -> Result<Real, UpdateError> {
        let mut state = self.cp_inv;
        let f = self.path.deformation(strain, lateral);
        let up = update_point(&self.mat, &self.opts, &f, &mut state)?;
        Ok(0.5 * (up.tau[XX] + up.tau[YY]))
    }

    /// Newton (finite-difference slope) on the lateral stretch λ so that the
    /// lateral Kirchhoff stress vanishes.
    fn solve_lateral(&self, strain: Real) -> Result<Real, DriveError> {
        let tol = LATERAL_TOL * self.mat.params.youngs_modulus_pa;
        let mut lam = self.lateral;
        let mut r = self.lateral_stress(strain, lam)?;
        for _ in 0..LATERAL_MAX_ITERATIONS {
            if math::abs(r) <= tol {
                return Ok(lam);
            }
            let h = 1.0e-7 * lam;
            let slope = (self.lateral_stress(strain, lam + h)? - r) / h;
            let mut step = -r / slope;
            if !step.is_finite() {
                break;
            }
            // Keep the stretch positive.
            while lam + step <= 0.0 {
                step *= 0.5;
            }
            lam += step;
            r = self.lateral_stress(strain, lam)?;
        }
        if math::abs(r) <= tol {
            Ok(lam)
        } else {
            Err(DriveError::LateralNoConvergence {
                residual_pa: math::abs(r),
            })
        }
    }
}
