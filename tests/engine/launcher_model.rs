//! Launcher model (thesis chapter 6): static equilibrium after the settle, the rear leaf spring's
//! engagement per rail variant (thesis 6.3.1), and a short excited run with wear per contact.

use nalgebra::Vector3;
use railwear::models::case::{build, load_case, run_options};
use railwear::models::launcher::LauncherSpec;
use railwear::models::launcher::{CONTACT_NAMES, LEAF_SPRING_FORCE, MISSILE, RAIL};
use railwear::models::run::{run_model, BuiltModel};
use railwear::models::spec::{CaseSpec, ModelSpecRef};
use railwear::physics::body::BodyKind;
use railwear::physics::forces::ForceElement;
use railwear::physics::simulate::{simulate, DivergenceLimits};
use railwear::pipeline::RunControl;
use railwear::units::STANDARD_GRAVITY;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("configs")
}

fn case(file: &str) -> CaseSpec {
    load_case(&configs().join(file)).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn launcher(case: &CaseSpec) -> LauncherSpec {
    match case.model_spec() {
        Ok(ModelSpecRef::Launcher(l)) => l.clone(),
        other => panic!("not a launcher: {other:?}"),
    }
}

/// Builds the case with no base motion and integrates `settle_s`; returns the model and the
/// final state.
fn settle(file: &str, settle_s: f64) -> (CaseSpec, BuiltModel, Vec<f64>) {
    let mut c = case(file);
    c.excitation = railwear::models::spec::CaseExcitation::none();
    c.simulation.settle_s = 0.0;
    c.simulation.duration_s = settle_s;
    let model = build(&c, Path::new(&configs())).unwrap_or_else(|e| panic!("{file}: {e}"));
    let options = run_options(&c).unwrap();
    let mut y = model.initial_state.clone();
    simulate(
        &model.system,
        &mut y,
        0.0,
        settle_s,
        options.integrator,
        DivergenceLimits::default(),
        &RunControl::silent(),
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("{file}: {e}"));
    (c, model, y)
}

/// Leaf spring deflection δ (m) and the vertical force it puts on the missile (N) at state `y`.
fn leaf_spring(model: &BuiltModel, t: f64, y: &[f64]) -> (f64, f64) {
    let sys = &model.system;
    let mut ws = sys.workspace();
    sys.frames(t, y, &mut ws);
    let ForceElement::OneSidedSpring(s) = &sys.forces[LEAF_SPRING_FORCE] else {
        panic!("force {LEAF_SPRING_FORCE} is not the leaf spring");
    };
    let pa = ws.frames[s.a.body].to_world(&s.a.point);
    let pb = ws.frames[s.b.body].to_world(&s.b.point);
    let n = ws.frames[s.b.body].rotation * s.direction;
    let delta = (pb - pa).dot(&n) - s.engagement_gap;
    let mut wrenches = vec![(Vector3::zeros(), Vector3::zeros()); sys.bodies.len()];
    sys.forces[LEAF_SPRING_FORCE].accumulate(&ws.frames, &mut wrenches);
    (delta, wrenches[MISSILE].0.y)
}

#[test]
fn design_launcher_settles_to_static_equilibrium() {
    let t = 0.5;
    let (c, model, y) = settle("launcher-design.toml", t);
    let sys = &model.system;
    let l = launcher(&c);
    let weight = l.missile.mass_kg * STANDARD_GRAVITY;
    let BodyKind::Dynamic { offset } = sys.bodies[MISSILE].kind else {
        panic!("missile not dynamic");
    };
    // Acceleration of the missile is small: |a| < 1 % of g.
    let mut ws = sys.workspace();
    let mut dy = vec![0.0; sys.state_len()];
    sys.derivative(t, &y, &mut dy, &mut ws);
    let a = Vector3::new(dy[offset + 7], dy[offset + 8], dy[offset + 9]);
    assert!(
        a.norm() < 0.01 * STANDARD_GRAVITY,
        "missile acceleration {a:?} m/s² after {t} s settle"
    );
    // Conservation check, recomputed from the contact tracks and the leaf spring alone:
    // the vertical contact forces (normal and friction) on the missile, less the leaf spring's
    // push, carry its weight within 2 %.
    let mut contact_y = 0.0;
    sys.tracks(t, &y, &mut ws, &mut |tr| {
        let contact = &sys.contacts[tr.contact as usize];
        let speed = tr.slip_velocity.norm();
        let friction = if speed > 0.0 {
            -tr.slip_velocity * (tr.friction_force / speed)
        } else {
            Vector3::zeros()
        };
        let f = tr.normal * tr.normal_force + friction;
        if contact.body_a == MISSILE {
            contact_y += f.y;
        } else if contact.body_b == MISSILE {
            contact_y -= f.y;
        }
    });
    let (_, leaf_y) = leaf_spring(&model, t, &y);
    let constant_y: f64 = l
        .double_barrel_springs
        .iter()
        .map(|f| f.force_n * f.direction_in_rail[1])
        .sum();
    let total = contact_y + leaf_y + constant_y;
    assert!(
        (total - weight).abs() < 0.02 * weight,
        "vertical forces {total} N (contacts {contact_y} N, leaf {leaf_y} N) vs weight {weight} N"
    );
    // The latch holds the missile: the mid shoe-latch contact carries the double-barrel push
    // (30 N along +z) within 20 % (the rest is head friction).
    let push: f64 = l.double_barrel_springs.iter().map(|f| f.force_n).sum();
    let mut latch_z = 0.0;
    sys.tracks(t, &y, &mut ws, &mut |tr| {
        if sys.contacts[tr.contact as usize].name == "mid_shoe-latch" {
            latch_z += tr.normal.z * tr.normal_force;
        }
    });
    assert!(
        (latch_z + push).abs() < 0.2 * push,
        "latch reaction {latch_z} N vs push {push} N"
    );
}

#[test]
fn leaf_spring_engagement_follows_the_rail_clearance() {
    let mut forces = Vec::new();
    for file in [
        "launcher-tight.toml",
        "launcher-design.toml",
        "launcher-loose.toml",
    ] {
        let t = 0.3;
        let (c, model, y) = settle(file, t);
        let expected = launcher(&c).leaf_spring_static_compression_m();
        let (delta, f_y) = leaf_spring(&model, t, &y);
        if expected > 0.0 {
            assert!(
                delta > 0.0,
                "{file}: spec says engaged, simulated δ = {delta} m"
            );
            assert!(
                f_y < 0.0,
                "{file}: engaged spring must push the shoe down, {f_y} N"
            );
        } else {
            // Thesis 6.3.1: the loose rail's leaf spring is free when static.
            assert!(
                delta <= 0.0,
                "{file}: spec says free, simulated δ = {delta} m"
            );
            assert_eq!(f_y, 0.0, "{file}: a free spring carries no force");
        }
        // The shoes sink into the lips, so δ is below the assembly compression.
        assert!(
            delta < expected,
            "{file}: δ {delta} m vs assembly {expected} m"
        );
        forces.push(-f_y);
    }
    // Less vertical clearance, more leaf spring force.
    assert!(
        forces[0] > forces[1] && forces[1] >= forces[2],
        "leaf spring forces tight/design/loose {forces:?} N"
    );
}

#[test]
fn short_excited_run_reports_wear_per_contact() {
    let mut c = case("launcher-design.toml");
    c.simulation.settle_s = 0.1;
    c.simulation.duration_s = 0.3;
    let model = build(&c, &configs()).unwrap();
    let options = run_options(&c).unwrap();
    let report = run_model(&model, &options, &RunControl::silent())
        .unwrap_or_else(|e| panic!("launcher excited run: {e}"));
    assert!((report.window_s - 0.3).abs() < 1e-9);
    for name in CONTACT_NAMES {
        let cr = report
            .contacts
            .iter()
            .find(|r| r.name == name)
            .unwrap_or_else(|| panic!("contact {name} missing from the report"));
        assert!(
            cr.mass_rate_mg_per_h.is_finite() && cr.mass_rate_mg_per_h >= 0.0,
            "{name}: {}",
            cr.mass_rate_mg_per_h
        );
        assert!(cr.mean_friction_power_w.is_finite() && cr.mean_friction_power_w >= 0.0);
    }
    let rail_name = &model.system.bodies[RAIL].name;
    let rail = report
        .bodies
        .iter()
        .find(|b| &b.name == rail_name)
        .expect("rail in the body report");
    assert!(
        rail.mass_rate_mg_per_h.is_finite() && rail.mass_rate_mg_per_h >= 0.0,
        "rail wear rate {}",
        rail.mass_rate_mg_per_h
    );
    // The missile rests on its shoes, so the shoe-rail contacts carry load in the window: the
    // mean normal force of all contacts is at least the weight.
    let weight = launcher(&c).missile.mass_kg * STANDARD_GRAVITY;
    assert!(
        report.mean_normal_force_n > 0.9 * weight,
        "mean normal force {} N vs weight {weight} N",
        report.mean_normal_force_n
    );
}
