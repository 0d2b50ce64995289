//! The browser front end's experiment, run natively, against
//! `granbed-cli granule`'s code path: the same samples bit for bit, the
//! same σ_est and σ_y,eff0, the same CSV bytes; and the input errors.

use granbed_cli::granule::outputs::write_force_csv;
use granbed_cli::granule::run::run_platens;
use granbed_cli::granule::summary::{RunSetup, Summary};
use granbed_cli::model::{MeshLevel, OwnedReference};
use granbed_kernel::material::GranuleType;
use granbed_kernel::scene::platens::PlatenParams;
use granbed_wasm::experiment::{Experiment, Inputs};

fn coarse(t: GranuleType) -> Inputs {
    Inputs {
        mesh: (4, 1),
        ..Inputs::standard(t)
    }
}

fn run_to_end(inputs: Inputs) -> Experiment {
    let mut run = Experiment::new(inputs).expect("valid inputs");
    let mut chunks = 0;
    while !run.finished() {
        run.step(97).expect("the run completes");
        chunks += 1;
        assert!(chunks < 1_000_000);
    }
    run
}

#[test]
fn coarse_b2_matches_the_cli_bit_for_bit() {
    let run = run_to_end(coarse(GranuleType::B2));

    let level = MeshLevel::new(4, 1);
    let mesh = OwnedReference::sphere(0.5e-3, level, true).unwrap();
    let material = GranuleType::B2.params().validate().unwrap();
    let params = PlatenParams::standard(material);
    let cli = run_platens(params, &mesh, &mut |_, _| {}).unwrap();
    assert!(cli.error.is_none());
    assert_eq!(run.samples(), cli.samples.as_slice());

    let setup = RunSetup {
        granule_type: "B2",
        mesh: level,
        nodes: mesh.positions.len(),
        hexes: mesh.hexes.len(),
        params: &params,
    };
    let summary = Summary::new(&setup, &cli, None);
    let m = run.measures();
    assert_eq!(m.sigma_est_pa, summary.sigma_est_pa);
    assert_eq!(m.sigma_eff0_pa, summary.sigma_eff0_pa);
    assert_eq!(m.fit.map(|f| f.slope), summary.slope_n_per_m);
    assert!(m.sigma_est_pa.unwrap() > 0.0);
    assert_eq!(
        m.quasi_static.max_kinetic_to_internal,
        summary.quasi_static.max_kinetic_to_internal
    );
    assert!(m.quasi_static.passed && summary.quasi_static.passed);

    let dir = std::env::temp_dir().join(format!("granbed-wasm-native-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("force_displacement.csv");
    write_force_csv(&path, &cli.samples).unwrap();
    let expected = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(run.csv(), expected);
}

#[test]
fn pooled_buffers_give_the_same_run() {
    // The second run reuses the first one's buffers (returned on drop).
    let inputs = Inputs {
        mesh: (2, 1),
        ..Inputs::standard(GranuleType::C3)
    };
    let first = run_to_end(inputs).samples().to_vec();
    let second = run_to_end(inputs).samples().to_vec();
    assert_eq!(first, second);
    assert!(first.len() > 10);
}

#[test]
fn bad_inputs_name_the_field_and_range() {
    let mut inputs = Inputs::standard(GranuleType::B2);
    assert!(inputs.set("poisson_ratio", 0.6));
    let Err(e) = Experiment::new(inputs) else {
        panic!("nu = 0.6 accepted")
    };
    assert_eq!(e.field, Some("poisson_ratio"));
    assert_eq!(e.value, Some(0.6));
    assert!(e.message.contains("Poisson's ratio"), "{}", e.message);
    assert!(e.message.contains("-1 < ν < 0.5"), "{}", e.message);

    let mut inputs = Inputs::standard(GranuleType::B2);
    inputs.diameter_m = -1.0;
    let Err(e) = Experiment::new(inputs) else {
        panic!("negative diameter accepted")
    };
    assert_eq!(e.field, Some("diameter_m"));

    let inputs = Inputs {
        mesh: (3, 1),
        ..Inputs::standard(GranuleType::B2)
    };
    let Err(e) = Experiment::new(inputs) else {
        panic!("odd mesh level accepted")
    };
    assert!(e.message.contains("3x1"), "{}", e.message);

    assert!(!Inputs::standard(GranuleType::B2).set("nonsense", 1.0));

    // Several inputs out of range: every one named, a line each, in the
    // form's order (MATERIAL_FIELDS) and the diameter last; `field` is the
    // first's.
    let mut inputs = Inputs {
        diameter_m: 5.0,
        ..Inputs::standard(GranuleType::B2)
    };
    inputs.set("friction", 20.0);
    inputs.set("eta0", 0.1);
    inputs.set("youngs_modulus_pa", 0.0);
    let Err(e) = Experiment::new(inputs) else {
        panic!("four bad inputs accepted")
    };
    assert_eq!(
        e.fields,
        ["eta0", "youngs_modulus_pa", "friction", "diameter_m"]
    );
    assert_eq!((e.field, e.value), (Some("eta0"), Some(0.1)));
    let lines: Vec<&str> = e.message.lines().collect();
    assert_eq!(lines.len(), 4, "{}", e.message);
    assert!(lines[1].contains("E (Pa) = 0"), "{}", e.message);
    assert!(lines[3].contains("1e-6 ≤ d ≤ 1 m"), "{}", e.message);
    assert_eq!(granbed_wasm::experiment::refusals(&inputs).len(), 4);
    assert!(granbed_wasm::experiment::refusals(&Inputs::standard(GranuleType::C3)).is_empty());
}

#[test]
fn custom_diameter_scales_the_strain() {
    let inputs = Inputs {
        diameter_m: 2.0e-3,
        mesh: (2, 1),
        ..Inputs::standard(GranuleType::B2)
    };
    let mut run = Experiment::new(inputs).unwrap();
    assert_eq!(run.diameter(), 2.0e-3);
    run.step(50).unwrap();
    let last = run.samples().last().unwrap();
    assert_eq!(last.strain, last.approach_m / 2.0e-3);
}

/// A diameter typed in mm is refused in mm, at the bounds of the range in m.
#[test]
fn a_diameter_in_mm_is_refused_in_mm() {
    use granbed_wasm::experiment::{DIAMETER_RANGE_M, diameter_m_of_mm};
    assert_eq!(diameter_m_of_mm(1000.0).unwrap(), DIAMETER_RANGE_M[1]);
    assert_eq!(diameter_m_of_mm(1.0).unwrap(), 1.0e-3);
    assert!(diameter_m_of_mm(0.001).unwrap() >= DIAMETER_RANGE_M[0]);
    for bad in [0.0001, 2000.0, -1.0, f64::NAN] {
        let e = diameter_m_of_mm(bad).unwrap_err();
        assert_eq!(e.field, Some("diameter_mm"));
        assert!(
            e.message.contains("granule diameter d (mm)")
                && e.message.contains("0.001 ≤ d ≤ 1000 mm"),
            "{}",
            e.message
        );
    }
}
