//! The die-compaction scene (physics.md §6 "Transfer to FE"): one granule
//! mesh, randomly rotated, at every centre of a poured packing, with zero
//! velocity; the lower punch at z = 0, the die wall at r = R_d, and the
//! upper punch starting at the bed height H0 = max(z + r) and moving down
//! at constant speed. Compression starts at once (the bed is not
//! pre-settled).

use granbed_kernel::Real;
use granbed_kernel::analysis::quasi_static::ImposedCompression;
use granbed_kernel::contact::wall::{Plane, Wall};
use granbed_kernel::rng::Rng;

use super::{Placement, WallSpec};

/// The die and the punch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DieScene {
    /// Die radius R_d, m.
    pub die_radius_m: Real,
    /// Bed height H0 = max(z + r), where the upper punch starts, m.
    pub bed_height_m: Real,
    /// Upper-punch speed (downwards), m/s.
    pub punch_speed_m_s: Real,
}

/// Indices of the walls in [`DieScene::walls`].
pub mod wall_index {
    /// The lower punch z = 0.
    pub const LOWER: usize = 0;
    /// The die wall.
    pub const DIE: usize = 1;
    /// The upper punch.
    pub const UPPER: usize = 2;
}

impl DieScene {
    /// The scene for spheres of `radius` at `centres` in a die of
    /// `die_radius_m`, pressed at `punch_speed_m_s`.
    pub fn new(
        centres: &[[Real; 3]],
        radius: Real,
        die_radius_m: Real,
        punch_speed_m_s: Real,
    ) -> Self {
        let bed_height_m = centres.iter().fold(0.0, |h: Real, c| h.max(c[2] + radius));
        Self {
            die_radius_m,
            bed_height_m,
            punch_speed_m_s,
        }
    }

    /// Lower punch, die wall, upper punch (see [`wall_index`]).
    pub fn walls(&self) -> Vec<WallSpec> {
        let lower = Wall::Plane(Plane {
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
        });
        let upper = Wall::Plane(Plane {
            normal: [0.0, 0.0, -1.0],
            offset: -self.bed_height_m,
        });
        vec![
            WallSpec::fixed(lower),
            WallSpec::fixed(Wall::Die {
                radius: self.die_radius_m,
            }),
            WallSpec::moving(upper, self.punch_speed_m_s, Real::INFINITY),
        ]
    }

    /// The affine compression the punches impose at time `t`: the lower
    /// punch at rest at z = 0, the upper one at H0 − v t moving down at v
    /// (the walls of [`Self::walls`]).
    pub fn imposed_at(&self, t: Real) -> ImposedCompression {
        ImposedCompression {
            lower_z_m: 0.0,
            lower_velocity_m_s: 0.0,
            upper_z_m: self.bed_height_m - self.punch_speed_m_s * t,
            upper_velocity_m_s: -self.punch_speed_m_s,
        }
    }

    /// Axial strain (punch travel / H0) at time `t`.
    pub fn strain_at(&self, t: Real) -> Real {
        self.punch_speed_m_s * t / self.bed_height_m
    }

    /// The nominal axial strain (H0 − H)/H0 with the upper punch at height
    /// `upper_z_m` (the lower one at 0): the strain of a punch withdrawing.
    pub fn strain_at_height(&self, upper_z_m: Real) -> Real {
        (self.bed_height_m - upper_z_m) / self.bed_height_m
    }

    /// Time at which the axial strain reaches `strain`, s.
    pub fn time_of_strain(&self, strain: Real) -> Real {
        strain * self.bed_height_m / self.punch_speed_m_s
    }
}

/// One placement per centre, at rest, with rotations drawn uniformly on
/// SO(3) from the generator seeded with `seed` (the same seed gives the
/// same rotations).
pub fn placements(centres: &[[Real; 3]], seed: u64) -> Vec<Placement> {
    let mut rng = Rng::new(seed);
    centres
        .iter()
        .map(|&centre| Placement {
            rotation: random_rotation(&mut rng),
            ..Placement::at(centre)
        })
        .collect()
}

/// A rotation matrix (row-major) uniform on SO(3): the unit quaternion of
/// Shoemake's method from three uniform numbers.
pub fn random_rotation(rng: &mut Rng) -> [[Real; 3]; 3] {
    let (u1, u2, u3) = (rng.unit(), rng.unit(), rng.unit());
    let tau = 2.0 * core::f64::consts::PI;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (w, x, y, z) = (
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    );
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_rotations_are_proper_orthogonal_and_reproducible() {
        let mut rng = Rng::new(5);
        for _ in 0..100 {
            let r = random_rotation(&mut rng);
            for i in 0..3 {
                for j in 0..3 {
                    let dot: Real = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!((dot - expected).abs() < 1e-14);
                }
            }
            let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
                - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
                + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
            assert!((det - 1.0).abs() < 1e-14);
        }
        let a = placements(&[[0.0; 3]; 3], 9);
        let b = placements(&[[0.0; 3]; 3], 9);
        assert_eq!(a, b);
        assert_ne!(a[0].rotation, a[1].rotation);
    }
}
