//! Spec tests: parsing, validation naming the field, derived geometry.

use super::*;
use crate::analysis::rattle_space::LauncherDimensions;
use crate::models::launcher::LauncherSpec;
use std::path::PathBuf;

fn configs_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("configs")
}

fn load(name: &str) -> CaseSpec {
    let text = std::fs::read_to_string(configs_dir().join(name)).unwrap();
    CaseSpec::from_toml_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn round_to(x: f64, decimals: i32) -> f64 {
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
fn rattle_box_cases_match_table_5_1_and_5_2() {
    for (file, k) in [
        ("rattle-box-a.toml", 0.25),
        ("rattle-box-b.toml", 0.44),
        ("rattle-box-c.toml", 0.64),
        ("rattle-box-d.toml", 0.79),
    ] {
        let case = load(file);
        let Ok(ModelSpecRef::RattleBox(rb)) = case.model_spec() else {
            panic!("{file} is not a rattle box");
        };
        assert_eq!(round_to(rb.rattle_space().unwrap(), 2), k, "{file}");
        // 7075 cube, 1 in: 2810 kg/m³ x 16.387 cm³ = 46.05 g (thesis fixture about 46 g).
        assert!(
            (rb.cube_mass_kg() - 0.04605).abs() < 5e-6,
            "{}",
            rb.cube_mass_kg()
        );
        // Table 5.2 in SI: k 1e9 N/m², c 5e5 N·s/m, v_s 6.4634 mm/s.
        let ip = rb.contact.to_impact_params();
        assert!((ip.stiffness - 1.0e9).abs() < 1.0);
        assert!((ip.max_damping - 5.0e5).abs() < 1e-6);
        assert!((ip.full_damping_depth - 1.0e-5).abs() < 1e-15);
        let fp = rb.friction;
        assert!((fp.stiction_transition_speed - 6.4634e-3).abs() < 1e-12);
        assert!((fp.friction_transition_speed - 12.0e-3).abs() < 1e-12);
        assert!((rb.edge_radius_m - 0.02 * 0.0254).abs() < 1e-12);
        assert_eq!(
            case.excitation["tones"][0]["frequency_hz"].as_f64(),
            Some(20.0)
        );
        assert_eq!(
            case.excitation["tones"][0]["amplitude_g"].as_f64(),
            Some(15.0)
        );
    }
}

fn launcher(file: &str) -> LauncherSpec {
    match load(file).model_spec() {
        Ok(ModelSpecRef::Launcher(l)) => l.clone(),
        other => panic!("{file}: {other:?}"),
    }
}

#[test]
fn launcher_variants_have_the_thesis_rattle_spaces() {
    for (file, k) in [
        ("launcher-tight.toml", 0.8317),
        ("launcher-design.toml", 0.7990),
        ("launcher-loose.toml", 0.7684),
    ] {
        let l = launcher(file);
        assert_eq!(round_to(l.rattle_space().unwrap(), 4), k, "{file}");
    }
    // The config files carry the same numbers as the named sets in code.
    assert_eq!(
        launcher("launcher-design.toml").dimensions,
        LauncherDimensions::design()
    );
    let tight = launcher("launcher-tight.toml").dimensions;
    assert!((tight.b_rail_mm - LauncherDimensions::tight().b_rail_mm).abs() < 1e-9);
}

#[test]
fn leaf_spring_engages_except_on_the_loose_rail() {
    // Design: vertical clearance 0.60 mm, tip reach 0.80 mm -> 0.20 mm compression.
    let d = launcher("launcher-design.toml");
    assert!((d.leaf_spring_static_compression_m() - 0.20e-3).abs() < 1e-9);
    // Tight: clearance 0.60 - 2 x 0.201 = 0.198 mm -> 0.602 mm compression.
    let t = launcher("launcher-tight.toml");
    assert!((t.leaf_spring_static_compression_m() - 0.602e-3).abs() < 1e-9);
    // Loose: clearance 0.60 + 2 x 0.1955 = 0.991 mm -> a 0.191 mm gap (thesis 6.3.1).
    let l = launcher("launcher-loose.toml");
    assert!((l.leaf_spring_static_compression_m() + 0.191e-3).abs() < 1e-9);
}

#[test]
fn rail_faces_follow_the_dimensions() {
    let l = launcher("launcher-design.toml");
    let faces = l.rail_faces();
    assert_eq!(faces.len(), 10);
    let get = |n: &str| faces.iter().find(|f| f.name == n).unwrap().clone();
    // Chamber wall at x = (B + A - N)/2 = (10.23 + 38.10 - 9.53)/2 mm = 19.40 mm.
    assert!((get("chamber_wall_right").centre_m[0] - 19.40e-3).abs() < 1e-12);
    // Slot wall at B/2 = 5.115 mm; roof at lip top + 10.13 mm.
    assert!((get("slot_wall_left").centre_m[0] + 5.115e-3).abs() < 1e-12);
    assert!((get("roof_left").centre_m[1] - (-0.030 + 10.13e-3)).abs() < 1e-12);
    for f in &faces {
        let n = f.normal;
        assert!((n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-12);
        assert!(f.half_width_m > 0.0 && f.half_length_m > 0.0, "{}", f.name);
    }
    // The rear shoe head sits on the lips at assembly, inside the chamber.
    let head = l.rear_shoe.head_box(&l.dimensions);
    let centre = l.missile_to_rail_m(head.centre_m);
    assert!((centre[1] - head.half_extents_m[1] - l.rail.lip_top_y_m).abs() < 1e-12);
    assert!(head.half_extents_m[0] < get("chamber_wall_right").centre_m[0]);
    // Loose rail: wider slot and chamber.
    let loose = launcher("launcher-loose.toml").rail_faces();
    let wall = loose.iter().find(|f| f.name == "slot_wall_right").unwrap();
    assert!(wall.centre_m[0] > get("slot_wall_right").centre_m[0]);
}

#[test]
fn missile_inertia_defaults_to_a_solid_cylinder() {
    let l = launcher("launcher-design.toml");
    let i = l.missile.inertia_kg_m2();
    let (m, r, len) = (45.0, 0.089, 1.63);
    assert!((i[0] - m * (3.0 * r * r + len * len) / 12.0).abs() < 1e-12);
    assert!((i[2] - 0.5 * m * r * r).abs() < 1e-12);
}

#[test]
fn latch_spring_and_contacts() {
    let l = launcher("launcher-design.toml");
    assert!((l.latch_spring_installed_length_m() - 0.030).abs() < 1e-12);
    let def = l.contacts.rear_shoe_rail;
    assert_eq!(def, ContactSpec::thesis_default());
    assert!(l.contacts.mid_shoe_latch.stiffness_n_per_mm_e > def.stiffness_n_per_mm_e);
    assert!(l.contacts.latch_rail.stiffness_n_per_mm_e > def.stiffness_n_per_mm_e);
    // The latch tooth's rear face touches the mid shoe protrusion's front face at assembly.
    let tooth = l.latch.tooth_centre_in_rail_m();
    let pr = l.mid_shoe.protrusion.unwrap();
    let front = l.missile_to_rail_m(pr.centre_m)[2] + pr.half_extents_m[2];
    assert!((tooth[2] - l.latch.tooth.half_extents_m[2] - front).abs() < 1e-12);
}

#[test]
fn persistent_contact_derived_quantities() {
    let case = load("persistent-contact.toml");
    let Ok(ModelSpecRef::PersistentContact(p)) = case.model_spec() else {
        panic!("not a persistent contact case");
    };
    // 50 N over 3 pads of 6.35 mm x 6.35 mm.
    let expected = 50.0 / (3.0 * 0.00635 * 0.00635);
    assert!((p.nominal_pressure_pa() - expected).abs() < 1e-6);
    // eq. 4.4: peak slip = 30 deg x 2 pi x 1 Hz x 20 mm.
    let v = 30f64.to_radians() * 2.0 * std::f64::consts::PI * 0.020;
    assert!((p.peak_slip_speed_m_per_s() - v).abs() < 1e-12);
    assert_eq!(p.contact, ContactSpec::thesis_default());
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
