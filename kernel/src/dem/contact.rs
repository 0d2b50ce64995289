//! The discrete-element contact law (physics.md §6): Hertz normal force with
//! viscous damping set by a coefficient of restitution, and a Mindlin-type
//! tangential spring capped by Coulomb friction.
//!
//! Normal: F_n = (4/3) E* √R* δ^{3/2} − γ_n v_n, γ_n = −2√(5/6) β √(S_n m*),
//! S_n = 2E*√(R*δ), β = ln e / √(ln²e + π²); never attractive.
//! Tangential: the spring history ξ (projected onto the current tangent
//! plane) grows by v_t Δt; F_t = −S_t ξ − γ_t v_t, S_t = 8G*√(R*δ),
//! γ_t = −2√(5/6) β √(S_t m*); if |F_t| > μF_n it slips: F_t is scaled to
//! μF_n and ξ set consistent with it.

use crate::{Real, math};

/// Effective properties of one kind of contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// Effective Young's modulus E*, Pa.
    pub e_star: Real,
    /// Effective shear modulus G*, Pa.
    pub g_star: Real,
    /// Effective radius R*, m.
    pub r_star: Real,
    /// Effective mass m*, kg.
    pub m_star: Real,
    /// Coulomb friction coefficient μ.
    pub friction: Real,
    /// 2√(5/6)·√(2E* m*): γ_n = −β × this × (R*δ)^{1/4}.
    pub damping_normal: Real,
    /// 2√(5/6)·√(8G* m*): γ_t = −β × this × (R*δ)^{1/4}.
    pub damping_tangential: Real,
}

impl ContactLaw {
    fn new(e_star: Real, g_star: Real, r_star: Real, m_star: Real, friction: Real) -> Self {
        let k = 2.0 * math::sqrt(5.0 / 6.0);
        Self {
            e_star,
            g_star,
            r_star,
            m_star,
            friction,
            damping_normal: k * math::sqrt(2.0 * e_star * m_star),
            damping_tangential: k * math::sqrt(8.0 * g_star * m_star),
        }
    }

    /// Two identical spheres (radius `r`, m; mass `m`, kg) of an isotropic
    /// solid (Young's modulus `youngs`, Pa; Poisson's ratio `poisson`),
    /// with Coulomb `friction` (dimensionless).
    pub fn sphere_sphere(youngs: Real, poisson: Real, r: Real, m: Real, friction: Real) -> Self {
        let g = youngs / (2.0 * (1.0 + poisson));
        Self::new(
            youngs / (2.0 * (1.0 - poisson * poisson)),
            g / (2.0 * (2.0 - poisson)),
            0.5 * r,
            0.5 * m,
            friction,
        )
    }

    /// A sphere (radius `r`, m; mass `m`, kg; `youngs`, Pa; `poisson`)
    /// against a rigid flat wall, with Coulomb `friction`.
    pub fn sphere_wall(youngs: Real, poisson: Real, r: Real, m: Real, friction: Real) -> Self {
        let g = youngs / (2.0 * (1.0 + poisson));
        Self::new(
            youngs / (1.0 - poisson * poisson),
            g / (2.0 - poisson),
            r,
            m,
            friction,
        )
    }
}

/// β = ln e/√(ln²e + π²) of a coefficient of restitution 0 < e ≤ 1 (β ≤ 0):
/// exact for a linear spring, but with the Hertz spring it gives a higher
/// restitution (0.55 for e = 0.5); use [`hertz_beta`] for the exact value.
pub fn damping_beta(restitution: Real) -> Real {
    let l = math::ln(restitution);
    l / math::sqrt(l * l + core::f64::consts::PI * core::f64::consts::PI)
}

