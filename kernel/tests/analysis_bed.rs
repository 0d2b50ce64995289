//! Oracles of the bed measures (physics.md §7 items 1–6, P3, E4).

mod common;

use common::{assert_close, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::analysis::bed::{
    BedError, GranuleShape, HEYWOOD_FIXED_DIAMETER, KAWAKITA_MIN_STRAIN, applied_pressure,
    axial_strain, bed_density, coordination_number, coordination_number_with_walls, granule_shape,
    heckel_fit, heckel_fit_slices, heywood_coefficient, kawakita_fit, kawakita_fit_slices,
    mean_relative_density, relative_density, solid_over_volume, surface_geometry,
    volume_equivalent_diameter,
};
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::mesh::surface::area_and_volume;

const PI: Real = core::f64::consts::PI;

/// Samples (P, C) on the Kawakita law C = abP/(1 + bP), i.e.
/// P = C/(b(a − C)), for C evenly spaced from `c_lo` to `c_hi`.
fn kawakita_law(a: Real, inv_b: Real, c_lo: Real, c_hi: Real, n: usize) -> Vec<(Real, Real)> {
    (0..n)
        .map(|i| {
            let c = c_lo + (c_hi - c_lo) * i as Real / (n - 1) as Real;
            (c * inv_b / (a - c), c)
        })
        .collect()
}

/// P3: a = 0.4, 1/b = 50 kPa over C = 0.2…0.32 are recovered to 1e-12 from
/// the points with C ≥ 0.25, and R² = 1.
#[test]
fn kawakita_recovers_the_law() {
    let (a, inv_b) = (0.4, 50e3);
    let data = kawakita_law(a, inv_b, 0.2, 0.32, 49);
    let used = data.iter().filter(|(_, c)| *c >= 0.25).count();
    let fit = kawakita_fit(data.iter().copied(), KAWAKITA_MIN_STRAIN).unwrap();
    println!(
        "Kawakita: a = {:.17} (err {:.2e}), 1/b = {:.12} Pa (err {:.2e}), R² = {:.17}, points {}",
        fit.a,
        (fit.a - a).abs() / a,
        fit.inv_b_pa,
        (fit.inv_b_pa - inv_b).abs() / inv_b,
        fit.r_squared,
        fit.points
    );
    assert_eq!(fit.points, used);
    assert!(used >= 2 && used < data.len());
    assert_close("a", fit.a, a, 1e-12, 0.0);
    assert_close("1/b", fit.inv_b_pa, inv_b, 1e-12, 0.0);
    assert_close("R²", fit.r_squared, 1.0, 1e-12, 0.0);

    // A second law, more points, a different threshold.
    let data = kawakita_law(0.65, 12.5e3, 0.05, 0.6, 200);
    let fit = kawakita_fit(data.iter().copied(), 0.3).unwrap();
    assert_close("a (2)", fit.a, 0.65, 1e-12, 0.0);
    assert_close("1/b (2)", fit.inv_b_pa, 12.5e3, 1e-12, 0.0);
}

/// Points below the threshold have no effect, whatever they hold.
#[test]
fn kawakita_ignores_points_below_the_threshold() {
    let data = kawakita_law(0.4, 50e3, 0.25, 0.32, 15);
    let clean = kawakita_fit(data.iter().copied(), KAWAKITA_MIN_STRAIN).unwrap();
    let mut dirty = Vec::new();
    let garbage = [
        (1e12, 0.1),
        (-3.0, 0.2499999),
        (Real::NAN, 0.2),
        (Real::INFINITY, 0.0),
        (5.0, -0.4),
        (7e4, Real::NAN),
        (1.0, Real::NEG_INFINITY),
    ];
    for (i, &d) in data.iter().enumerate() {
        dirty.push(garbage[i % garbage.len()]);
        dirty.push(d);
    }
    let fit = kawakita_fit(dirty.iter().copied(), KAWAKITA_MIN_STRAIN).unwrap();
    assert_eq!(fit, clean, "garbage below the threshold changed the fit");

    // Slices give the same bits; mismatched lengths are an error.
    let (p, c): (Vec<Real>, Vec<Real>) = dirty.iter().copied().unzip();
    assert_eq!(
        kawakita_fit_slices(&p, &c, KAWAKITA_MIN_STRAIN),
        Ok(Some(clean))
    );
    assert!(matches!(
        kawakita_fit_slices(&p, &c[1..], KAWAKITA_MIN_STRAIN),
        Err(BedError::BufferLength {
            buffer: "strains",
            ..
        })
    ));
}

#[test]
fn kawakita_degenerate_inputs_give_none() {
    let none = |d: &[(Real, Real)]| kawakita_fit(d.iter().copied(), KAWAKITA_MIN_STRAIN);
    assert!(none(&[]).is_none());
    assert!(none(&[(1e5, 0.3)]).is_none(), "one point");
    assert!(
        none(&[(1e5, 0.3), (2e5, 0.1)]).is_none(),
        "one usable point"
    );
    assert!(
        none(&[(1e5, 0.3), (1e5, 0.31)]).is_none(),
        "equal pressures"
    );
    // P/C constant: slope 0, a infinite.
    assert!(none(&[(1e5, 0.3), (2e5, 0.6)]).is_none(), "zero slope");
    // A threshold ≤ 0 still skips C = 0 (P/C undefined).
    let data = [(0.0, 0.0), (1e5, 0.3), (2e5, 0.35)];
    assert_eq!(kawakita_fit(data.iter().copied(), 0.0).unwrap().points, 2);
    assert!(kawakita_fit(data.iter().copied(), Real::NAN).is_none());
}

/// Samples (P, D) on the Heckel law ln(1/(1 − D)) = K·P + A, i.e.
/// D = 1 − exp(−(K·P + A)), for P evenly spaced from `p_lo` to `p_hi` Pa.
fn heckel_law(k: Real, a: Real, p_lo: Real, p_hi: Real, n: usize) -> Vec<(Real, Real)> {
    (0..n)
        .map(|i| {
            let p = p_lo + (p_hi - p_lo) * i as Real / (n - 1) as Real;
            (p, 1.0 - (-(k * p + a)).exp())
        })
        .collect()
}

/// The Heckel law is recovered: P_y = 1/K, A and D_A = 1 − e^(−A) to 1e-12
/// on two laws (a bed's kPa and a tablet press's MPa), R² = 1.
#[test]
fn heckel_recovers_the_law() {
    for (py, a, p_hi) in [(120e3, 0.6, 60e3), (85e6, 0.35, 250e6)] {
        let data = heckel_law(1.0 / py, a, 0.0, p_hi, 40);
        let fit = heckel_fit(data.iter().copied()).unwrap();
        println!(
            "Heckel: P_y = {:.12} Pa (err {:.2e}), A = {:.15}, D_A = {:.15}, R² = {:.15}",
            fit.yield_pressure_pa,
            (fit.yield_pressure_pa - py).abs() / py,
            fit.a,
            fit.d_a,
            fit.r_squared
        );
        assert_eq!(fit.points, data.len());
        assert_close("P_y", fit.yield_pressure_pa, py, 1e-12, 0.0);
        assert_close("K", fit.k_per_pa, 1.0 / py, 1e-12, 0.0);
        assert_close("A", fit.a, a, 1e-12, 0.0);
        assert_close("D_A", fit.d_a, 1.0 - (-a).exp(), 1e-12, 0.0);
        assert_close("R²", fit.r_squared, 1.0, 1e-12, 0.0);
    }
}

/// Rows where the law is undefined (D ≥ 1, D ≤ 0, not finite) are left
/// out; the slices give the same bits; degenerate data give no fit.
#[test]
fn heckel_skips_undefined_rows_and_refuses_degenerate_data() {
    let data = heckel_law(1.0 / 50e3, 0.7, 10e3, 40e3, 12);
    let clean = heckel_fit(data.iter().copied()).unwrap();
    let garbage = [
        (5e4, 1.0),
        (6e4, 1.2),
        (1e3, 0.0),
        (1e3, -0.1),
        (Real::NAN, 0.5),
        (2e4, Real::NAN),
        (Real::INFINITY, 0.6),
    ];
    let mut dirty = Vec::new();
    for (i, &d) in data.iter().enumerate() {
        dirty.push(garbage[i % garbage.len()]);
        dirty.push(d);
    }
    assert_eq!(heckel_fit(dirty.iter().copied()), Some(clean));
    let (p, d): (Vec<Real>, Vec<Real>) = dirty.iter().copied().unzip();
    assert_eq!(heckel_fit_slices(&p, &d), Ok(Some(clean)));
    assert!(matches!(
        heckel_fit_slices(&p[1..], &d),
        Err(BedError::BufferLength {
            buffer: "solid_fractions",
            ..
        })
    ));

    let none = |d: &[(Real, Real)]| heckel_fit(d.iter().copied());
    assert!(none(&[]).is_none());
    assert!(none(&[(1e4, 0.6)]).is_none(), "one point");
    assert!(none(&[(1e4, 0.6), (1e4, 0.7)]).is_none(), "equal pressures");
    assert!(
        none(&[(1e4, 0.6), (2e4, 0.6)]).is_none(),
        "no densification"
    );
    assert!(
        none(&[(1e4, 0.7), (2e4, 0.6)]).is_none(),
        "density falling with pressure"
    );
}

/// §7 items 1–2: P = F/(πR_d²), C = (H0 − H)/H0.
#[test]
fn pressure_and_strain() {
    assert_close(
        "P",
        applied_pressure(100.0, 5e-3).unwrap(),
        100.0 / (PI * 25e-6),
        1e-15,
        0.0,
    );
    assert_close(
        "C at 60 ms",
        axial_strain(9.5e-3, 6.5e-3).unwrap(),
        3.0 / 9.5,
        1e-14,
        0.0,
    );
    assert_eq!(axial_strain(9.5e-3, 9.5e-3), Some(0.0));
    assert!(applied_pressure(1.0, 0.0).is_none());
    assert!(applied_pressure(1.0, -1.0).is_none());
    assert!(applied_pressure(Real::NAN, 1.0).is_none());
    assert!(axial_strain(0.0, 1.0).is_none());
    assert!(axial_strain(1.0, Real::INFINITY).is_none());
}

fn standard_shape(positions: &[[Real; 3]], quads: &[[u32; 4]], v0: Real) -> GranuleShape {
    granule_shape(positions, quads, 0.6, v0, HEYWOOD_FIXED_DIAMETER).unwrap()
}

/// E4 / §3.4: the undeformed standard mesh gives α_SV = 6.0175 (d_V) and
/// 6.0514 (d = 1 mm), η_g = η0.
#[test]
fn standard_mesh_heywood() {
    let m = sphere_mesh(&SphereMeshParams::standard());
    let (_, v0) = area_and_volume(&m.positions, &m.quads).unwrap();
    let s = standard_shape(&m.positions, &m.quads, v0);
    println!(
        "standard mesh: V = {:.6e} m³, S = {:.6e} m², α(d_V) = {:.6}, α(1 mm) = {:.6}, η = {}",
        s.volume_m3, s.area_m2, s.heywood_dv, s.heywood_fixed, s.relative_density
    );
    assert_eq!(s.volume_m3, v0);
    assert_eq!(s.relative_density, 0.6);
    assert_close("V_mesh", s.volume_m3, 0.514836e-9, 2e-6, 0.0);
    assert_close("S_mesh", s.area_m2, 3.11550e-6, 2e-6, 0.0);
    // Four decimals: half a unit of the last digit.
    assert_close("α_SV(d_V)", s.heywood_dv, 6.0175, 0.0, 5e-5);
    assert_close("α_SV(1 mm)", s.heywood_fixed, 6.0514, 0.0, 5e-5);
}

/// A perfect sphere gives α_SV(d_V) = 6 exactly; the cubed-sphere meshes
/// approach it from above as O(h²) (error ratio ≈ 4 per refinement), and the
/// Richardson extrapolation of n = 16 and 32 is 6 to 1e-5.
#[test]
fn heywood_tends_to_six_for_a_sphere() {
    let r: Real = 0.5e-3;
    let (s, v) = (4.0 * PI * r * r, 4.0 / 3.0 * PI * r * r * r);
    let d_v = volume_equivalent_diameter(v).unwrap();
    assert_close("d_V of a sphere", d_v, 2.0 * r, 1e-15, 0.0);
    assert_close(
        "α_SV of a sphere",
        heywood_coefficient(d_v, s, v).unwrap(),
        6.0,
        1e-15,
        0.0,
    );
    let errors: Vec<Real> = [4, 8, 16, 32]
        .iter()
        .map(|&n| {
            let m = sphere_mesh(&SphereMeshParams::new(r, n, n / 4 + 1));
            let (_, v0) = area_and_volume(&m.positions, &m.quads).unwrap();
            let e = standard_shape(&m.positions, &m.quads, v0).heywood_dv - 6.0;
            println!("n = {n}: α_SV(d_V) − 6 = {e:.4e}");
            e
        })
        .collect();
    for w in errors.windows(2) {
        assert!(w[1] > 0.0, "a convex polyhedral surface has α > 6");
        let ratio = w[0] / w[1];
        assert!((3.5..4.5).contains(&ratio), "error ratio {ratio}");
    }
    // Richardson extrapolation of the two finest meshes: the limit is 6.
    let limit = 6.0 + (4.0 * errors[3] - errors[2]) / 3.0;
    println!("Richardson limit of α_SV(d_V): {limit:.8}");
    assert_close("α_SV(d_V) limit", limit, 6.0, 0.0, 1e-5);
}

/// Uniform scaling by λ leaves α_SV(d_V) unchanged, multiplies η by λ⁻³ and
/// α_SV(d) by λ⁻¹; rigid motions change nothing; an affine stretch raises
/// α_SV(d_V) and multiplies η by 1/det.
#[test]
fn heywood_under_scaling_and_stretch() {
    let m = sphere_mesh(&SphereMeshParams::standard());
    let (_, v0) = area_and_volume(&m.positions, &m.quads).unwrap();
    let s0 = standard_shape(&m.positions, &m.quads, v0);
    let map = |f: &dyn Fn([Real; 3]) -> [Real; 3]| -> Vec<[Real; 3]> {
        m.positions.iter().map(|&x| f(x)).collect()
    };

    for lambda in [0.8, 0.93, 1.25] {
        let x = map(&|p| p.map(|c| lambda * c));
        let s = standard_shape(&x, &m.quads, v0);
        assert_close("α(d_V) scaled", s.heywood_dv, s0.heywood_dv, 1e-13, 0.0);
        assert_close(
            "η scaled",
            s.relative_density,
            0.6 / (lambda * lambda * lambda),
            1e-13,
            0.0,
        );
        assert_close(
            "α(1 mm) scaled",
            s.heywood_fixed,
            s0.heywood_fixed / lambda,
            1e-13,
            0.0,
        );
    }

    // Rotation about a skew axis plus a translation.
    let (c, s) = (0.6_f64, 0.8_f64);
    let x = map(&|p| {
        [
            c * p[0] - s * p[1] + 2e-3,
            s * p[0] + c * p[1] - 1e-3,
            p[2] + 7e-4,
        ]
    });
    let r = standard_shape(&x, &m.quads, v0);
    assert_close("α(d_V) rigid", r.heywood_dv, s0.heywood_dv, 1e-11, 0.0);
    assert_close("η rigid", r.relative_density, 0.6, 1e-11, 0.0);

    let mut last = s0.heywood_dv;
    for k in [0.95, 0.85, 0.7_f64] {
        // Axial compression by k with lateral expansion 1/√k (isochoric) and
        // a non-isochoric variant.
        let l = 1.0 / k.sqrt();
        let iso = standard_shape(&map(&|p| [l * p[0], l * p[1], k * p[2]]), &m.quads, v0);
        assert_close("η isochoric", iso.relative_density, 0.6, 1e-13, 0.0);
        assert!(
            iso.heywood_dv > last,
            "k = {k}: {} ≤ {last}",
            iso.heywood_dv
        );
        last = iso.heywood_dv;
        let squash = standard_shape(&map(&|p| [p[0], p[1], k * p[2]]), &m.quads, v0);
        assert_close("η squashed", squash.relative_density, 0.6 / k, 1e-13, 0.0);
        assert!(squash.heywood_dv > s0.heywood_dv);
        println!(
            "stretch k = {k}: α(d_V) isochoric {:.6}, squashed {:.6}",
            iso.heywood_dv, squash.heywood_dv
        );
    }
}

#[test]
fn granule_shape_rejects_bad_input() {
    let m = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let (_, v0) = area_and_volume(&m.positions, &m.quads).unwrap();
    let shape = |x: &[[Real; 3]], q: &[[u32; 4]], eta0, v0, d| granule_shape(x, q, eta0, v0, d);
    assert!(matches!(
        shape(&m.positions, &[], 0.6, v0, 1e-3),
        Err(BedError::Empty { buffer: "quads" })
    ));
    let mut quads = m.quads.clone();
    quads[3][2] = m.positions.len() as u32;
    assert_eq!(
        shape(&m.positions, &quads, 0.6, v0, 1e-3),
        Err(BedError::NodeOutOfRange {
            quad: 3,
            node: m.positions.len() as u32
        })
    );
    // Inverted orientation: negative volume.
    let inverted: Vec<[u32; 4]> = m.quads.iter().map(|q| [q[0], q[3], q[2], q[1]]).collect();
    assert!(matches!(
        shape(&m.positions, &inverted, 0.6, v0, 1e-3),
        Err(BedError::Degenerate { .. })
    ));
    // Collapsed to a point, and a NaN position.
    let point = vec![[1.0; 3]; m.positions.len()];
    assert!(matches!(
        shape(&point, &m.quads, 0.6, v0, 1e-3),
        Err(BedError::Degenerate { .. })
    ));
    let mut nan = m.positions.clone();
    nan[m.quads[0][0] as usize][1] = Real::NAN;
    assert!(matches!(
        surface_geometry(&nan, &m.quads),
        Err(BedError::Degenerate { .. })
    ));
    for (eta0, v, d, name) in [
        (0.0, v0, 1e-3, "eta0"),
        (Real::NAN, v0, 1e-3, "eta0"),
        (0.6, -v0, 1e-3, "v0_m3"),
        (0.6, v0, Real::INFINITY, "d_fixed_m"),
    ] {
        match shape(&m.positions, &m.quads, eta0, v, d) {
            Err(BedError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    assert!(relative_density(0.6, v0, 0.0).is_none());
    assert!(volume_equivalent_diameter(-1.0).is_none());
    assert!(heywood_coefficient(1e-3, Real::NAN, 1.0).is_none());
}

/// §7 item 4: a 3×3×3 simple-cubic stack pressed in a box has 54 granule
/// pairs and 54 granule–wall contacts: Z = 4, with walls 6.
#[test]
fn coordination_of_a_cubic_stack() {
    let (mut pairs, mut walls) = (0usize, 0usize);
    for i in 0..3i32 {
        for j in 0..3i32 {
            for k in 0..3i32 {
                let c = [i, j, k];
                pairs += c.iter().filter(|&&x| x < 2).count();
                walls += c
                    .iter()
                    .map(|&x| (x == 0) as usize + (x == 2) as usize)
                    .sum::<usize>();
            }
        }
    }
    assert_eq!((pairs, walls), (54, 54));
    assert_eq!(coordination_number(pairs as Real, 27), Some(4.0));
    assert_eq!(
        coordination_number_with_walls(pairs as Real, walls as Real, 27),
        Some(6.0)
    );
    // An interval mean of N_pp gives the interval mean of Z.
    assert_eq!(coordination_number(53.5, 27), Some(107.0 / 27.0));
    assert!(coordination_number(1.0, 0).is_none());
    assert!(coordination_number(-1.0, 3).is_none());
    assert!(coordination_number_with_walls(1.0, Real::NAN, 3).is_none());
}

/// §7 item 5: the arithmetic mean of η_g and Σsolid/ΣV (the V-weighted mean).
#[test]
fn bed_relative_density() {
    let etas = [0.6, 0.75, 0.9];
    let volumes = [1.0e-9, 0.8e-9, 2.0 / 3.0 * 1.0e-9];
    let solid: Vec<Real> = etas.iter().zip(&volumes).map(|(e, v)| e * v).collect();
    assert_close(
        "arithmetic",
        mean_relative_density(&etas).unwrap(),
        0.75,
        1e-15,
        0.0,
    );
    let expected = 1.8e-9 / (1.0e-9 + 0.8e-9 + 2.0 / 3.0 * 1.0e-9);
    assert_close(
        "Σsolid/ΣV",
        solid_over_volume(&solid, &volumes).unwrap(),
        expected,
        1e-14,
        0.0,
    );
    let shapes: Vec<GranuleShape> = etas
        .iter()
        .zip(&volumes)
        .map(|(&e, &v)| GranuleShape {
            volume_m3: v,
            area_m2: 1.0,
            relative_density: e,
            heywood_dv: 6.0,
            heywood_fixed: 6.0,
        })
        .collect();
    let bed = bed_density(&shapes).unwrap();
    assert_close("bed arithmetic", bed.arithmetic, 0.75, 1e-15, 0.0);
    assert_close("bed Σsolid/ΣV", bed.solid_over_volume, expected, 1e-14, 0.0);

    assert!(mean_relative_density(&[]).is_none());
    assert!(mean_relative_density(&[0.5, Real::NAN]).is_none());
    assert!(bed_density(&[]).is_none());
    assert!(matches!(
        solid_over_volume(&solid, &volumes[..2]),
        Err(BedError::BufferLength {
            buffer: "volumes_m3",
            expected: 3,
            got: 2
        })
    ));
    assert!(matches!(
        solid_over_volume(&[], &[]),
        Err(BedError::Empty { .. })
    ));
    assert!(matches!(
        solid_over_volume(&[1.0], &[0.0]),
        Err(BedError::InvalidParameter { .. })
    ));
}
