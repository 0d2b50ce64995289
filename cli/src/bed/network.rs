//! The contact network of a bed snapshot in figures: how the contact
//! forces are distributed over the granule pairs and how the pairs are
//! oriented (the fabric). Written beside each snapshot's tables as
//! `vtk/network_<k>.csv` (one row, [`NETWORK_COLUMNS`]) from the rows of
//! `contacts_<k>.csv` ([`super::snapshot_tables`]), and gathered from
//! there into `summary.json`'s `contact_network` and the report, so that a
//! finished run resumed without a step keeps them.
//!
//! The forces of a compressed granular packing are broadly distributed:
//! most pairs carry less than the mean force, and a minority of strong
//! pairs, the force chains, carries most of the load along the direction
//! of compression. The figures here say how much: quantiles of f/⟨f⟩,
//! the share of pairs above the mean and the share of the force they
//! carry, and the axial component of the fabric tensor ⟨n ⊗ n⟩ of the
//! branch directions n, by number and weighted by the force.

use std::path::Path;

use granbed_kernel::Real;
use serde::Serialize;

use super::snapshot_tables::ContactRow;
use crate::csv::{Field, write_table};

/// Columns of a network file, in order: (name, meaning with its unit).
pub const NETWORK_COLUMNS: [(&str, &str); 16] = [
    (
        "strain",
        "the snapshot's nominal axial strain C (the state is that of the step that first reached it)",
    ),
    (
        "pairs",
        "granule pairs in the snapshot's contacts table (in contact in its step)",
    ),
    (
        "mean_normal_force_n",
        "mean normal force ⟨f⟩ of a pair (its constraints' Σ F_n), N",
    ),
    (
        "median_to_mean",
        "median f/⟨f⟩: 1 if every pair carried the same force, below 1 for the broad force distributions of granular packings",
    ),
    (
        "p90_to_mean",
        "90th percentile of f/⟨f⟩ (linear between ranks)",
    ),
    ("max_to_mean", "largest f/⟨f⟩"),
    (
        "strong_share",
        "share of the pairs with f > ⟨f⟩: the strong network (Radjai's), which holds the force chains",
    ),
    (
        "strong_force_share",
        "share of Σ f that the strong pairs carry",
    ),
    (
        "fabric_zz",
        "⟨n_z²⟩ over the pairs, n the branch direction (z the die axis): 1/3 if the pairs point in all directions alike, more if they align with the axis",
    ),
    (
        "force_fabric_zz",
        "Σ f n_z² / Σ f: the same weighted by the normal force, the alignment of the load-carrying pairs",
    ),
    (
        "strong_fabric_zz",
        "⟨n_z²⟩ over the strong pairs alone (f > ⟨f⟩)",
    ),
    (
        "weak_fabric_zz",
        "⟨n_z²⟩ over the weak pairs (f ≤ ⟨f⟩): in granular packings these tend to lie across the load",
    ),
    (
        "friction_to_normal",
        "Σ |friction| / Σ f over the pairs: their mobilised friction, force-weighted (Coulomb's law keeps each pair's at or below μ)",
    ),
    (
        "sliding_share",
        "share of the pairs whose friction reaches 0.99 μ f (Coulomb's limit μ f, to 1 %): the pairs sliding as a whole; the mobilisation is spread smoothly up to μ, so many pairs lie just below",
    ),
    (
        "interior_granules",
        "granules whose centre of mass lies at least one nominal diameter d from the die wall and from both punches: the bed's interior (NaN, null in summary.json, in files written before the column existed)",
    ),
    (
        "interior_coordination",
        "their granule contacts per granule (the contacts table's pairs they are in, over their number): the coordination number without the walls' deficit (a granule at a wall has fewer granule neighbours), the one packing models such as Arzt's describe; NaN without an interior granule and in older files",
    ),
];

/// Columns of the network files written before the interior's.
const COLUMNS_BEFORE_INTERIOR: usize = 14;

/// The bed's interior in a snapshot: its granules and their mean granule
/// contacts ([`interior`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interior {
    /// Granules in the interior.
    pub granules: usize,
    /// Their granule contacts per granule (NaN without one).
    pub coordination: Real,
}

