//! Geometric measures of a bed of equal spheres in a cylindrical die
//! (physics.md §6): bed height, packing fractions (whole bed and the
//! interior region away from the walls and the top), contacts and the
//! coordination number.
//!
//! Everything here is plain `f64` geometry with no kernel types, so the
//! functions can move into the kernel later. The die axis is the z axis,
//! its floor z = 0.
//!
//! The interior packing fraction needs the volume of a sphere inside a
//! cylinder and between two planes. [`sphere_cylinder_slab_volume`]
//! integrates over z the area of the sphere's cross-section disk inside the
//! cylinder's disk ([`disk_intersection_area`], written so it stays
//! accurate for a cylinder far larger than the sphere). The integrand is a
//! quadratic polynomial where the cross-section lies wholly inside the
//! cylinder (integrated in closed form), a constant or zero where it covers
//! the cylinder's disk or misses it, and a smooth lens area in between;
//! where the regimes meet (the cross-section's circle touches the
//! cylinder's) the lens area behaves like |z − z_k|^{3/2}. The lens pieces,
//! split at those z_k, are integrated by composite 20-point Gauss–Legendre
//! on panels graded geometrically towards both ends, which keeps the error
//! at round-off level (checked against closed forms in the tests).

use core::f64::consts::PI;
use std::sync::OnceLock;

/// Highest sphere top max(z + r) of spheres of radius `radius` centred at
/// `centres`, m; −∞ for no spheres.
pub fn bed_height(centres: &[[f64; 3]], radius: f64) -> f64 {
    centres
        .iter()
        .fold(f64::NEG_INFINITY, |h, c| h.max(c[2] + radius))
}

/// Volume of a sphere of radius `r`, (4/3)πr³.
pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * PI * r * r * r
}

/// Packing fraction of `n` spheres of radius `radius` in a die of radius
/// `die_radius` filled to `height`: n·(4/3)πr³ / (π R² H).
pub fn packing_fraction(n: usize, radius: f64, die_radius: f64, height: f64) -> f64 {
    n as f64 * sphere_volume(radius) / (PI * die_radius * die_radius * height)
}

/// The interior region of a bed: the cylinder of radius `radius` about the
/// die axis between the planes `z_lo` and `z_hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Radius of the region's cylinder, m.
    pub radius: f64,
    /// Bottom plane, m.
    pub z_lo: f64,
    /// Top plane, m.
    pub z_hi: f64,
}

impl Region {
    /// The interior of a bed of height `height` in a die of radius
    /// `die_radius`: everything at least `margin` from the die wall, the
    /// floor and the bed top (physics.md §6 uses margin = 2 diameters).
    /// `None` if that leaves no volume.
    pub fn interior(die_radius: f64, height: f64, margin: f64) -> Option<Self> {
        let region = Self {
            radius: die_radius - margin,
            z_lo: margin,
            z_hi: height - margin,
        };
        (region.radius > 0.0 && region.z_hi > region.z_lo).then_some(region)
    }

    /// Volume of the region, π R² (z_hi − z_lo), m³.
    pub fn volume(&self) -> f64 {
        PI * self.radius * self.radius * (self.z_hi - self.z_lo)
    }

    /// Solid fraction of the region: the summed volume of the spheres of
    /// radius `radius` centred at `centres` inside it (overlaps between
    /// spheres counted twice; they are below a micrometre in a settled bed)
    /// over its volume.
    pub fn packing_fraction(&self, centres: &[[f64; 3]], radius: f64) -> f64 {
        let solid: f64 = centres
            .iter()
            .map(|c| sphere_cylinder_slab_volume(*c, radius, self.radius, self.z_lo, self.z_hi))
            .sum();
        solid / self.volume()
    }
}

/// `φ − sin φ` for 0 ≤ φ ≤ 2π without cancellation for small φ.
fn angle_minus_sine(phi: f64) -> f64 {
    if phi >= 1.0 {
        return phi - phi.sin();
    }
    // φ³/3! − φ⁵/5! + …: the terms fall by φ²/((2k)(2k+1)) ≤ 1/20 each.
    let phi2 = phi * phi;
    let mut term = phi * phi2 / 6.0;
    let mut sum: f64 = 0.0;
    let mut k = 2.0;
    while term.abs() > 1e-17 * sum.abs() && k < 60.0 {
        sum += term;
        term *= -phi2 / (k * 2.0 * (k * 2.0 + 1.0));
        k += 1.0;
    }
    sum
}

