//! Case file tests: every shipped case parses, validation names the field, TOML round trip.
//! Each model's own spec tests are in its folder; they load cases with [`load`].

use super::*;
use std::path::PathBuf;

/// The shipped case files, `configs/`.
pub(in crate::models) fn configs_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("configs")
}

/// The case file `configs/<name>`, parsed and validated.
pub(in crate::models) fn load(name: &str) -> CaseSpec {
    let text = std::fs::read_to_string(configs_dir().join(name)).unwrap();
    CaseSpec::from_toml_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `x` rounded to `decimals` decimal places.
pub(in crate::models) fn round_to(x: f64, decimals: i32) -> f64 {
    let s = 10f64.powi(decimals);
    (x * s).round() / s
}

#[test]
fn every_case_file_parses_and_validates() {
    let mut count = 0;
    for entry in std::fs::read_dir(configs_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue; // also skips the profiles/ directory
        }
        if path.file_name().and_then(|n| n.to_str()) == Some("service.toml") {
            continue; // service settings, not a case
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let case =
            CaseSpec::from_toml_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            path.file_stem().and_then(|s| s.to_str()),
            Some(case.name.as_str()),
            "file name and `name` should agree"
        );
        count += 1;
    }
    assert!(
        count >= 8,
        "expected the 8 shipped case files, found {count}"
    );
}

#[test]
fn validation_names_fields() {
    let text = std::fs::read_to_string(configs_dir().join("launcher-design.toml")).unwrap();
    let field_of = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        CaseSpec::from_toml_str(&text.replacen(from, to, 1))
            .unwrap_err()
            .field
    };
    assert_eq!(
        field_of("b_rail_mm = 10.23", "b_rail_mm = 9.0"),
        "launcher.dimensions.n_shoe_mm"
    );
    assert_eq!(
        field_of("a_shoe_mm = 38.1", "a_shoe_mm = 1.5"),
        "launcher.dimensions.a_shoe_mm"
    );
    assert_eq!(
        field_of("mass_kg = 45.0", "mass_kg = -45.0"),
        "launcher.missile.mass_kg"
    );
    assert_eq!(
        field_of(
            "hinge_axis = [1.0, 0.0, 0.0]",
            "hinge_axis = [1.0, 1.0, 0.0]"
        ),
        "launcher.latch.hinge_axis"
    );
    assert_eq!(
        field_of(
            "stiffness_n_per_mm_e = 10000.0",
            "stiffness_n_per_mm_e = 0.0"
        ),
        "launcher.contacts.latch_rail.stiffness_n_per_mm_e"
    );
    assert_eq!(
        field_of("lip_thickness_m = 0.005", "lip_thickness_m = 0.008"),
        "launcher.rail.lip_thickness_m"
    );
    assert_eq!(
        field_of("duration_s = 10.0", "duration_s = 0.0"),
        "simulation.duration_s"
    );
    // Unknown keys are rejected (deny_unknown_fields), reported as a TOML error.
    assert_eq!(
        field_of("mass_kg = 45.0", "mass_kg = 45.0\nmass_lb = 99.0"),
        "toml"
    );
    // The wrong model table.
    assert_eq!(
        field_of("model = \"launcher\"", "model = \"rattle_box\""),
        "launcher"
    );

    let pc = std::fs::read_to_string(configs_dir().join("persistent-contact.toml")).unwrap();
    let e = CaseSpec::from_toml_str(&pc.replacen(
        "frequency_hz = 1.0",
        "frequency_hz = 1.0\nphase_deg = 3.0",
        1,
    ))
    .unwrap_err();
    assert_eq!(e.field, "toml");
    let e = CaseSpec::from_toml_str(&pc.replace("mean_radius_m = 0.020", "mean_radius_m = 0.024"))
        .unwrap_err();
    assert_eq!(e.field, "persistent_contact.coupon_side_m");

    let rb = std::fs::read_to_string(configs_dir().join("rattle-box-c.toml")).unwrap();
    let e = CaseSpec::from_toml_str(
        &rb.replace("tube_inner_side_m = 0.031750", "tube_inner_side_m = 0.0200"),
    )
    .unwrap_err();
    assert_eq!(e.field, "rattle_box.tube_inner_side_m");
    let e = CaseSpec::from_toml_str(&rb.replace("mu_dynamic = 0.1660", "mu_dynamic = -0.1"))
        .unwrap_err();
    assert_eq!(e.field, "rattle_box.friction.mu_dynamic");
}

#[test]
fn toml_round_trip() {
    let case = load("launcher-loose.toml");
    let text = toml::to_string(&case).unwrap();
    let back = CaseSpec::from_toml_str(&text).unwrap();
    assert_eq!(back, case);
}