/// The interior of a bed whose granules' centres of mass are `centres`
/// (m, the die's axis x = y = 0, the lower punch z = 0), in contact as
/// `rows` say, in a die of radius `die_radius_m` with the punches
/// `height_m` apart: the granules at least `margin_m` (a granule's
/// diameter) from the die wall and from both punches, and their contacts
/// per granule.
pub fn interior(
    centres: &[[Real; 3]],
    rows: &[ContactRow],
    die_radius_m: Real,
    height_m: Real,
    margin_m: Real,
) -> Interior {
    let inside: Vec<bool> = centres
        .iter()
        .map(|c| {
            c[0].hypot(c[1]) <= die_radius_m - margin_m
                && c[2] >= margin_m
                && c[2] <= height_m - margin_m
        })
        .collect();
    let is_inside = |g: u32| inside.get(g as usize).copied().unwrap_or(false);
    let contacts = rows
        .iter()
        .map(|r| u64::from(is_inside(r.a)) + u64::from(is_inside(r.b)))
        .sum::<u64>();
    let granules = inside.iter().filter(|&&i| i).count();
    Interior {
        granules,
        coordination: contacts as Real / granules as Real,
    }
}

/// One snapshot's network in figures ([`NETWORK_COLUMNS`]). A snapshot
/// without pairs has `pairs` 0 and every ratio NaN (`null` in JSON); one
/// whose pairs all carry the same force has no strong pair, and its
/// `strong_fabric_zz` is NaN.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NetworkStats {
    /// The snapshot's index k (its files' number), which the file's name
    /// holds, not its row.
    pub snapshot: usize,
    /// Nominal axial strain C of the snapshot.
    pub strain: Real,
    /// Granule pairs in contact.
    pub pairs: usize,
    /// ⟨f⟩, N.
    pub mean_normal_force_n: Real,
    /// Median f/⟨f⟩.
    pub median_to_mean: Real,
    /// 90th percentile of f/⟨f⟩.
    pub p90_to_mean: Real,
    /// Largest f/⟨f⟩.
    pub max_to_mean: Real,
    /// Share of pairs with f > ⟨f⟩.
    pub strong_share: Real,
    /// Share of Σ f those pairs carry.
    pub strong_force_share: Real,
    /// ⟨n_z²⟩ (1/3: isotropic).
    pub fabric_zz: Real,
    /// Σ f n_z² / Σ f.
    pub force_fabric_zz: Real,
    /// ⟨n_z²⟩ over the strong pairs.
    pub strong_fabric_zz: Real,
    /// ⟨n_z²⟩ over the weak pairs.
    pub weak_fabric_zz: Real,
    /// Σ |friction| / Σ f.
    pub friction_to_normal: Real,
    /// Share of the pairs at Coulomb's limit ([`SLIDING_AT`]).
    pub sliding_share: Real,
    /// Granules in the bed's interior ([`interior`]; `None` from a file
    /// written before the column existed).
    pub interior_granules: Option<usize>,
    /// Their granule contacts per granule.
    pub interior_coordination: Real,
}

/// The `q` quantile (0 ≤ q ≤ 1) of the ascending `sorted`, linear between
/// the ranks (rank q (n − 1), the default of numpy's `quantile`); NaN if
/// empty.
fn quantile(sorted: &[Real], q: Real) -> Real {
    let Some(last) = sorted.len().checked_sub(1) else {
        return Real::NAN;
    };
    let rank = q * last as Real;
    let below = rank.floor() as usize;
    let above = (below + 1).min(last);
    let t = rank - below as Real;
    sorted[below] + t * (sorted[above] - sorted[below])
}

/// A pair slides as a whole when its friction is within this share of
/// Coulomb's limit μ f ([`NetworkStats::sliding_share`]). Its constraints'
/// frictions add as vectors, over the step's sweeps, so the pair's reaches
/// μ f only when they all slide the same way on parallel faces in every
/// sweep: of the default bed's pairs whose every constraint was at its cap
/// in a sweep, a quarter to a half reach 0.99 μ f (BENCHMARKS.md, session
/// 51).
pub const SLIDING_AT: Real = 0.99;

