//! Closest point of a node on a bilinear quadrilateral (physics.md §5.2).
//!
//! The quad x1..x4 (counter-clockwise seen from outside) is written
//! x(ξ, η) = c + ξ e1 + η e2 + ξη w with c = Σxᵢ/4, e1 = (−x1+x2+x3−x4)/4,
//! e2 = (−x1−x2+x3+x4)/4 and the warp w = (x1−x2+x3−x4)/4. The closest
//! point to p minimises ½|x(ξ, η) − p|²: Newton from the parallelogram
//! start ξ0 = (p−c)·e1/|e1|², η0 = (p−c)·e2/|e2|², with a projected-gradient
//! step whenever the Hessian is not positive definite.

use crate::Real;
use crate::math::{abs, max, sqrt};

/// A 3-vector.
pub type Vec3 = [Real; 3];

/// Where a point projects on a quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadProjection {
    /// Local coordinates (ξ*, η*); inside the face when both are in [−1, 1].
    pub xi: Real,
    /// See `xi`.
    pub eta: Real,
    /// The closest point x(ξ*, η*), m.
    pub point: Vec3,
    /// Unit outward normal x_ξ × x_η / |…| at (ξ*, η*).
    pub normal: Vec3,
    /// Signed gap n·(p − x_c), m: negative means p is behind the face.
    pub gap: Real,
    /// Bilinear weights Nᵢ = ¼(1+ξᵢξ*)(1+ηᵢη*) of the four corners.
    pub weights: [Real; 4],
}

impl QuadProjection {
    /// True if (ξ*, η*) lies in the face, up to `tol` (physics.md: 1e-6).
    pub fn inside(&self, tol: Real) -> bool {
        abs(self.xi) <= 1.0 + tol && abs(self.eta) <= 1.0 + tol
    }
}

/// Corner coordinates (ξᵢ, ηᵢ) in the counter-clockwise order x1..x4.
const CORNERS: [(Real, Real); 4] = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];

/// Newton iterations at most; a parallelogram converges in one.
const MAX_ITERATIONS: usize = 12;

/// Step halvings of the backtracking line search at most.
const LINE_SEARCH_HALVINGS: usize = 30;

pub(crate) fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: &Vec3, b: &Vec3) -> Real {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn axpy(a: Real, x: &Vec3, y: &Vec3) -> Vec3 {
    [y[0] + a * x[0], y[1] + a * x[1], y[2] + a * x[2]]
}

/// |a|, m.
pub(crate) fn norm(a: &Vec3) -> Real {
    sqrt(dot(a, a))
}

/// The bilinear quad in the form c + ξe1 + ηe2 + ξηw.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bilinear {
    pub(crate) c: Vec3,
    pub(crate) e1: Vec3,
    pub(crate) e2: Vec3,
    pub(crate) w: Vec3,
}

impl Bilinear {
    pub(crate) fn new(x: &[Vec3; 4]) -> Self {
        let comb = |s: [Real; 4]| -> Vec3 {
            core::array::from_fn(|a| {
                0.25 * (s[0] * x[0][a] + s[1] * x[1][a] + s[2] * x[2][a] + s[3] * x[3][a])
            })
        };
        Self {
            c: comb([1.0, 1.0, 1.0, 1.0]),
            e1: comb([-1.0, 1.0, 1.0, -1.0]),
            e2: comb([-1.0, -1.0, 1.0, 1.0]),
            w: comb([1.0, -1.0, 1.0, -1.0]),
        }
    }

    pub(crate) fn at(&self, xi: Real, eta: Real) -> Vec3 {
        core::array::from_fn(|a| {
            self.c[a] + xi * self.e1[a] + eta * self.e2[a] + xi * eta * self.w[a]
        })
    }

    pub(crate) fn tangents(&self, xi: Real, eta: Real) -> (Vec3, Vec3) {
        (axpy(eta, &self.w, &self.e1), axpy(xi, &self.w, &self.e2))
    }
}

/// The bilinear weights of the corners at (ξ, η).
pub fn weights(xi: Real, eta: Real) -> [Real; 4] {
    CORNERS.map(|(a, b)| 0.25 * (1.0 + a * xi) * (1.0 + b * eta))
}

