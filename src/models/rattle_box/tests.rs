//! Rattle box spec tests: the shipped cases A-D against Tables 5.1 and 5.2.

use crate::models::spec::tests::{load, round_to};
use crate::models::spec::ModelSpecRef;

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