/// The figures of the contact `rows` of snapshot `snapshot` at `strain`,
/// the pairs' friction coefficient `mu`, with the bed's `interior`.
pub fn network_stats(
    snapshot: usize,
    strain: Real,
    mu: Real,
    rows: &[ContactRow],
    interior: Interior,
) -> NetworkStats {
    let n = rows.len() as Real;
    let total: Real = rows.iter().map(|r| r.normal_n).sum();
    let mean = total / n;
    let mut ratios: Vec<Real> = rows.iter().map(|r| r.normal_n / mean).collect();
    ratios.sort_by(Real::total_cmp);
    let strong = rows.iter().filter(|r| r.normal_n > mean);
    let strong_force: Real = strong.clone().map(|r| r.normal_n).sum();
    // n_z² of each pair's branch direction.
    let nz2 = |r: &ContactRow| {
        let l2: Real = r.branch.iter().map(|x| x * x).sum();
        r.branch[2] * r.branch[2] / l2
    };
    let mean_nz2 = |strong_ones: bool| {
        let (count, sum) = rows
            .iter()
            .filter(|r| (r.normal_n > mean) == strong_ones)
            .fold((0_usize, 0.0), |(c, s), r| (c + 1, s + nz2(r)));
        sum / count as Real
    };
    NetworkStats {
        snapshot,
        strain,
        pairs: rows.len(),
        mean_normal_force_n: mean,
        median_to_mean: quantile(&ratios, 0.5),
        p90_to_mean: quantile(&ratios, 0.9),
        max_to_mean: ratios.last().copied().unwrap_or(Real::NAN),
        strong_share: strong.count() as Real / n,
        strong_force_share: strong_force / total,
        fabric_zz: rows.iter().map(nz2).sum::<Real>() / n,
        force_fabric_zz: rows.iter().map(|r| r.normal_n * nz2(r)).sum::<Real>() / total,
        strong_fabric_zz: mean_nz2(true),
        weak_fabric_zz: mean_nz2(false),
        friction_to_normal: rows.iter().map(|r| r.friction_n).sum::<Real>() / total,
        sliding_share: rows
            .iter()
            .filter(|r| r.friction_n >= SLIDING_AT * mu * r.normal_n && r.normal_n > 0.0)
            .count() as Real
            / n,
        interior_granules: Some(interior.granules),
        interior_coordination: interior.coordination,
    }
}

impl NetworkStats {
    /// The row's cells, as [`NETWORK_COLUMNS`] lists them.
    pub fn fields(&self) -> [Field; 16] {
        [
            self.strain.into(),
            Field::Int(self.pairs as u64),
            self.mean_normal_force_n.into(),
            self.median_to_mean.into(),
            self.p90_to_mean.into(),
            self.max_to_mean.into(),
            self.strong_share.into(),
            self.strong_force_share.into(),
            self.fabric_zz.into(),
            self.force_fabric_zz.into(),
            self.strong_fabric_zz.into(),
            self.weak_fabric_zz.into(),
            self.friction_to_normal.into(),
            self.sliding_share.into(),
            self.interior_granules
                .map_or(Field::Real(Real::NAN), |n| Field::Int(n as u64)),
            self.interior_coordination.into(),
        ]
    }

    /// The figures of snapshot `snapshot` from the cells of its network
    /// file's row, in [`NETWORK_COLUMNS`]' order.
    fn from_cells(snapshot: usize, c: &[Real; 16]) -> Self {
        Self {
            snapshot,
            strain: c[0],
            pairs: c[1] as usize,
            mean_normal_force_n: c[2],
            median_to_mean: c[3],
            p90_to_mean: c[4],
            max_to_mean: c[5],
            strong_share: c[6],
            strong_force_share: c[7],
            fabric_zz: c[8],
            force_fabric_zz: c[9],
            strong_fabric_zz: c[10],
            weak_fabric_zz: c[11],
            friction_to_normal: c[12],
            sliding_share: c[13],
            interior_granules: c[14].is_finite().then_some(c[14] as usize),
            interior_coordination: c[15],
        }
    }
}

/// File name of the network figures of snapshot `k`.
pub fn network_file(k: usize) -> String {
    format!("network_{k}.csv")
}

