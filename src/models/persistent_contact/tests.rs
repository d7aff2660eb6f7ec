//! Persistent contact spec tests: the shipped case's derived quantities (eq. 4.4, 4.7).

use crate::models::spec::tests::load;
use crate::models::spec::{ContactSpec, ModelSpecRef};

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
