//! Tests of the reduced face law's closed forms and friction estimate (`reduced.rs`).

use super::*;
use crate::geometry::{HalfSpace, PlacedFace, QuadratureOrder};
use crate::physics::impact::ImpactParams;
use nalgebra::Isometry3;

#[test]
fn the_closed_forms_equal_a_fine_quadrature_of_the_densities() {
    // A shoe head's inner bottom face (half sides 18.5 and 39.5 mm, roundover 0.5 mm)
    // tilted on the plane y = 0 so that w runs from 0 to about 4 d across it, cut at
    // w = d into the core and the ramp (turned along w), with a closing rate affine in the
    // position. Every closed-form integral (force, load moment, stored energy, damping
    // power, the moments of ∂f/∂w and ∂f/∂ẇ) against the per-point law's densities
    // (`ImpactParams`) summed over 5 × 5 Gauss nodes on 64 slices per vertex interval: the
    // cycloid spans at most 2π across the ramp, so that rule is within about 1e-13; bound
    // 1e-9 of each integral's scale.
    let impact = ImpactParams::from_adams_units(1000.0, 2.0, 500.0, 0.01);
    let d = impact.full_damping_depth;
    let radius = 5e-4;
    let plane = HalfSpace::new(Vector3::y(), 0.0).expect("plane");
    let face = PlacedFace::new(plane, None, &Isometry3::identity());
    let n = Vector3::y();
    for (tilt_x, tilt_z, depth) in [
        (3e-4, 1e-4, 1.5e-5),
        (-2e-4, 6e-4, 2.2e-5),
        (1e-3, -5e-5, 4e-6),
    ] {
        let (a, b) = (0.0185, 0.0395);
        let axis_u = Vector3::new(a, -tilt_x * a, 0.0);
        let axis_v = Vector3::new(0.0, -tilt_z * b, b);
        let centre = Point3::new(0.0, radius - depth, 0.0);
        let Some(patch) = FacePatch::new(centre, axis_u, axis_v, radius, &face) else {
            panic!("pressed");
        };
        let rate_at = |x: &Point3<f64>| 2e-3 + 0.05 * x.x - 0.03 * x.z;
        let (core, ramp) = patch.split(&patch.depth().minus(d));
        let parts = [
            core.map(|c| (c, ClosedPart::Core)),
            ramp.map(|r| (r.aligned_with(&patch.depth()), ClosedPart::Ramp)),
        ];
        let mut checked = 0;
        for (part, kind) in parts.into_iter().flatten() {
            checked += 1;
            let rate = part.affine(|x| rate_at(&x));
            let got = part_integrals(&impact, &part, kind, &rate, radius, &n);
            let o = got.densities.origin;
            let (mut f0, mut f1, mut energy, mut power) = (0.0, Vector3::zeros(), 0.0, 0.0);
            let (mut a0, mut a1, mut a2) = (0.0, Vector3::zeros(), Matrix3::zeros());
            let (mut b0, mut b1, mut b2) = (0.0, Vector3::zeros(), Matrix3::zeros());
            let order = QuadratureOrder {
                across: 5,
                along: 5,
            };
            part.for_each_node_sliced(order, 64, &mut |x, share| {
                let w = radius - x.y;
                let wdot = rate_at(&x);
                let (spring, damping) = impact.force_parts(w);
                let f = spring + damping * wdot;
                let (dfdw, dfdwdot) = impact.unclamped_gradient(w, wdot, damping);
                let q = x - n * radius - o;
                f0 += share * f;
                f1 += q * (share * f);
                energy += share * impact.potential(w);
                power += share * damping * wdot * wdot;
                a0 += share * dfdw;
                a1 += q * (share * dfdw);
                a2 += q * q.transpose() * (share * dfdw);
                b0 += share * dfdwdot;
                b1 += q * (share * dfdwdot);
                b2 += q * q.transpose() * (share * dfdwdot);
            });
            let g = &got.densities;
            let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= 1e-9 * scale;
            let lever = b;
            assert!(close(g.f0, f0, f0.abs()), "{kind:?} f0 {} vs {f0}", g.f0);
            assert!((g.f1 - f1).norm() <= 1e-9 * f0.abs() * lever, "{kind:?} f1");
            assert!(close(got.energy, energy, energy), "{kind:?} energy");
            assert!(close(got.damping_power, power, power), "{kind:?} power");
            assert!(close(g.a0, a0, a0.abs()), "{kind:?} a0 {} vs {a0}", g.a0);
            assert!((g.a1 - a1).norm() <= 1e-9 * a0.abs() * lever, "{kind:?} a1");
            assert!(
                (g.a2 - a2).norm() <= 1e-9 * a0.abs() * lever * lever,
                "{kind:?} a2"
            );
            assert!(close(g.b0, b0, b0.abs()), "{kind:?} b0 {} vs {b0}", g.b0);
            assert!((g.b1 - b1).norm() <= 1e-9 * b0.abs() * lever, "{kind:?} b1");
            assert!(
                (g.b2 - b2).norm() <= 1e-9 * b0.abs() * lever * lever,
                "{kind:?} b2"
            );
            assert!(got.damping_power >= 0.0);
        }
        assert_eq!(checked, 2, "both a core and a ramp");
    }
}

#[test]
fn the_friction_estimate_bounds_the_per_point_laws_difference_on_a_turning_part() {
    // A part whose slip turns about its load centre: the friction μ(|s|) ŝ averaged over a
    // disc of points with uniform load, against one friction at the centre's slip. The
    // measured relative differences (force, power, N |s|) stay within the estimate, over
    // speeds across the stiction and friction transitions and beyond.
    let fr = FrictionParams::thesis_table_5_2();
    let radius = 0.02;
    for (speed, omega) in [
        (0.05, 0.5),
        (0.02, 0.3),
        (0.009, 0.1),
        (0.2, 2.0),
        (0.013, 0.05),
    ] {
        let delta: f64 = omega * radius;
        let estimate = friction_estimate(&fr, speed, delta);
        if !estimate.is_finite() {
            continue;
        }
        let s_c = Vector3::new(speed, 0.0, 0.0);
        let (mut force, mut power, mut slip, mut count) = (Vector3::zeros(), 0.0, 0.0, 0.0);
        let m = 60;
        for i in 0..m {
            for j in 0..m {
                let x = -radius + (2.0 * i as f64 + 1.0) * radius / m as f64;
                let z = -radius + (2.0 * j as f64 + 1.0) * radius / m as f64;
                if x * x + z * z > radius * radius {
                    continue;
                }
                // ω about the normal y: slip s_c + ω × r.
                let s = s_c + Vector3::new(omega * z, 0.0, -omega * x);
                let v = s.norm();
                let mu = fr.coefficient(v);
                force += s * (mu / v);
                power += mu * v;
                slip += v;
                count += 1.0;
            }
        }
        let mu_c = fr.coefficient(speed);
        let err_force = (force / count - s_c * (mu_c / speed)).norm() / mu_c;
        let err_power = (power / count - mu_c * speed).abs() / (mu_c * speed);
        let err_slip = (slip / count - speed).abs() / speed;
        let measured = err_force.max(err_power).max(err_slip);
        assert!(
            measured <= estimate,
            "|s_c| {speed}, δ {delta}: measured {measured:e} over the estimate {estimate:e}"
        );
    }
}
