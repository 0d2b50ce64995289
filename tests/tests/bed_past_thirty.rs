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
/// above could not fail. (B2 seed 3 overlapped by more than 10 % of the
/// element while folded nodes went unheld; since they are held,
/// `nearest_penetrated_face`, by 4.0 %: still four times the suite's
/// limit.)
#[test]
fn held_throughout_the_same_bed_overlaps() {
    let scene = Scene {
        exact_contact_from_strain: 1.0,
        ..suite_bed("B2", 3)
    };
    let (record, _) = run_bed_case(&scene).unwrap();
    let overlap = record.max_penetration_rel_element.unwrap();
    assert!(!record.passed && overlap > 0.02, "overlap {overlap}");
}

/// The nearest penetrated face acts in these beds: with physics.md's
/// normal test on every hit instead, nodes at the folds of the flattened
/// granules go unheld past about 45 % and the bed takes another path.
/// Before the first such node both runs are the same. The detection's own
/// overlap measure barely sees those nodes (0.54 % of the element); the
/// suite's measure by geometry, the winding number of each neighbour's
/// surface, finds them a quarter of an element deep (25.6 % measured) and
/// fails the bed, and finds the published bed below 1 % (BENCHMARKS.md,
/// "Overlaps the detection did not see", "… measured by geometry").
#[test]
fn folded_nodes_held_by_the_nearest_face_change_the_bed_past_thirty() {
    let with = suite_bed("A3", 1);
    let without = Scene {
        nearest_penetrated_face: false,
        ..with.clone()
    };
    let pressures = |scene: &Scene| {
        let (record, run) = run_bed_case(scene).unwrap();
        let rows = run
            .samples
            .iter()
            .map(|s| (s.strain, s.upper_pressure_pa))
            .collect::<Vec<_>>();
        (record, rows)
    };
    let ((held, a), (unheld, b)) = (pressures(&with), pressures(&without));
    let hidden =
        |r: &granbed_cli::study::stability::Record| r.max_hidden_overlap_rel_element.unwrap();
    assert!(held.passed && hidden(&held) < 0.01, "{held:?}");
    assert!(
        !unheld.passed
            && unheld.max_penetration_rel_element.unwrap() < 0.01
            && hidden(&unheld) > 0.1,
        "{unheld:?}"
    );
    let early = |rows: &[(f64, f64)]| {
        rows.iter()
            .filter(|r| r.0 <= 0.3)
            .copied()
            .collect::<Vec<_>>()
    };
    assert_eq!(early(&a), early(&b));
    assert_ne!(a.last(), b.last());
}