/// Normal restitution of a Hertz contact damped with β: the outgoing over
/// incoming normal speed. Scaled to x'' = −x^{3/2} − a x^{1/4} x' with
/// a = −√5 β, it depends on β alone (not on speed, mass or stiffness);
/// integrated by RK4 until the (never attractive) force vanishes.
pub fn hertz_restitution(beta: Real) -> Real {
    let a = -math::sqrt(5.0) * beta;
    let accel = |x: Real, v: Real| {
        let xp = math::max(x, 0.0);
        let root = math::sqrt(math::sqrt(xp));
        math::min(0.0, -xp * math::sqrt(xp) - a * root * v)
    };
    let (mut x, mut v, h) = (0.0, 1.0, 1.0e-3);
    for _ in 0..200_000 {
        let k1 = (v, accel(x, v));
        let k2 = (
            v + 0.5 * h * k1.1,
            accel(x + 0.5 * h * k1.0, v + 0.5 * h * k1.1),
        );
        let k3 = (
            v + 0.5 * h * k2.1,
            accel(x + 0.5 * h * k2.0, v + 0.5 * h * k2.1),
        );
        let k4 = (v + h * k3.1, accel(x + h * k3.0, v + h * k3.1));
        x += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        // Separation: moving out and the force has vanished (or x back to 0).
        if v < 0.0 && (x <= 0.0 || accel(x, v) == 0.0) {
            return -v;
        }
    }
    0.0
}

