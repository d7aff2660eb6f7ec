//! The local error test measures each body's motion relative to the model's carrier (the
//! kinematic body that carries the excitation: `MultibodySystem::with_carrier`). Galilean
//! relativity fixes what that must give: a scene that drifts as a whole at a constant velocity
//! slides, creeps and wears exactly as the same scene at rest, so a drift must not loosen the
//! tolerance on the motion that slips.
//!
//! The scene is the latch's regime on the launcher: a sled on four spheres on an incline below
//! its friction angle, creeping inside the friction law's stiction transition while its base
//! shakes along the slope.
//!
//! The test's norm is also body by body (the largest of each body's root mean square), so a
//! body added beside the sled leaves the sled's steps as they were.

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use railwear::physics::body::{write_state, BodyKind, KinematicMotion, MassProperties, RigidBody};
use railwear::physics::friction::FrictionParams;
use railwear::physics::integrator::{IntegratorSettings, Tolerances};
use railwear::physics::simulate::{simulate, DivergenceLimits, StepView};
use railwear::pipeline::RunControl;
use railwear::validation::{sled_on_base, sled_rest_pose};
use std::sync::Arc;

/// Incline angle: 0.8 of the friction angle, so the sled creeps (`μ(v) = tan a` at a speed
/// inside the stiction transition).
fn angle() -> f64 {
    0.8 * FrictionParams::thesis_table_5_2().mu_static.atan()
}

/// The base: tilted by `angle` about z, drifting at `drift` (m/s, world) and shaking along
/// its slope with `amplitude` (m) at `omega` (rad/s).
struct ShakenBase {
    tilt: UnitQuaternion<f64>,
    drift: Vector3<f64>,
    amplitude: f64,
    omega: f64,
}

impl ShakenBase {
    fn slope(&self) -> Vector3<f64> {
        self.tilt * Vector3::x()
    }
}

impl KinematicMotion for ShakenBase {
    fn pose(&self, t: f64) -> Isometry3<f64> {
        let p = self.drift * t + self.slope() * (self.amplitude * (self.omega * t).sin());
        Isometry3::from_parts(Translation3::from(p), self.tilt)
    }
    fn velocity(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let v = self.drift + self.slope() * (self.amplitude * self.omega * (self.omega * t).cos());
        (v, Vector3::zeros())
    }
    fn acceleration(&self, t: f64) -> Vector3<f64> {
        self.slope() * (-self.amplitude * self.omega * self.omega * (self.omega * t).sin())
    }
}

/// The sled's downhill slip relative to the base over `t_end` s (m), the accepted steps, and
/// the mean of `N |v_slip|` (W) the wear integrates, with the base drifting at `drift`, with
/// or without the base as the carrier, at the case tolerance `rel`.
/// With `bystander`, a second body falls freely beside the sled, touching nothing.
fn creep(
    drift: Vector3<f64>,
    carrier: bool,
    rel: f64,
    t_end: f64,
    bystander: bool,
) -> (f64, u64, f64) {
    let tilt = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle());
    // 15 m/s² peak along the slope at 40 Hz: the inertial push swings the creep in and out of
    // the stiction transition, as the rail's shaking does the latch's.
    let omega = 2.0 * std::f64::consts::PI * 40.0;
    let base = Arc::new(ShakenBase {
        tilt,
        drift,
        amplitude: 15.0 / (omega * omega),
        omega,
    });
    let ground = RigidBody {
        name: "base".into(),
        mass: MassProperties {
            mass: 1.0,
            inertia: Matrix3::identity(),
        },
        kind: BodyKind::Kinematic(base.clone()),
    };
    let mut others = Vec::new();
    if bystander {
        others.push(RigidBody {
            name: "bystander".into(),
            mass: MassProperties {
                mass: 2.0,
                inertia: Matrix3::from_diagonal_element(4e-3),
            },
            kind: BodyKind::Dynamic { offset: 13 },
        });
    }
    let mut sys = sled_on_base(ground, others);
    if carrier {
        sys = sys.with_carrier(1);
    }
    // At t = 0 the base sits at the origin: the sled rests on it, moving with it.
    let mut y = vec![0.0; sys.state_len()];
    let (v0, _) = base.velocity(0.0);
    let rest = sled_rest_pose(angle());
    write_state(&mut y, 0, &rest, v0, Vector3::zeros());
    // The state's local error test alone: the energy account's work test (`energy_rel`)
    // integrates the drive's power, which a drift changes by nature (kinetic energy and the
    // base's work on the sled depend on the inertial frame), so it would see the drift.
    let mut tolerances = Tolerances::default().scaled(rel / Tolerances::default().rel);
    tolerances.energy_rel = 0.0;
    if bystander {
        // Free fall from 1 m beside the base, drifting with it: a quadratic in time, which the
        // second-order method integrates with no local error.
        write_state(
            &mut y,
            13,
            &Isometry3::translation(1.0, 1.0, 0.0),
            v0,
            Vector3::zeros(),
        );
    }
    let settings = IntegratorSettings {
        tolerances,
        ..IntegratorSettings::default()
    };
    let mut work = 0.0;
    let mut last: Option<(f64, f64)> = None;
    let stats = simulate(
        &sys,
        &mut y,
        0.0,
        t_end,
        settings,
        DivergenceLimits::default(),
        &RunControl::silent(),
        &mut |v: &StepView| {
            let p: f64 = v
                .tracks
                .iter()
                .map(|tr| tr.normal_force * tr.slip_speed)
                .sum();
            if let Some((t0, p0)) = last {
                work += 0.5 * (v.t - t0) * (p0 + p);
            }
            last = Some((v.t, p));
        },
    )
    .expect("the sled runs");
    let downhill = -base.slope();
    let relative = Vector3::new(y[0], y[1], y[2])
        - base.pose(t_end).translation.vector
        - rest.translation.vector;
    (
        relative.dot(&downhill),
        stats.integrator.accepted,
        work / t_end,
    )
}

