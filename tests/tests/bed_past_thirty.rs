//! Beds compressed far past 30 % keep their granules apart: the beds of
//! `granbed-cli study stability`'s default size (30 coarse 4x1 granules in
//! a 5 mm die) that overlapped by 26–40 % of the element at 60 % while the
//! contact held its constraints between searches throughout (B2 poured with
//! seed 3, A3 with seed 1; BENCHMARKS.md, "The 30-granule suite at 60 %")
//! pass the suite's judgement with the published scene, which searches in
//! every contact sweep from 30 % on (`exact_contact_from_strain`).

use granbed_cli::bed::Scene;
use granbed_cli::study::stability::run_bed_case;

fn suite_bed(granule_type: &str, seed: u64) -> Scene {
    Scene {
        granule_type: granule_type.to_owned(),
        seed,
        granules: 30,
        mesh: "4x1".to_owned(),
        die_diameter_mm: 5.0,
        final_strain: 0.6,
        snapshot_strains: Vec::new(),
        ..Scene::published()
    }
}

#[test]
fn beds_that_overlapped_at_sixty_percent_pass_the_stability_judgement() {
    assert!(Scene::published().exact_contact_from_strain <= 0.3);
    for (granule_type, seed) in [("B2", 3), ("A3", 1)] {
        let (record, _) = run_bed_case(&suite_bed(granule_type, seed)).unwrap();
        eprintln!("{record:?}");
        assert!(record.passed, "{granule_type} seed {seed}: {record:?}");
        let overlap = record.max_penetration_rel_element.unwrap();
        assert!(
            overlap < 0.01,
            "{granule_type} seed {seed}: overlap {overlap}"
        );
    }
}

/// The same beds held throughout do overlap: without the switch the test
/// above could not fail.
#[test]
fn held_throughout_the_same_bed_overlaps() {
    let scene = Scene {
        exact_contact_from_strain: 1.0,
        ..suite_bed("B2", 3)
    };
    let (record, _) = run_bed_case(&scene).unwrap();
    let overlap = record.max_penetration_rel_element.unwrap();
    assert!(!record.passed && overlap > 0.1, "overlap {overlap}");
}
