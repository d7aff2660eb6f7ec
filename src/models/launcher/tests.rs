//! Launcher spec tests: the shipped variants' rattle spaces (eq. 6.1-6.3), the leaf spring's
//! engagement, the derived geometry (rail faces, shoe heads, latch tooth), missile inertia.

use super::LauncherSpec;
use crate::analysis::rattle_space::LauncherDimensions;
use crate::models::spec::tests::{load, round_to};
use crate::models::spec::{ContactSpec, ModelSpecRef};

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