/// Projects `p` on the quad `x` (corners counter-clockwise from outside).
/// Returns `None` only for a degenerate quad (zero-length edge vectors or
/// a zero normal at the closest point), non-finite input, or a quad so
/// large that |x_ξ × x_η|² overflows.
pub fn project(p: &Vec3, x: &[Vec3; 4]) -> Option<QuadProjection> {
    let q = Bilinear::new(x);
    let (l1, l2) = (dot(&q.e1, &q.e1), dot(&q.e2, &q.e2));
    if l1.is_nan() || l2.is_nan() || l1 <= 0.0 || l2 <= 0.0 {
        return None;
    }
    let d = sub(p, &q.c);
    let (mut xi, mut eta) = (dot(&d, &q.e1) / l1, dot(&d, &q.e2) / l2);
    let mut r = sub(&q.at(xi, eta), p);
    let mut f = dot(&r, &r);
    for _ in 0..MAX_ITERATIONS {
        let (t1, t2) = q.tangents(xi, eta);
        let g = [dot(&r, &t1), dot(&r, &t2)];
        let h11 = dot(&t1, &t1);
        let h22 = dot(&t2, &t2);
        let h12 = dot(&t1, &t2) + dot(&r, &q.w);
        let det = h11 * h22 - h12 * h12;
        let (dxi, deta) = if h11 > 0.0 && det > 1e-12 * h11 * h22 {
            (
                (h22 * g[0] - h12 * g[1]) / det,
                (h11 * g[1] - h12 * g[0]) / det,
            )
        } else {
            // Not positive definite: a gradient step scaled by the
            // diagonal, which decreases the distance for small steps.
            (g[0] / max(h11, l1), g[1] / max(h22, l2))
        };
        if abs(dxi) < 1e-12 && abs(deta) < 1e-12 {
            // Keep far-off iterates from running away (the face is [−1, 1]²).
            xi = (xi - dxi).clamp(-4.0, 4.0);
            eta = (eta - deta).clamp(-4.0, 4.0);
            break;
        }
        // Backtracking: accept the first of the steps 1, ½, ¼, … that does
        // not increase the distance, so the iterates only descend. A full
        // Newton step on a mildly warped face is always accepted (the
        // iterates are those of the plain Newton method); on a strongly
        // warped one the plain method could stop at a point that is not a
        // minimum, reporting a false contact (found by fuzzing).
        let mut scale = 1.0;
        let mut accepted = false;
        for _ in 0..LINE_SEARCH_HALVINGS {
            let xi_t = (xi - scale * dxi).clamp(-4.0, 4.0);
            let eta_t = (eta - scale * deta).clamp(-4.0, 4.0);
            let r_t = sub(&q.at(xi_t, eta_t), p);
            let f_t = dot(&r_t, &r_t);
            // Small steps are Newton's final, quadratically converging
            // ones, where f changes by round-off only: taken as they are.
            let small = abs(dxi) < 1e-6 && abs(deta) < 1e-6;
            if f_t <= f || small {
                (xi, eta, r, f) = (xi_t, eta_t, r_t, f_t);
                accepted = true;
                break;
            }
            scale *= 0.5;
        }
        if !accepted {
            // No descent left at this precision: a minimum.
            break;
        }
    }
    if !(xi.is_finite() && eta.is_finite()) {
        return None;
    }
    // A search that found no descent at its start returns the start,
    // which may lie far out (the weights of ξ ≥ 2⁵³ cancel to a sum of 0;
    // found by fuzzing): keep it in the same box as the iterates.
    finish(p, &q, xi.clamp(-4.0, 4.0), eta.clamp(-4.0, 4.0))
}

/// The projection record at (ξ, η) (no minimisation).
fn finish(p: &Vec3, q: &Bilinear, xi: Real, eta: Real) -> Option<QuadProjection> {
    let point = q.at(xi, eta);
    let (t1, t2) = q.tangents(xi, eta);
    let n = cross(&t1, &t2);
    let len = norm(&n);
    // Not finite: |n|² overflowed (a quad beyond f64's range, found by
    // fuzzing), which would give a zero "unit" normal.
    if !len.is_finite() || len <= 0.0 {
        return None;
    }
    let normal = n.map(|c| c / len);
    Some(QuadProjection {
        xi,
        eta,
        point,
        normal,
        gap: dot(&normal, &sub(p, &point)),
        weights: weights(xi, eta),
    })
}