/// Area of the part of a disk of radius `rho` beyond a chord, given the
/// chord's distance from the far edge of the disk `e` = ρ − h, where h is
/// the chord's signed distance from the centre (0 ≤ e ≤ 2ρ):
/// ρ²(2θ − sin 2θ)/2 with θ the half-angle of the chord. Passing `e`
/// instead of h keeps a thin segment of a large disk accurate.
fn segment_area(rho: f64, e: f64) -> f64 {
    let e = e.clamp(0.0, 2.0 * rho);
    let half_chord = (e * (2.0 * rho - e)).sqrt();
    let theta = half_chord.atan2(rho - e);
    0.5 * rho * rho * angle_minus_sine(2.0 * theta)
}

/// Area of the intersection of two disks of radii `a` and `b` (≥ 0) whose
/// centres are `dist` (≥ 0) apart, m².
///
/// The lens is the sum of two circular segments cut by the common chord.
/// Each segment is computed from its thickness (the chord's distance from
/// the disk's far edge), formed from the signed gap `dist − larger radius`,
/// so the result stays accurate to round-off in the absolute sense even for
/// a disk much larger than the other (the half-plane limit).
pub fn disk_intersection_area(a: f64, b: f64, dist: f64) -> f64 {
    let (small, large) = if a <= b { (a, b) } else { (b, a) };
    if small <= 0.0 || dist >= small + large {
        return 0.0;
    }
    if dist + small <= large {
        return PI * small * small;
    }
    // Signed gap of the small centre outside the large circle.
    let gap = dist - large;
    // Chord position from the small centre towards the large one:
    // h = (D² + s² − L²)/(2D) = (gap (D + L) + s²)/(2D).
    let h = (gap * (dist + large) + small * small) / (2.0 * dist);
    // The small disk's segment beyond the chord has thickness s − h; the
    // large disk's, on the other side, L − (D − h) = h − gap.
    segment_area(small, small - h) + segment_area(large, h - gap)
}

/// Nodes and weights of the 20-point Gauss–Legendre rule on [−1, 1].
fn gauss_legendre_20() -> &'static ([f64; 20], [f64; 20]) {
    static RULE: OnceLock<([f64; 20], [f64; 20])> = OnceLock::new();
    RULE.get_or_init(gauss_legendre::<20>)
}