#[test]
fn a_drifting_scene_creeps_as_the_scene_at_rest_when_its_base_is_the_carrier() {
    let t_end = 0.5;
    let rel = 1e-4;
    let drift = Vector3::new(20.0, 0.0, 10.0);
    let (d_rest, n_rest, p_rest) = creep(Vector3::zeros(), true, rel, t_end, false);
    let (d_drift, n_drift, p_drift) = creep(drift, true, rel, t_end, false);
    let (d_world, n_world, p_world) = creep(drift, false, rel, t_end, false);
    // A tight reference at rest (the same physics, a sixteenth of the tolerance).
    let (d_ref, _, p_ref) = creep(Vector3::zeros(), true, rel / 16.0, t_end, false);
    eprintln!(
        "slip relative to the base: rest {d_rest:.6e} m ({n_rest} steps, N|v| {p_rest:.6e} W), \
         drifting with the carrier {d_drift:.6e} m ({n_drift}, {p_drift:.6e} W), drifting in \
         the world frame {d_world:.6e} m ({n_world}, {p_world:.6e} W), reference {d_ref:.6e} m \
         ({p_ref:.6e} W)"
    );
    // The sled creeps and slides (not stuck): the slope's pull is below μ_s, the shaking
    // swings it through the stiction transition.
    assert!(d_ref > 0.0, "the sled slips downhill: {d_ref} m");
    // Resolved: the mean N|v| the wear integrates, at rest and drifting 22 m/s with the base
    // as the carrier, within 1e-3 of the tight reference. In the world frame the drift
    // loosens every velocity's tolerance by rel × 22 m/s, and the drifting scene misses by
    // 1.7e-3 (measured; printed above).
    for (what, p) in [("at rest", p_rest), ("drifting", p_drift)] {
        assert!(
            (p - p_ref).abs() <= 1e-3 * p_ref,
            "mean N|v| {what} {p:e} W against the reference {p_ref:e} W"
        );
    }
    // Galilean relativity: the tolerance sees the same relative motion, so the two agree to
    // within a quarter of that accuracy (the scatter of accept/reject decisions that round-off
    // in the drifted coordinates can flip; measured 1.2e-4; the world frame's 1.2e-3).
    assert!(
        (p_drift - p_rest).abs() <= 2.5e-4 * p_rest,
        "mean N|v| at rest {p_rest:e} W, drifting {p_drift:e} W"
    );
    assert!(
        (d_drift - d_rest).abs() <= 2.5e-4 * d_rest,
        "slip at rest {d_rest:e} m, drifting {d_drift:e} m"
    );
}

#[test]
fn a_body_beside_the_sled_leaves_its_steps_as_they_were() {
    let (d_alone, n_alone, p_alone) = creep(Vector3::zeros(), true, 1e-5, 0.5, false);
    let (d_pair, n_pair, p_pair) = creep(Vector3::zeros(), true, 1e-5, 0.5, true);
    eprintln!(
        "alone: {n_alone} steps, slip {d_alone:.6e} m, N|v| {p_alone:.6e} W; with a bystander: \
         {n_pair} steps, slip {d_pair:.6e} m, N|v| {p_pair:.6e} W"
    );
    // The bystander's entries carry no local error. A root mean square over every entry would
    // halve the sled's share of the sum and let its error-limited steps grow by 2^(1/6)
    // (measured with that norm: 744 steps against 785, a third of them at the largest step);
    // body by body the sled's test is its own. What is left is Newton's convergence test,
    // which weighs every entry and may end an iteration one update earlier or later.
    let steps = |a: u64, b: u64| (a as f64 - b as f64).abs() <= 0.02 * a as f64;
    assert!(
        steps(n_alone, n_pair),
        "{n_alone} steps alone, {n_pair} with a bystander"
    );
    assert!(
        (p_pair - p_alone).abs() <= 2.5e-4 * p_alone,
        "mean N|v| alone {p_alone:e} W, with a bystander {p_pair:e} W"
    );
}