/// The β for which a Hertz contact has normal restitution `e` (0 < e ≤ 1),
/// by bisection on [`hertz_restitution`].
pub fn hertz_beta(restitution: Real) -> Real {
    if restitution >= 1.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (-1.0, 0.0); // restitution rises from lo to hi
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if hertz_restitution(mid) < restitution {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn dot(a: &[Real; 3], b: &[Real; 3]) -> Real {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The contact force of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactForce {
    /// Total force on the first body (normal + tangential), N; the second
    /// gets its negative.
    pub force: [Real; 3],
    /// Tangential part of `force`, N.
    pub tangential: [Real; 3],
    /// Normal force magnitude F_n ≥ 0, N.
    pub normal: Real,
}

/// Force on body i of a contact with overlap `delta` > 0 (m), unit normal `n`
/// pointing from the other body to i, relative velocity of i at the contact
/// point `v_rel` (m/s), and spring history `xi` (m, in/out). `beta` from
/// [`damping_beta`]; `dt` the step (s).
#[inline(always)]
pub fn hertz_mindlin(
    law: &ContactLaw,
    beta: Real,
    delta: Real,
    n: &[Real; 3],
    v_rel: &[Real; 3],
    xi: &mut [Real; 3],
    dt: Real,
) -> ContactForce {
    let root = math::sqrt(law.r_star * delta);
    let s_n = 2.0 * law.e_star * root;
    let s_t = 8.0 * law.g_star * root;
    // γ = −2√(5/6) β √(S m*), with √S = √(2E* or 8G*) · (R*δ)^{1/4}.
    let quarter = -beta * math::sqrt(root);
    let gamma_n = quarter * law.damping_normal;
    let gamma_t = quarter * law.damping_tangential;
    let vn = dot(v_rel, n);
    let push = (2.0 / 3.0) * s_n * delta - gamma_n * vn;
    let normal = if push > 0.0 { push } else { 0.0 };
    let vt: [Real; 3] = core::array::from_fn(|a| v_rel[a] - vn * n[a]);
    // Keep the history in the current tangent plane, then load it.
    let xn = dot(xi, n);
    for a in 0..3 {
        xi[a] += -xn * n[a] + vt[a] * dt;
    }
    let mut ft: [Real; 3] = core::array::from_fn(|a| -s_t * xi[a] - gamma_t * vt[a]);
    let ft2 = dot(&ft, &ft);
    let cap = law.friction * normal;
    if ft2 > cap * cap {
        let ft_mag = math::sqrt(ft2);
        let scale = if ft_mag > 0.0 { cap / ft_mag } else { 0.0 };
        for a in 0..3 {
            ft[a] *= scale;
            xi[a] = if s_t > 0.0 {
                -(ft[a] + gamma_t * vt[a]) / s_t
            } else {
                0.0
            };
        }
    }
    ContactForce {
        force: core::array::from_fn(|a| normal * n[a] + ft[a]),
        tangential: ft,
        normal,
    }
}

/// `L` contacts evaluated side by side, component-major (`n[a][l]` is
/// component a of lane l) so that the compiler can pair the lanes in SIMD
/// registers. Inputs are set by the caller; [`hertz_mindlin_lanes`] fills
/// `force`, `torque` and updates `xi`.
#[derive(Clone, Copy, Debug)]
pub struct ContactLanes<const L: usize> {
    /// Effective radius R* of each lane's law, m.
    pub r_star: [Real; L],
    /// Effective Young's modulus E* of each lane's law, Pa.
    pub e_star: [Real; L],
    /// G* of each lane's law, Pa.
    pub g_star: [Real; L],
    /// Friction coefficient of each lane's law.
    pub friction: [Real; L],
    /// [`ContactLaw::damping_normal`] of each lane's law.
    pub damping_normal: [Real; L],
    /// [`ContactLaw::damping_tangential`] of each lane's law.
    pub damping_tangential: [Real; L],
    /// Overlap δ > 0, m.
    pub delta: [Real; L],
    /// Unit normal from the partner to sphere i.
    pub n: [[Real; L]; 3],
    /// v_i − v_j (v_j = 0 for a wall), m/s.
    pub dv: [[Real; L]; 3],
    /// ω_i + ω_j (ω_j = 0 for a wall), rad/s.
    pub w: [[Real; L]; 3],
    /// Tangential spring history ξ, m (in/out).
    pub xi: [[Real; L]; 3],
    /// Force on sphere i (out), N.
    pub force: [[Real; L]; 3],
    /// Torque on sphere i, and on a sphere partner j (out), N m.
    pub torque: [[Real; L]; 3],
}

impl<const L: usize> ContactLanes<L> {
    /// All lanes zero.
    pub const ZERO: Self = Self {
        r_star: [0.0; L],
        e_star: [0.0; L],
        g_star: [0.0; L],
        friction: [0.0; L],
        damping_normal: [0.0; L],
        damping_tangential: [0.0; L],
        delta: [0.0; L],
        n: [[0.0; L]; 3],
        dv: [[0.0; L]; 3],
        w: [[0.0; L]; 3],
        xi: [[0.0; L]; 3],
        force: [[0.0; L]; 3],
        torque: [[0.0; L]; 3],
    };

    /// Sets lane `l`'s law.
    ///
    /// # Panics
    /// If `l` ≥ `L`.
    #[inline(always)]
    pub fn set_law(&mut self, l: usize, law: &ContactLaw) {
        self.r_star[l] = law.r_star;
        self.e_star[l] = law.e_star;
        self.g_star[l] = law.g_star;
        self.friction[l] = law.friction;
        self.damping_normal[l] = law.damping_normal;
        self.damping_tangential[l] = law.damping_tangential;
    }
}

#[inline(always)]
fn lane<const L: usize>(f: impl FnMut(usize) -> Real) -> [Real; L] {
    core::array::from_fn(f)
}

/// [`hertz_mindlin`] for `L` contacts at once, followed by the torque
/// (−r n) × F_t on sphere i (the same on a sphere partner) of spheres of
/// radius `r`, with v_rel = (v_i − v_j) − r (ω_i + ω_j) × n. Every lane does
/// exactly the operations of the single-contact path, in the same order,
/// so the results are the same bits.
#[inline(always)]
pub fn hertz_mindlin_lanes<const L: usize>(c: &mut ContactLanes<L>, beta: Real, r: Real, dt: Real) {
    let (n, w) = (&c.n, &c.w);
    let wxn = [
        lane::<L>(|l| w[1][l] * n[2][l] - w[2][l] * n[1][l]),
        lane::<L>(|l| w[2][l] * n[0][l] - w[0][l] * n[2][l]),
        lane::<L>(|l| w[0][l] * n[1][l] - w[1][l] * n[0][l]),
    ];
    let v_rel: [[Real; L]; 3] = core::array::from_fn(|a| lane::<L>(|l| c.dv[a][l] - r * wxn[a][l]));
    let root = lane::<L>(|l| math::sqrt(c.r_star[l] * c.delta[l]));
    let s_n = lane::<L>(|l| 2.0 * c.e_star[l] * root[l]);
    let s_t = lane::<L>(|l| 8.0 * c.g_star[l] * root[l]);
    let quarter = lane::<L>(|l| -beta * math::sqrt(root[l]));
    let gamma_n = lane::<L>(|l| quarter[l] * c.damping_normal[l]);
    let gamma_t = lane::<L>(|l| quarter[l] * c.damping_tangential[l]);
    let vn = lane::<L>(|l| v_rel[0][l] * n[0][l] + v_rel[1][l] * n[1][l] + v_rel[2][l] * n[2][l]);
    let push = lane::<L>(|l| (2.0 / 3.0) * s_n[l] * c.delta[l] - gamma_n[l] * vn[l]);
    let normal = lane::<L>(|l| if push[l] > 0.0 { push[l] } else { 0.0 });
    let vt: [[Real; L]; 3] = core::array::from_fn(|a| lane::<L>(|l| v_rel[a][l] - vn[l] * n[a][l]));
    let xi = &mut c.xi;
    let xn = lane::<L>(|l| xi[0][l] * n[0][l] + xi[1][l] * n[1][l] + xi[2][l] * n[2][l]);
    for a in 0..3 {
        xi[a] = lane::<L>(|l| xi[a][l] + (-xn[l] * n[a][l] + vt[a][l] * dt));
    }
    let mut ft: [[Real; L]; 3] =
        core::array::from_fn(|a| lane::<L>(|l| -s_t[l] * xi[a][l] - gamma_t[l] * vt[a][l]));
    let ft2 = lane::<L>(|l| ft[0][l] * ft[0][l] + ft[1][l] * ft[1][l] + ft[2][l] * ft[2][l]);
    let cap = lane::<L>(|l| c.friction[l] * normal[l]);
    for l in 0..L {
        if ft2[l] > cap[l] * cap[l] {
            let ft_mag = math::sqrt(ft2[l]);
            let scale = if ft_mag > 0.0 { cap[l] / ft_mag } else { 0.0 };
            for a in 0..3 {
                ft[a][l] *= scale;
                xi[a][l] = if s_t[l] > 0.0 {
                    -(ft[a][l] + gamma_t[l] * vt[a][l]) / s_t[l]
                } else {
                    0.0
                };
            }
        }
    }
    c.force = core::array::from_fn(|a| lane::<L>(|l| normal[l] * n[a][l] + ft[a][l]));
    c.torque = [
        lane::<L>(|l| -r * (n[1][l] * ft[2][l] - n[2][l] * ft[1][l])),
        lane::<L>(|l| -r * (n[2][l] * ft[0][l] - n[0][l] * ft[2][l])),
        lane::<L>(|l| -r * (n[0][l] * ft[1][l] - n[1][l] * ft[0][l])),
    ];
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hertz_force_and_energy_conserving_limit() {
        let law = ContactLaw::sphere_wall(100e6, 0.3, 0.5e-3, 1e-6, 0.1);
        let mut xi = [0.0; 3];
        let f = hertz_mindlin(&law, 0.0, 1e-6, &[0.0, 0.0, 1.0], &[0.0; 3], &mut xi, 1e-6);
        let expect = 4.0 / 3.0 * law.e_star * (law.r_star).sqrt() * (1e-6f64).powf(1.5);
        assert!((f.normal - expect).abs() < 1e-12 * expect);
        assert_eq!(damping_beta(1.0), 0.0);
        assert!(damping_beta(0.5) < 0.0);
    }

    #[test]
    fn hertz_beta_inverts_the_restitution() {
        assert!(
            (hertz_restitution(0.0) - 1.0).abs() < 1e-6,
            "undamped contact is elastic"
        );
        for e in [0.3, 0.5, 0.9] {
            let b = hertz_beta(e);
            assert!((hertz_restitution(b) - e).abs() < 1e-6);
            // The linear-spring formula under-damps a Hertz contact.
            assert!(hertz_restitution(damping_beta(e)) > e);
        }
    }

    #[test]
    fn friction_caps_the_tangential_force() {
        let law = ContactLaw::sphere_wall(100e6, 0.3, 0.5e-3, 1e-6, 0.1);
        let mut xi = [0.0; 3];
        let n = [0.0, 0.0, 1.0];
        let mut last = 0.0;
        for _ in 0..1000 {
            let f = hertz_mindlin(&law, 0.0, 1e-6, &n, &[0.1, 0.0, 0.0], &mut xi, 1e-6);
            let ft = f.tangential[0].abs();
            assert!(ft <= 0.1 * f.normal * (1.0 + 1e-12));
            assert!(f.tangential[0] <= 0.0, "opposes the slip");
            last = ft;
        }
        let f_n = 4.0 / 3.0 * law.e_star * law.r_star.sqrt() * 1e-9;
        assert!((last - 0.1 * f_n).abs() < 1e-9 * f_n, "slides at mu F_n");
    }
    #[test]
    fn lanes_give_the_bits_of_the_single_contact() {
        let pp = ContactLaw::sphere_sphere(100e6, 0.3, 0.5e-3, 6e-7, 0.1);
        let pw = ContactLaw::sphere_wall(100e6, 0.3, 0.5e-3, 6e-7, 0.1);
        let (beta, r, dt) = (hertz_beta(0.5), 0.5e-3, 1e-6);
        let mut rng = crate::rng::Rng::new(3);
        let mut slips = 0;
        for round in 0..500 {
            let mut c = ContactLanes::<4>::ZERO;
            let mut single = [([0.0; 3], [0.0; 3], [0.0; 3]); 4];
            for (l, out) in single.iter_mut().enumerate() {
                let law = if (round + l) % 3 == 0 { &pw } else { &pp };
                c.set_law(l, law);
                let d: [Real; 3] = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
                let len = math::sqrt(dot(&d, &d));
                let n = d.map(|x| x / len);
                let delta = rng.uniform(1e-9, 1e-6);
                let dv: [Real; 3] = core::array::from_fn(|_| rng.uniform(-1e-3, 1e-3));
                let w: [Real; 3] = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
                let mut xi: [Real; 3] = core::array::from_fn(|_| rng.uniform(-1e-8, 1e-8));
                c.delta[l] = delta;
                for a in 0..3 {
                    (c.n[a][l], c.dv[a][l], c.w[a][l], c.xi[a][l]) = (n[a], dv[a], w[a], xi[a]);
                }
                // The single-contact path of the pour before the lanes.
                let wxn = [
                    w[1] * n[2] - w[2] * n[1],
                    w[2] * n[0] - w[0] * n[2],
                    w[0] * n[1] - w[1] * n[0],
                ];
                let v_rel: [Real; 3] = core::array::from_fn(|a| dv[a] - r * wxn[a]);
                let f = hertz_mindlin(law, beta, delta, &n, &v_rel, &mut xi, dt);
                let ft = f.tangential;
                slips += usize::from(
                    dot(&ft, &ft) >= (0.1 * f.normal) * (0.1 * f.normal) * (1.0 - 1e-9),
                );
                let t = [
                    -r * (n[1] * ft[2] - n[2] * ft[1]),
                    -r * (n[2] * ft[0] - n[0] * ft[2]),
                    -r * (n[0] * ft[1] - n[1] * ft[0]),
                ];
                *out = (f.force, t, xi);
            }
            hertz_mindlin_lanes(&mut c, beta, r, dt);
            for (l, (force, t, xi)) in single.iter().enumerate() {
                for a in 0..3 {
                    assert_eq!(c.force[a][l].to_bits(), force[a].to_bits());
                    assert_eq!(c.torque[a][l].to_bits(), t[a].to_bits());
                    assert_eq!(c.xi[a][l].to_bits(), xi[a].to_bits());
                }
            }
        }
        assert!(
            slips > 100 && slips < 1900,
            "both sticking and sliding: {slips}"
        );
    }
}