/// The `N`-point Gauss–Legendre rule on [−1, 1] (nodes ascending), by
/// Newton's method on the Legendre polynomial P_N.
fn gauss_legendre<const N: usize>() -> ([f64; N], [f64; N]) {
    let (mut nodes, mut weights) = ([0.0; N], [0.0; N]);
    let n = N as f64;
    for i in 0..N.div_ceil(2) {
        let mut x = (PI * (i as f64 + 0.75) / (n + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_N(x) by the three-term recurrence, P_N' from P_N and P_{N−1}.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=N {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        nodes[i] = -x;
        nodes[N - 1 - i] = x;
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        weights[i] = w;
        weights[N - 1 - i] = w;
    }
    (nodes, weights)
}

/// Ratio of successive panel lengths of [`graded_integral`] towards an end.
const GRADING: f64 = 0.2;
/// Number of graded panels towards each end (the smallest is 0.2¹² / 2 ≈
/// 2e-9 of the interval).
const GRADED_LEVELS: i32 = 12;

/// ∫ f over [lo, hi] by 20-point Gauss–Legendre on panels graded
/// geometrically towards both ends, for integrands that are smooth inside
/// the interval but may behave like |z − end|^α (α > 0) at its ends.
fn graded_integral(f: &dyn Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let (nodes, weights) = gauss_legendre_20();
    let len = hi - lo;
    let mut edges = Vec::with_capacity(2 * GRADED_LEVELS as usize + 3);
    edges.push(0.0);
    edges.extend((1..=GRADED_LEVELS).rev().map(|k| 0.5 * GRADING.powi(k)));
    edges.push(0.5);
    edges.extend((1..=GRADED_LEVELS).map(|k| 1.0 - 0.5 * GRADING.powi(k)));
    edges.push(1.0);
    let mut sum = 0.0;
    for w in edges.windows(2) {
        let (a, b) = (lo + w[0] * len, lo + w[1] * len);
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        let panel: f64 = nodes
            .iter()
            .zip(weights)
            .map(|(x, wt)| wt * f(mid + half * x))
            .sum();
        sum += half * panel;
    }
    sum
}

/// Volume of the part of the sphere (centre `centre`, radius `r`) inside
/// the cylinder of radius `cyl_radius` about the z axis and between the
/// planes z = `z_lo` and z = `z_hi`, m³.
///
/// Exact (closed form) where the sphere's cross-sections lie wholly inside
/// or outside the cylinder; elsewhere the integral over z of
/// [`disk_intersection_area`] of the cross-section and the cylinder's disk,
/// split where the two circles touch and integrated by graded
/// Gauss–Legendre (see the module docs), accurate to about 1e-13 of the
/// sphere's volume.
pub fn sphere_cylinder_slab_volume(
    centre: [f64; 3],
    r: f64,
    cyl_radius: f64,
    z_lo: f64,
    z_hi: f64,
) -> f64 {
    let lo = z_lo.max(centre[2] - r);
    let hi = z_hi.min(centre[2] + r);
    if !(r > 0.0 && cyl_radius > 0.0 && hi > lo) {
        return 0.0;
    }
    let dist = centre[0].hypot(centre[1]);
    let gap = dist - cyl_radius;
    // Cross-section radius a(z) = √(r² − (z − z_c)²).
    let section = |z: f64| {
        let t = z - centre[2];
        ((r - t) * (r + t)).max(0.0).sqrt()
    };
    // The regime changes where a(z) = |gap| (the circles touch, inside or
    // outside) or a(z) = dist + R (the cross-section starts to cover the
    // cylinder's disk).
    let mut breaks = vec![lo, hi];
    for touch in [gap.abs(), dist + cyl_radius] {
        if touch <= r {
            let s = ((r - touch) * (r + touch)).sqrt();
            for z in [centre[2] - s, centre[2] + s] {
                if z > lo && z < hi {
                    breaks.push(z);
                }
            }
        }
    }
    breaks.sort_by(f64::total_cmp);
    let mut volume = 0.0;
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let a_mid = section(0.5 * (a + b));
        volume += if a_mid + dist <= cyl_radius {
            // Wholly inside: ∫ π (r² − t²) dt.
            let antiderivative = |z: f64| {
                let t = z - centre[2];
                PI * t * (r * r - t * t / 3.0)
            };
            antiderivative(b) - antiderivative(a)
        } else if a_mid <= gap {
            0.0
        } else if a_mid >= dist + cyl_radius {
            PI * cyl_radius * cyl_radius * (b - a)
        } else {
            graded_integral(
                &|z| disk_intersection_area(section(z), cyl_radius, dist),
                a,
                b,
            )
        };
    }
    volume
}

/// Sphere–sphere contacts of a bed: pairs whose centres are closer than one
/// diameter (overlapping).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SphereContacts {
    /// Overlapping pairs.
    pub pairs: usize,
    /// Largest overlap 2r − |x_i − x_j| among them, m (0 if none).
    pub max_overlap: f64,
}

/// The overlapping pairs among the candidate pairs `pairs` (sphere indices
/// i < j into `centres`) of spheres of radius `radius`. The pair list must
/// hold every pair closer than one diameter (a neighbour list does; all
/// pairs i < j do too).
pub fn sphere_contacts(
    centres: &[[f64; 3]],
    radius: f64,
    pairs: impl IntoIterator<Item = (usize, usize)>,
) -> SphereContacts {
    let mut out = SphereContacts::default();
    for (i, j) in pairs {
        let overlap = 2.0 * radius - distance(&centres[i], &centres[j]);
        if overlap > 0.0 {
            out.pairs += 1;
            out.max_overlap = out.max_overlap.max(overlap);
        }
    }
    out
}

/// |p − q|, with the differences taken p − q.
pub fn distance(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Coordination number Z = 2 × contacts / spheres (0 for no spheres).
pub fn coordination_number(contacts: usize, spheres: usize) -> f64 {
    if spheres == 0 {
        0.0
    } else {
        2.0 * contacts as f64 / spheres as f64
    }
}

/// Spheres touching the die floor and wall.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallContacts {
    /// Spheres overlapping the floor (z < r).
    pub floor: usize,
    /// Spheres overlapping the die wall (√(x² + y²) + r > R).
    pub die: usize,
    /// Largest overlap with the floor or the wall, m (0 if none).
    pub max_overlap: f64,
}