/// The closest point of `p` on the quad when (ξ, η) is confined to the
/// face [−1, 1]²: the point on the nearest edge or corner when `p`
/// projects outside. The normal is the face normal at that point and
/// `gap` is the signed distance along it (the caller replaces the normal
/// by an average over the faces that share the edge).
pub fn project_clamped(p: &Vec3, x: &[Vec3; 4]) -> Option<QuadProjection> {
    let free = project(p, x)?;
    if free.inside(0.0) {
        return Some(free);
    }
    let q = Bilinear::new(x);
    // Minimise over each edge (a 1-D Newton on the straight edge is exact:
    // the edges of a bilinear quad are straight lines) and keep the best.
    let mut best: Option<(Real, Real, Real)> = None;
    for (k, &(xi_fixed, eta_fixed)) in [
        (None, Some(-1.0)),
        (Some(1.0), None),
        (None, Some(1.0)),
        (Some(-1.0), None),
    ]
    .iter()
    .enumerate()
    {
        let (a, b) = (x[k], x[(k + 1) % 4]);
        let e = sub(&b, &a);
        let l = dot(&e, &e);
        let s = if l > 0.0 {
            (dot(&sub(p, &a), &e) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let y = axpy(s, &e, &a);
        let dist2 = dot(&sub(p, &y), &sub(p, &y));
        // Local coordinates of the edge point: the free one runs from the
        // start corner's value to the end corner's.
        let (c0, c1) = (CORNERS[k], CORNERS[(k + 1) % 4]);
        let xi = xi_fixed.unwrap_or(c0.0 + s * (c1.0 - c0.0));
        let eta = eta_fixed.unwrap_or(c0.1 + s * (c1.1 - c0.1));
        if best.is_none_or(|(d, _, _)| dist2 < d) {
            best = Some((dist2, xi, eta));
        }
    }
    let (_, xi, eta) = best?;
    finish(p, &q, xi, eta)
}

/// A cheap, conservative pre-test of [`project`]: from the quad's centre
/// plane and its oblique coordinates it rules out points that can neither
/// lie behind the face within a window nor project near it.
///
/// The bounds, for a face c + ξe1 + ηe2 + ξηw (n = e1 × e2 / |e1 × e2|,
/// `axis1`, `axis2` the reciprocal axes below) and a point p = X(ξ*, η*) +
/// h N* that [`project`] returns with |ξ*|, |η*| ≤ R = 1 + reach and
/// −window < h ≤ 0 (N* the unit normal there; a stationary point of the
/// distance, so p − X* is along N*):
/// * along n: d·n = ξ*η* w·n + h N*·n lies in [−window − R²|w|, R²|w|]
///   while the face does not fold (N*·n > 0);
/// * in the plane: d·axis1 = ξ* + ξ*η* w·axis1 + h N*·axis1, so
///   |d·axis1 − ξ*| ≤ R²|w||axis1| + window sin θ |axis1|, θ the tilt of
///   N* from n. N* ∝ |e1 × e2| n + ξ*(e1 × w) + η*(w × e2), whose part off
///   n is at most T = R|w|(|e1| + |e2|), so sin θ ≤ T/(|e1 × e2| − T);
///   |axis1| = |e2|/|e1 × e2|, |axis2| = |e1|/|e1 × e2|. Where T reaches
///   half of |e1 × e2| the sieve passes every point (N*·n > 0 is only
///   certain while T < |e1 × e2|).
///
/// Both bounds are doubled against round-off and the Newton search
/// stopping short of the stationary point — room that only a face with
/// w ≠ 0 gets; on a parallelogram Newton is exact in one step. Callers
/// must pass a reach no smaller than the inside tolerance they test with.
/// 300 000 skewed, stretched, warped faces (`PROPTEST_CASES=300000 cargo
/// test --release -p granbed-kernel --test fuzz_inputs -- sieve`) found
/// no rejected point. (Session 13 replaced a constant ½ in the
/// in-plane bound by the tilt term: on a dense bed 7 of 8 projections the
/// sieve let through ended outside the face. The earlier parallelogram
/// coordinates (p − c)·e/|e|² ignored the skew of e1 and e2; fuzzing found
/// a skewed, warped face where that rejected a true contact.)
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuadSieve {
    centre: Vec3,
    /// The reciprocal axes of (e1, e2) in the centre plane: for
    /// d = ξe1 + ηe2 + h n, d·axis1 = ξ and d·axis2 = η exactly.
    axis1: Vec3,
    axis2: Vec3,
    /// Unit normal of the centre plane (e1 × e2).
    normal: Vec3,
    /// 2|w|: twice the bound |ξη||w| ≤ R²|w| on how far the bilinear face
    /// leaves its centre plane, per R², m.
    warp: Real,
    /// Round-off allowance of the normal test, m.
    floor: Real,
    /// 2 max(|axis1|, |axis2|) |w|: twice the in-plane offset of the twist
    /// per R².
    twist: Real,
    /// |w|(|e1| + |e2|)/|e1 × e2|: the tilt bound's T per R, relative.
    bend: Real,
    /// max(|axis1|, |axis2|), 1/m.
    axis_norm: Real,
}

impl QuadSieve {
    /// The sieve of the quad `x`; `None` if it is degenerate.
    pub fn new(x: &[Vec3; 4]) -> Option<Self> {
        let q = Bilinear::new(x);
        let (l1, l2) = (dot(&q.e1, &q.e1), dot(&q.e2, &q.e2));
        let n = cross(&q.e1, &q.e2);
        let len = norm(&n);
        let finite = l1.is_finite() && l2.is_finite() && len.is_finite();
        if !finite || l1 <= 0.0 || l2 <= 0.0 || len <= 0.0 {
            return None;
        }
        let normal = n.map(|c| c / len);
        let w = norm(&q.w);
        let (a1, a2) = (sqrt(l1), sqrt(l2));
        let shortest = if a1 < a2 { a1 } else { a2 };
        let longest = if a1 < a2 { a2 } else { a1 };
        let axis_norm = longest / len;
        Some(Self {
            centre: q.c,
            axis1: cross(&q.e2, &normal).map(|c| c / len),
            axis2: cross(&normal, &q.e1).map(|c| c / len),
            normal,
            warp: 2.0 * w,
            floor: 1e-3 * shortest,
            twist: 2.0 * axis_norm * w,
            bend: w * (a1 + a2) / len,
            axis_norm,
        })
    }

    /// False only if `p` can be neither behind the face by less than
    /// `window` nor within `reach` (in ξ, η beyond ±1) of it.
    pub fn may_touch(&self, p: &Vec3, window: Real, reach: Real) -> bool {
        self.may_touch_within(p, window, 0.0, reach)
    }

    /// [`Self::may_touch`] that also passes what may lie in front of the
    /// face by less than `front` (0 ≤ `front` ≤ `window`; 0: the same
    /// test, bit for bit).
    pub fn may_touch_within(&self, p: &Vec3, window: Real, front: Real, reach: Real) -> bool {
        let r = 1.0 + reach;
        let t = r * self.bend;
        // The face may fold within the reach (N*·n ≤ 0 needs t ≥ 1): no
        // test is safe. (A NaN passes too.)
        if t.is_nan() || t >= 0.5 {
            return true;
        }
        let d = sub(p, &self.centre);
        let g0 = dot(&d, &self.normal);
        let warp = r * r * self.warp + self.floor;
        if g0 > warp + front || g0 < -window - warp {
            return false;
        }
        let tilt = t / (1.0 - t);
        let lean = if tilt > 0.0 {
            2.0 * window * tilt * self.axis_norm
        } else {
            0.0
        };
        let limit = r + r * r * self.twist + lean + 1e-9;
        // A NaN limit passes.
        limit.is_nan() || (abs(dot(&d, &self.axis1)) <= limit && abs(dot(&d, &self.axis2)) <= limit)
    }
}
