//! Bit-for-bit checks of the exact face contact's geometry shortcuts (docs/journal/performance.md,
//! seventeenth pass): a split's parts, an inner face's parts from one pressed square, and the
//! signed distance within a reach.

use super::*;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// Random head-like inner faces over a bounded lip (edges at `s = 0` and `t = 0.03`, the
/// plane `y = 0` tilted slightly): (centre, axis_u, axis_v, radius, face).
#[allow(clippy::type_complexity)]
fn random_faces_over_a_lip(
    n: usize,
) -> Vec<(Point3<f64>, Vector3<f64>, Vector3<f64>, f64, PlacedFace)> {
    let mut rng = ChaCha8Rng::seed_from_u64(27);
    (0..n)
        .map(|_| {
            let tilt = UnitQuaternion::from_euler_angles(
                rng.gen_range(-0.02..0.02),
                rng.gen_range(-0.5..0.5),
                rng.gen_range(-0.02..0.02),
            );
            let plane = HalfSpace::new(tilt * Vector3::y(), rng.gen_range(-1e-4..1e-4)).unwrap();
            let extent = FaceExtent {
                origin: Point3::origin(),
                tangent: Vector3::x_axis(),
                s_range_m: (f64::NEG_INFINITY, 0.0),
                t_range_m: (f64::NEG_INFINITY, 0.03),
            };
            let face = PlacedFace::new(plane, Some(&extent), &Isometry3::identity());
            let radius = 5e-4;
            let pose = UnitQuaternion::from_euler_angles(
                rng.gen_range(-0.05..0.05),
                rng.gen_range(-PI..PI),
                rng.gen_range(-0.05..0.05),
            );
            let centre = Point3::new(
                rng.gen_range(-0.02..0.02),
                radius - rng.gen_range(-1e-4..2e-4),
                rng.gen_range(0.0..0.05),
            );
            let axis_u = pose * Vector3::x() * rng.gen_range(0.003..0.02);
            let axis_v = pose * Vector3::z() * rng.gen_range(0.003..0.04);
            (centre, axis_u, axis_v, radius, face)
        })
        .collect()
}

fn same_polygon(a: Option<&FacePatch>, b: Option<&FacePatch>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.vertices().len() == b.vertices().len()
                && a.vertices().iter().zip(b.vertices()).all(|(p, q)| {
                    p[0].to_bits() == q[0].to_bits() && p[1].to_bits() == q[1].to_bits()
                })
        }
        _ => false,
    }
}

#[test]
fn both_parts_of_a_split_are_the_clips_by_the_line_and_by_its_negation_bit_for_bit() {
    // `split` takes the line at each vertex once and clips the part below with the values
    // negated; before, it clipped by the negated line itself. `split(−line).0` is that clip
    // (its values are the negated line's own), so each part must equal it bit for bit.
    let mut cut = 0;
    for (centre, axis_u, axis_v, radius, face) in random_faces_over_a_lip(400) {
        let Some(patch) = FacePatch::new(centre, axis_u, axis_v, radius, &face) else {
            continue;
        };
        for k in 0..4 {
            let a = [0.3, -1.1, 0.7, 2.0][k];
            let dir = Vector3::new(a, 1.0, -a * a);
            let line = patch.affine(|x| dir.dot(&(x - centre)) - 1e-4 * a);
            let opposite = patch.affine(|x| -(dir.dot(&(x - centre)) - 1e-4 * a));
            let (above, below) = patch.split(&line);
            let (o_above, o_below) = patch.split(&opposite);
            assert!(same_polygon(above.as_ref(), o_below.as_ref()));
            assert!(same_polygon(below.as_ref(), o_above.as_ref()));
            cut += usize::from(above.is_some() && below.is_some());
        }
    }
    assert!(cut > 100, "only {cut} lines cut a patch");
}

#[test]
fn the_parts_of_an_inner_face_are_its_pressed_polygon_and_strips_bit_for_bit() {
    let mut strips = 0;
    for (centre, axis_u, axis_v, radius, face) in random_faces_over_a_lip(400) {
        let mut pressed = None;
        let mut beyond = Vec::new();
        FacePatch::for_each_part(centre, axis_u, axis_v, radius, &face, |part, strip| {
            if strip {
                beyond.push(*part);
            } else {
                pressed = Some(*part);
            }
        });
        let want = FacePatch::new(centre, axis_u, axis_v, radius, &face);
        assert!(same_polygon(pressed.as_ref(), want.as_ref()));
        let want: Vec<_> = FacePatch::beyond_sides(centre, axis_u, axis_v, radius, &face)
            .into_iter()
            .flatten()
            .collect();
        assert_eq!(beyond.len(), want.len());
        for (got, want) in beyond.iter().zip(&want) {
            assert!(same_polygon(Some(got), Some(want)));
        }
        strips += want.len();
    }
    assert!(strips > 50, "only {strips} strips");
}

#[test]
fn signed_distance_within_a_reach_is_the_signed_distance_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(28);
    let (mut some, mut none) = (0, 0);
    for (_, _, _, radius, face) in random_faces_over_a_lip(50) {
        for _ in 0..200 {
            let x = Point3::new(
                rng.gen_range(-2e-3..2e-3),
                rng.gen_range(-1e-3..2e-3),
                rng.gen_range(0.028..0.032),
            );
            let (d, n) = face.signed_distance(&x);
            match face.signed_distance_within(&x, radius) {
                Some((dw, nw)) => {
                    some += 1;
                    assert!(radius - d > 0.0);
                    assert_eq!(d.to_bits(), dw.to_bits());
                    for k in 0..3 {
                        assert_eq!(n[k].to_bits(), nw[k].to_bits());
                    }
                }
                None => {
                    none += 1;
                    assert!(radius - d <= 0.0);
                }
            }
        }
    }
    assert!(some > 1000 && none > 1000, "{some} within, {none} beyond");
}