/// The floor and wall contacts of spheres of radius `radius` centred at
/// `centres` in a die of radius `die_radius`.
pub fn wall_contacts(centres: &[[f64; 3]], radius: f64, die_radius: f64) -> WallContacts {
    let mut out = WallContacts::default();
    for c in centres {
        let floor = radius - c[2];
        if floor > 0.0 {
            out.floor += 1;
            out.max_overlap = out.max_overlap.max(floor);
        }
        let wall = c[0].hypot(c[1]) + radius - die_radius;
        if wall > 0.0 {
            out.die += 1;
            out.max_overlap = out.max_overlap.max(wall);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(what: &str, got: f64, want: f64, rel: f64) {
        assert!(
            (got - want).abs() <= rel * want.abs(),
            "{what}: got {got:.17e}, want {want:.17e} (rel err {:.2e})",
            (got - want).abs() / want.abs()
        );
    }

    #[test]
    fn gauss_legendre_is_exact_to_degree_39() {
        let (x, w) = gauss_legendre_20();
        let sum = |p: i32| x.iter().zip(w).map(|(x, w)| w * x.powi(p)).sum::<f64>();
        close("weights", sum(0), 2.0, 1e-15);
        close("x^38", sum(38), 2.0 / 39.0, 1e-13);
        assert!(sum(39).abs() < 1e-15);
        assert!(x.windows(2).all(|p| p[0] < p[1]));
    }

    #[test]
    fn disk_intersections() {
        // Disjoint, contained, equal disks at distance r (lens of
        // (2π/3 − √3/2) r²), half-plane limit.
        assert_eq!(disk_intersection_area(1.0, 1.0, 2.0), 0.0);
        assert_eq!(disk_intersection_area(1.0, 3.0, 1.5), PI);
        assert_eq!(disk_intersection_area(3.0, 1.0, 1.5), PI);
        close(
            "equal disks",
            disk_intersection_area(1.0, 1.0, 1.0),
            2.0 * PI / 3.0 - 3f64.sqrt() / 2.0,
            1e-15,
        );
        for big in [1e6, 1e12] {
            close(
                "half disk",
                disk_intersection_area(1.0, big, big),
                PI / 2.0,
                2.0 / big,
            );
        }
        assert!(angle_minus_sine(1e-3) > 0.0);
        close(
            "phi - sin phi",
            angle_minus_sine(0.5),
            0.5 - 0.5f64.sin(),
            1e-15,
        );
    }

    #[test]
    fn sphere_wholly_inside_is_the_sphere() {
        let r = 0.5e-3;
        let v = sphere_cylinder_slab_volume([1e-3, -0.5e-3, 3e-3], r, 3e-3, 1e-3, 8e-3);
        close("inside", v, sphere_volume(r), 1e-14);
        // Outside radially, below, above.
        assert_eq!(
            sphere_cylinder_slab_volume([3.6e-3, 0.0, 3e-3], r, 3e-3, 0.0, 1.0),
            0.0
        );
        assert_eq!(
            sphere_cylinder_slab_volume([0.0, 0.0, 0.4e-3], r, 3e-3, 1e-3, 8e-3),
            0.0
        );
        assert_eq!(
            sphere_cylinder_slab_volume([0.0, 0.0, 8.5e-3], r, 3e-3, 1e-3, 8e-3),
            0.0
        );
    }

    #[test]
    fn slab_cuts_spherical_caps() {
        // A sphere on the axis with a cap of height h cut off below and one
        // of height k above: V = 4/3 π r³ − π h²(3r − h)/3 − π k²(3r − k)/3.
        let (r, zc) = (2.0, 5.0);
        let cap = |h: f64| PI * h * h * (3.0 * r - h) / 3.0;
        for (h, k) in [(0.5, 0.0), (1.2, 0.7), (3.0, 0.25), (2.0, 2.0)] {
            let v = sphere_cylinder_slab_volume([0.0, 0.0, zc], r, 10.0, zc - r + h, zc + r - k);
            close("caps", v, sphere_volume(r) - cap(h) - cap(k), 1e-14);
        }
    }

    #[test]
    fn tangent_plane_limit_is_half_the_sphere() {
        // Centre on the wall of a cylinder much larger than the sphere: the
        // wall is nearly a plane through the centre. The (convex) cylinder
        // lies on its side of that tangent plane, so the inside is a little
        // less than half: the sliver between the plane and the wall,
        // u < y²/(2R) over the sphere's mid-section, is πr⁴/(8R), i.e.
        // 3r/(16R) of the half, up to O((r/R)²).
        for big in [1e4, 1e8, 1e12] {
            let v = sphere_cylinder_slab_volume([big, 0.0, 0.0], 1.0, big, -1.0, 1.0);
            let half = sphere_volume(1.0) / 2.0;
            assert!(v < half, "{v} >= {half}");
            let want = half * (1.0 - 3.0 / (16.0 * big));
            close("half", v, want, 4.0 / (big * big) + 1e-15);
        }
        // Off-axis direction and a slab cut through the centre: a quarter.
        let big = 1e9;
        let v = sphere_cylinder_slab_volume([0.6 * big, 0.8 * big, 0.0], 1.0, big, 0.0, 5.0);
        close("quarter", v, sphere_volume(1.0) / 4.0, 1e-8);
    }

    #[test]
    fn cylinder_through_the_sphere() {
        // A cylinder of radius c < r along a diameter: V = 4π/3 (r³ − (r² −
        // c²)^{3/2}).
        let r = 1.0;
        for c in [0.1, 0.5, 0.9, 0.999] {
            let v = sphere_cylinder_slab_volume([0.0, 0.0, 0.0], r, c, -2.0, 2.0);
            let want = 4.0 * PI / 3.0 * (r * r * r - (r * r - c * c).powf(1.5));
            // The closed form cancels for a thin cylinder: compare to the
            // sphere's volume.
            assert!(
                (v - want).abs() < 1e-14 * sphere_volume(r),
                "c = {c}: {v:e} vs {want:e}"
            );
        }
    }

    #[test]
    fn viviani_solid() {
        // A cylinder of radius r/2 through the centre of the sphere, its axis
        // r/2 from it (Viviani): V = (2/9)(3π − 4) r³. The lens reaches the
        // sphere's poles and touches tangentially at the equator: the hard
        // case for the quadrature.
        for r in [1.0, 0.5e-3] {
            let v = sphere_cylinder_slab_volume([0.5 * r, 0.0, 7.0 * r], r, 0.5 * r, 0.0, 20.0 * r);
            let want = 2.0 / 9.0 * (3.0 * PI - 4.0) * r * r * r;
            close("Viviani", v, want, 1e-12);
        }
    }

    #[test]
    fn volumes_add_over_slabs_and_match_the_sphere_inside() {
        // A sphere crossing the wall: the slab pieces add up, and a huge
        // cylinder holds it all.
        let (c, r, cyl) = ([2.3, 1.1, 0.4], 0.9, 2.8);
        let whole = sphere_cylinder_slab_volume(c, r, cyl, -1.0, 2.0);
        let parts: f64 = [(-1.0, 0.0), (0.0, 0.3), (0.3, 0.95), (0.95, 2.0)]
            .iter()
            .map(|&(a, b)| sphere_cylinder_slab_volume(c, r, cyl, a, b))
            .sum();
        close("additive", parts, whole, 1e-14);
        assert!(whole > 0.0 && whole < sphere_volume(r));
        close(
            "inside a big cylinder",
            sphere_cylinder_slab_volume(c, r, 1e3, -1.0, 2.0),
            sphere_volume(r),
            1e-14,
        );
    }

    #[test]
    fn bed_measures() {
        let r = 0.5;
        // 0–1 overlap by 0.01, 0–2 by 0.05; 0 and 1 sink 0.05 into the
        // floor, 3 pokes 0.3 into the wall.
        let x = [
            [0.0, 0.0, 0.45],
            [0.99, 0.0, 0.45],
            [0.0, 0.0, 1.4],
            [5.0, 0.0, 0.6],
        ];
        assert_eq!(bed_height(&x, r), 1.9);
        let all = (0..4).flat_map(|i| (i + 1..4).map(move |j| (i, j)));
        let c = sphere_contacts(&x, r, all);
        assert_eq!(c.pairs, 2);
        assert!((c.max_overlap - 0.05).abs() < 1e-15);
        assert_eq!(coordination_number(c.pairs, 4), 1.0);
        let w = wall_contacts(&x, r, 5.2);
        assert_eq!((w.floor, w.die), (2, 1));
        assert!((w.max_overlap - 0.3).abs() < 1e-15);
        close(
            "phi",
            packing_fraction(4, r, 2.0, 3.0),
            4.0 * sphere_volume(r) / (PI * 12.0),
            1e-15,
        );
        assert_eq!(Region::interior(2.0, 3.0, 2.0), None);
        let region = Region::interior(5.0, 10.0, 2.0).unwrap();
        assert_eq!((region.radius, region.z_lo, region.z_hi), (3.0, 2.0, 8.0));
        let inside = [[0.0, 0.0, 5.0]];
        close(
            "interior",
            region.packing_fraction(&inside, 1.0),
            sphere_volume(1.0) / (PI * 9.0 * 6.0),
            1e-14,
        );
    }
}
