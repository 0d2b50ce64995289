//! Ordinary least-squares straight lines, used for the effective yield
//! stress of a granule (slope of F(x), physics.md §7 item 7) and the Kawakita
//! fit of a bed (§7 item 3).

use crate::Real;

/// A fitted line y = slope·x + intercept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// Slope.
    pub slope: Real,
    /// Intercept.
    pub intercept: Real,
    /// Coefficient of determination R² (1 for a perfect fit, including a
    /// constant y, which the horizontal line fits exactly).
    pub r_squared: Real,
    /// Points used.
    pub points: usize,
}

/// Least-squares line through `points` (x, y), summed in iteration order
/// after centring on the means (two passes, so the iterator is cloned).
/// `None` with fewer than two points, when all x are equal, or when a
/// coordinate is not finite.
pub fn linear_fit<I>(points: I) -> Option<LineFit>
where
    I: Iterator<Item = (Real, Real)> + Clone,
{
    let (mut n, mut sx, mut sy) = (0usize, 0.0, 0.0);
    for (x, y) in points.clone() {
        n += 1;
        sx += x;
        sy += y;
    }
    if n < 2 {
        return None;
    }
    let (mx, my) = (sx / n as Real, sy / n as Real);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in points {
        let (dx, dy) = (x - mx, y - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    if sxx == 0.0 || !(sxx + syy + mx + my).is_finite() {
        return None;
    }
    let slope = sxy / sxx;
    Some(LineFit {
        slope,
        intercept: my - slope * mx,
        r_squared: if syy == 0.0 {
            1.0
        } else {
            sxy * sxy / (sxx * syy)
        },
        points: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_y_fits_exactly_and_non_finite_points_fit_nothing() {
        let flat = linear_fit([(0.0, 3.0), (1.0, 3.0), (2.0, 3.0)].into_iter()).unwrap();
        assert_eq!(
            (flat.slope, flat.intercept, flat.r_squared),
            (0.0, 3.0, 1.0)
        );
        assert!(linear_fit([(0.0, 1.0), (1.0, Real::NAN)].into_iter()).is_none());
        assert!(linear_fit([(0.0, 1.0), (Real::INFINITY, 2.0)].into_iter()).is_none());
    }

    #[test]
    fn exact_line_is_recovered() {
        let pts = [(0.1, 2.5), (0.2, 4.5), (0.35, 7.5), (0.4, 8.5)];
        let fit = linear_fit(pts.iter().copied()).unwrap();
        assert!((fit.slope - 20.0).abs() < 1e-12);
        assert!((fit.intercept - 0.5).abs() < 1e-12);
        assert!((fit.r_squared - 1.0).abs() < 1e-12);
        assert_eq!(fit.points, 4);
        assert!(linear_fit([(1.0, 2.0)].iter().copied()).is_none());
        assert!(linear_fit([(1.0, 2.0), (1.0, 3.0)].iter().copied()).is_none());
    }
}