/// Writes `stats` as `vtk_dir`/[`network_file`]`(k)`.
pub fn write_network(vtk_dir: &Path, k: usize, stats: &NetworkStats) -> anyhow::Result<()> {
    write_table(
        &vtk_dir.join(network_file(k)),
        &NETWORK_COLUMNS,
        core::iter::once(stats.fields()),
    )
}

/// Reads the network file of snapshot `snapshot`: its header must be
/// [`NETWORK_COLUMNS`]' names, or their first
/// [`COLUMNS_BEFORE_INTERIOR`] (a file written before the interior's
/// columns, read without them: `None`, NaN), and it must hold one row of
/// numbers.
fn read_network(snapshot: usize, path: &Path) -> anyhow::Result<NetworkStats> {
    let rows = crate::csv::read_table_or_older(path, &NETWORK_COLUMNS, COLUMNS_BEFORE_INTERIOR)?;
    match rows[..] {
        [cells] => Ok(NetworkStats::from_cells(snapshot, &cells)),
        _ => anyhow::bail!("`{}`: not one row", path.display()),
    }
}

/// The network files in `vtk_dir`, in the order of k (the snapshots'
/// strain order), each read (header and one row checked), and why each file that
/// could not be read was left out (a damaged file must not cost the run's
/// other outputs). None if the folder is not there.
pub fn read_all(vtk_dir: &Path) -> (Vec<NetworkStats>, Vec<String>) {
    super::snapshots::read_snapshot_files(vtk_dir, "network_", "contact_network", read_network)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(normal_n: Real, branch: [Real; 3], friction_n: Real) -> ContactRow {
        ContactRow {
            a: 0,
            b: 1,
            normal_n,
            friction_n,
            force_on_a: [0.0; 3],
            constraints: 1,
            slipping: 0,
            branch,
        }
    }

    /// Four pairs of forces 1, 2, 3, 6 (mean 3): the quantiles, the strong
    /// pair (one, 6/12 of the force) and the fabric of two axial and two
    /// horizontal branches, by number 1/2 and by force (2·0 + 3 + 6)/12;
    /// frictions 0.5 + 1 + 0 + 1.5 over Σ f = 12.
    #[test]
    fn the_figures_of_four_pairs() {
        let rows = [
            pair(1.0, [2e-3, 0.0, 0.0], 0.5),
            pair(2.0, [0.0, -1e-3, 0.0], 1.0),
            pair(3.0, [0.0, 0.0, 1e-3], 0.0),
            pair(6.0, [0.0, 0.0, -3e-3], 1.5),
        ];
        let s = network_stats(7, 0.2, 0.5, &rows, NO_INTERIOR);
        assert_eq!((s.snapshot, s.strain, s.pairs), (7, 0.2, 4));
        assert_eq!(s.mean_normal_force_n, 3.0);
        assert!((s.median_to_mean - 2.5 / 3.0).abs() < 1e-15);
        // Rank 0.9 · 3 = 2.7: 1 + 0.7 (2 − 1).
        assert!((s.p90_to_mean - 1.7).abs() < 1e-15);
        assert_eq!(s.max_to_mean, 2.0);
        assert_eq!((s.strong_share, s.strong_force_share), (0.25, 0.5));
        assert_eq!(s.fabric_zz, 0.5);
        assert_eq!(s.force_fabric_zz, 0.75);
        assert_eq!(s.friction_to_normal, 0.25);
        // Strong: the pair of 6 (axial); weak: 1, 2 (across) and 3 (axial).
        assert_eq!((s.strong_fabric_zz, s.weak_fabric_zz), (1.0, 1.0 / 3.0));
        // At μ = 0.5 the pairs of 1 and 2 are at the limit (0.5 = 0.5 · 1,
        // 1 = 0.5 · 2); those of 3 (no friction) and 6 (1.5 < 3) are not.
        assert_eq!(s.sliding_share, 0.5);
        // The limit is 0.99 μ f: 0.995 counts, 0.985 does not.
        let near = [
            pair(1.0, [0.0, 0.0, 1e-3], 0.995 * 0.1),
            pair(1.0, [0.0, 0.0, 1e-3], 0.985 * 0.1),
        ];
        assert_eq!(
            network_stats(0, 0.1, 0.1, &near, NO_INTERIOR).sliding_share,
            0.5
        );
    }

    /// A file written reads back to the same figures, to the bit; a
    /// snapshot without pairs has NaN ratios, which read back too.
    #[test]
    fn a_network_file_round_trips() {
        let dir = std::env::temp_dir().join(format!("granbed-network-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let rows = [
            pair(0.1, [1e-3, 2e-3, 3e-3], 0.01),
            pair(0.7, [-1e-3, 0.5e-3, 2e-3], 0.05),
        ];
        let inside = Interior {
            granules: 3,
            coordination: 5.0 / 3.0,
        };
        let full = network_stats(2, 0.1 + 0.2, 0.1, &rows, inside);
        let empty = network_stats(10, 0.3, 0.1, &[], NO_INTERIOR);
        assert_eq!(empty.pairs, 0);
        assert!(empty.median_to_mean.is_nan() && empty.fabric_zz.is_nan());
        write_network(&dir, 2, &full).unwrap();
        write_network(&dir, 10, &empty).unwrap();
        let (back, left_out) = read_all(&dir);
        assert!(left_out.is_empty());
        assert_eq!(back[0], full);
        assert_eq!((back[1].snapshot, back[1].pairs), (10, 0));
        assert!(back[1].median_to_mean.is_nan());
        // A damaged file is left out, and said so; the others are read.
        std::fs::write(dir.join(network_file(3)), "strain\n0.1\n").unwrap();
        let (back, left_out) = read_all(&dir);
        assert_eq!(back.iter().map(|s| s.snapshot).collect::<Vec<_>>(), [2, 10]);
        assert!(
            left_out.len() == 1
                && left_out[0].contains("network_3.csv")
                && left_out[0].contains("header"),
            "{left_out:?}"
        );
        // A file written before the interior's columns reads with none.
        let text = std::fs::read_to_string(dir.join(network_file(2))).unwrap();
        let old: String = text
            .lines()
            .map(|l| {
                l.split(',')
                    .take(COLUMNS_BEFORE_INTERIOR)
                    .collect::<Vec<_>>()
                    .join(",")
                    + "\n"
            })
            .collect();
        std::fs::write(dir.join(network_file(2)), old).unwrap();
        let (back, _) = read_all(&dir);
        assert_eq!(back[0].fabric_zz, full.fabric_zz);
        assert_eq!(back[0].interior_granules, None);
        assert!(back[0].interior_coordination.is_nan());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// No interior: the figures of a bed too small for one.
    const NO_INTERIOR: Interior = Interior {
        granules: 0,
        coordination: Real::NAN,
    };

    /// In a die of radius 5 mm with the punches 6 mm apart and a margin of
    /// 1 mm, the granules whose centres lie within r ≤ 4 mm and
    /// 1 ≤ z ≤ 5 mm are inside; each pair counts once for each granule of
    /// it that is.
    #[test]
    fn the_interior_is_away_from_every_wall() {
        let centres = [
            [0.0, 0.0, 3e-3],    // inside
            [3e-3, 2e-3, 2e-3],  // r = 3.6 mm: inside
            [3e-3, 3e-3, 3e-3],  // r = 4.2 mm: at the wall
            [0.0, 1e-3, 0.5e-3], // at the lower punch
            [1e-3, 0.0, 5.5e-3], // at the upper punch
        ];
        let pair = |a, b| ContactRow {
            a,
            b,
            ..super::tests::pair(1.0, [0.0, 0.0, 1e-3], 0.0)
        };
        let rows = [pair(0, 1), pair(0, 2), pair(2, 3), pair(1, 4), pair(0, 4)];
        let i = interior(&centres, &rows, 5e-3, 6e-3, 1e-3);
        // Granule 0 is in three pairs, granule 1 in two.
        assert_eq!(i.granules, 2);
        assert_eq!(i.coordination, 2.5);
        let none = interior(&centres[2..], &[], 5e-3, 6e-3, 1e-3);
        assert_eq!(none.granules, 0);
        assert!(none.coordination.is_nan());
    }
}
