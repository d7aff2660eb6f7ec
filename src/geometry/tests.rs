//! Closed-form and brute-force checks of the overlap geometry (SPEC §2, thesis 2.5).

use super::*;
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_4, PI};

const INCH: f64 = 0.0254;

/// Thesis 5.1 cube: 1 in side, 0.02 in roundover.
fn thesis_cube() -> (ConvexShape, f64, f64) {
    let a = INCH;
    let r = 0.02 * INCH;
    (
        ConvexShape::rounded_box(Vector3::repeat(a / 2.0), r).unwrap(),
        a,
        r,
    )
}

/// Floor: solid z <= 0, normal +z.
fn floor() -> HalfSpace {
    HalfSpace::new(Vector3::z(), 0.0).unwrap()
}

/// Pose with `rotation` and the shape's lowest point at z = -w, found by brute force over the
/// inner-box corners (lowest corner minus the roundover), independent of the code under test.
fn pose_at_depth(
    rotation: UnitQuaternion<f64>,
    outer: Vector3<f64>,
    r: f64,
    w: f64,
) -> Isometry3<f64> {
    let h = outer - Vector3::repeat(r);
    let mut lowest = f64::INFINITY;
    for corner in 0..8 {
        let v = Vector3::new(
            if corner & 1 == 0 { h.x } else { -h.x },
            if corner & 2 == 0 { h.y } else { -h.y },
            if corner & 4 == 0 { h.z } else { -h.z },
        );
        lowest = lowest.min((rotation * v).z);
    }
    let tz = -w - (lowest - r);
    Isometry3::from_parts(Translation3::new(0.0012, -0.0031, tz), rotation)
}

/// Area of a circular segment of height `w` in a disk of radius `r`.
fn segment_area(r: f64, w: f64) -> f64 {
    r * r * ((r - w) / r).acos() - (r - w) * (2.0 * r * w - w * w).sqrt()
}

fn cap(r: f64, w: f64) -> f64 {
    PI * w * w * (r - w / 3.0)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn sphere_on_plane_area_matches_cap_closed_form() {
    let radius = 0.01;
    let ball = ConvexShape::sphere(radius).unwrap();
    // The same ball written as a rounded box whose roundover equals its half extents.
    let ball_box = ConvexShape::rounded_box(Vector3::repeat(radius), radius).unwrap();
    for k in 0..=12 {
        let ratio = 10f64.powf(-5.0 + 3.0 * k as f64 / 12.0);
        let w = ratio * radius;
        let pose = Isometry3::translation(0.3, -0.2, radius - w);
        let o = shape_halfspace_overlap(&ball, &pose, &floor()).unwrap();
        let exact_area = PI * radius * w * (1.0 - w / (3.0 * radius));
        assert!(rel(o.depth, w) < 1e-9);
        assert!(
            rel(o.area, exact_area) < 1e-9,
            "w/R {ratio}: {} vs {exact_area}",
            o.area
        );
        // Cap centroid: 3 (2R - w)² / (4 (3R - w)) below the centre.
        let t = 2.0 * radius - w;
        let zc = radius - w - 3.0 * t * t / (4.0 * (3.0 * radius - w));
        assert!((o.centroid.z - zc).abs() < 1e-9 * w);
        assert!((o.deepest_point - Point3::new(0.3, -0.2, -w)).norm() < 1e-15);
        // Tilted pose of the ball-as-box: same cap (vertex pieces only).
        let rot = UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1);
        let pose = Isometry3::from_parts(Translation3::new(0.0, 0.0, radius - w), rot);
        let o = shape_halfspace_overlap(&ball_box, &pose, &floor()).unwrap();
        assert!(
            rel(o.area, exact_area) < 1e-6,
            "box-ball w/R {ratio}: {} vs {exact_area}",
            o.area
        );
    }
    let far = Isometry3::translation(0.0, 0.0, radius * 1.001);
    assert!(shape_halfspace_overlap(&ball, &far, &floor()).is_none());
}

#[test]
fn sharp_box_face_tilted_gives_wedge() {
    let a = INCH;
    let sharp = ConvexShape::rounded_box(Vector3::repeat(a / 2.0), 0.0).unwrap();
    for theta_deg in [0.5f64, 2.0] {
        let theta = theta_deg.to_radians();
        let rot = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.4)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), theta);
        // Wedge stays within the face: w / tan θ <= a.
        for frac in [0.05, 0.5, 0.95] {
            let w = frac * a * theta.tan();
            let pose = pose_at_depth(rot, Vector3::repeat(a / 2.0), 0.0, w);
            let o = shape_halfspace_overlap(&sharp, &pose, &floor()).unwrap();
            // Triangular prism of length a: apex angle 90° at the lowest edge, sides along the
            // tilted face (w / tan θ) and the side face (w tan θ).
            let prism = a * w * w * (1.0 / theta.tan() + theta.tan()) / 2.0;
            let wedge = w * w * a / (2.0 * theta.tan());
            assert!(rel(o.volume, prism) < 1e-9, "{} vs {prism}", o.volume);
            assert!(rel(o.volume, wedge) < 0.01);
            assert!(rel(o.area, wedge / w) < 0.01);
            assert!(rel(o.depth, w) < 1e-9);
        }
    }
}

#[test]
fn rounded_edge_parallel_to_plane_gives_truncated_cylinder() {
    let (cube, a, r) = thesis_cube();
    let rot = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_4);
    let length = a - 2.0 * r; // inner edge length
    for frac in [0.01, 0.1, 0.2, 0.29] {
        let w = frac * r; // < r (1 - cos 45°) = 0.293 r: the segment stays on the edge arc
        let pose = pose_at_depth(rot, Vector3::repeat(a / 2.0), r, w);
        let o = shape_halfspace_overlap(&cube, &pose, &floor()).unwrap();
        let cylinder = length * segment_area(r, w);
        // End caps: the two ball octants pairs at the edge ends form one cap of height w.
        let exact = cylinder + cap(r, w);
        assert!(
            rel(o.volume, exact) < 1e-6,
            "{frac}: {} vs {exact}",
            o.volume
        );
        assert!(rel(o.volume, cylinder) < 0.02);
        // Centroid on the symmetry plane through the edge midpoint.
        assert!((o.centroid.x - pose.translation.x).abs() < 1e-9 * a);
    }
}

#[test]
fn rounded_corner_lowest_gives_sphere_cap() {
    let (cube, a, r) = thesis_cube();
    let diagonal = Vector3::new(1.0, 1.0, 1.0).normalize();
    let rot = UnitQuaternion::from(Rotation3::rotation_between(&diagonal, &Vector3::z()).unwrap());
    for frac in [1e-4, 0.01, 0.1, 0.18] {
        // cap half angle acos(1 - w/r) < 35.26°: the cap stays inside the corner octant
        let w = frac * r;
        let pose = pose_at_depth(rot, Vector3::repeat(a / 2.0), r, w);
        let o = shape_halfspace_overlap(&cube, &pose, &floor()).unwrap();
        assert!(
            rel(o.volume, cap(r, w)) < 1e-6,
            "{frac}: {} vs {}",
            o.volume,
            cap(r, w)
        );
        let t = 2.0 * r - w;
        let zc = -w + r - 3.0 * t * t / (4.0 * (3.0 * r - w));
        assert!((o.centroid.z - zc).abs() < 1e-6 * w);
        let deepest = pose * Point3::from(-Vector3::repeat(a / 2.0 - r) - diagonal * r);
        assert!((o.deepest_point - deepest).norm() < 1e-12);
    }
}

#[test]
fn cube_resting_flat_matches_decomposition_closed_form() {
    let (cube, a, r) = thesis_cube();
    let inner = a - 2.0 * r;
    for yaw in [0.0, 0.9] {
        let rot = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
        for frac in [1e-3, 0.1, 0.5, 1.0] {
            let w = frac * r;
            let pose = pose_at_depth(rot, Vector3::repeat(a / 2.0), r, w);
            let o = shape_halfspace_overlap(&cube, &pose, &floor()).unwrap();
            // face slab + 4 edges (each half a segment) + 4 corners (each a quarter cap)
            let exact = inner * inner * w + 2.0 * inner * segment_area(r, w) + cap(r, w);
            assert!(
                rel(o.volume, exact) < 1e-10,
                "{frac}: {} vs {exact}",
                o.volume
            );
            assert!(rel(o.area, exact / w) < 1e-10);
            let lateral = (o.centroid.coords - pose.translation.vector).xy().norm();
            assert!(lateral < 1e-12, "lateral centroid offset {lateral}");
            assert!(
                (o.deepest_point.coords - pose.translation.vector)
                    .xy()
                    .norm()
                    < 1e-15
            );
        }
    }
}

/// Overlap of the vertical line through (x, y) with {z in [-w, 0], dist(x, K) <= r}: the
/// distance is convex along the line, so golden-section for its minimum, then bisection for
/// the two crossings. Returns (length, mid height).
fn line_overlap(
    x: f64,
    y: f64,
    w: f64,
    pose: &Isometry3<f64>,
    h: &Vector3<f64>,
    r: f64,
) -> (f64, f64) {
    // Line in the shape frame: p0 + z d (plain arithmetic: this runs unoptimised).
    let p0 = pose.inverse_transform_point(&Point3::new(x, y, 0.0)).coords;
    let d = pose.inverse_transform_vector(&Vector3::z());
    let (p, dv, hh) = ([p0.x, p0.y, p0.z], [d.x, d.y, d.z], [h.x, h.y, h.z]);
    let f2 = |z: f64| {
        let mut s = 0.0;
        for i in 0..3 {
            let e = ((p[i] + z * dv[i]).abs() - hh[i]).max(0.0);
            s += e * e;
        }
        s
    };
    let r2 = r * r;
    let (mut lo, mut hi) = (-w, 0.0);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..45 {
        let z1 = hi - g * (hi - lo);
        let z2 = lo + g * (hi - lo);
        if f2(z1) < f2(z2) {
            hi = z2;
        } else {
            lo = z1;
        }
    }
    let zmin = 0.5 * (lo + hi);
    if f2(zmin) > r2 {
        return (0.0, 0.0);
    }
    let cross = |mut inside: f64, mut outside: f64| {
        for _ in 0..40 {
            let mid = 0.5 * (inside + outside);
            if f2(mid) <= r2 {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        0.5 * (inside + outside)
    };
    let bottom = if f2(-w) <= r2 { -w } else { cross(zmin, -w) };
    let top = if f2(0.0) <= r2 { 0.0 } else { cross(zmin, 0.0) };
    (top - bottom, 0.5 * (top + bottom))
}

/// Midpoint-rule volume and centroid on an `n × n` grid over `[s0, s1] × [t0, t1]` in the
/// horizontal frame `(e1, e2)` (`e2` = z × `e1`). Also returns the bounding box of the hit
/// cells in that frame and the second moment of the hit cells (for the strip direction).
fn grid_overlap(
    e1: [f64; 2],
    rect: [f64; 4],
    n: usize,
    w: f64,
    pose: &Isometry3<f64>,
    h: &Vector3<f64>,
    r: f64,
) -> (f64, Vector3<f64>, [f64; 4], [f64; 3]) {
    let e2 = [-e1[1], e1[0]];
    let [s0, s1, t0, t1] = rect;
    let (ds, dt) = ((s1 - s0) / n as f64, (t1 - t0) / n as f64);
    let mut volume = 0.0;
    let mut moment = Vector3::zeros();
    let mut hit = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut cov = [0.0; 3];
    for i in 0..n {
        for j in 0..n {
            let s = s0 + (i as f64 + 0.5) * ds;
            let t = t0 + (j as f64 + 0.5) * dt;
            let (x, y) = (s * e1[0] + t * e2[0], s * e1[1] + t * e2[1]);
            let (len, zm) = line_overlap(x, y, w, pose, h, r);
            if len > 0.0 {
                let v = len * ds * dt;
                volume += v;
                moment += Vector3::new(x, y, zm) * v;
                hit = [hit[0].min(s), hit[1].max(s), hit[2].min(t), hit[3].max(t)];
                cov = [cov[0] + v * x * x, cov[1] + v * x * y, cov[2] + v * y * y];
            }
        }
    }
    let c = moment / volume;
    let cov = [
        cov[0] / volume - c.x * c.x,
        cov[1] / volume - c.x * c.y,
        cov[2] / volume - c.y * c.y,
    ];
    (volume, c, hit, cov)
}

#[test]
fn random_orientations_match_brute_force_integration() {
    let (cube, a, r) = thesis_cube();
    let outer = Vector3::repeat(a / 2.0);
    let h = outer - Vector3::repeat(r);
    let mut rng = ChaCha8Rng::seed_from_u64(2014);
    let depths = [0.01, 0.1, 0.5, 1.0, 2.0, 0.03, 0.3, 1.5];
    for frac in depths {
        let w = frac * r;
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ));
        let pose = pose_at_depth(q, outer, r, w);
        let o = shape_halfspace_overlap(&cube, &pose, &floor()).unwrap();
        // Lateral bound: x = k + b with k ∈ K, |b| <= r, so k lies in K ∩ {z <= r}; its
        // vertices are the corners and edge crossings of z = r.
        let corners: Vec<Vector3<f64>> = (0..8)
            .map(|c| {
                let v = Vector3::new(
                    if c & 1 == 0 { h.x } else { -h.x },
                    if c & 2 == 0 { h.y } else { -h.y },
                    if c & 4 == 0 { h.z } else { -h.z },
                );
                (pose * Point3::from(v)).coords
            })
            .collect();
        let mut pts = Vec::new();
        for (i, p) in corners.iter().enumerate() {
            if p.z <= r {
                pts.push(*p);
            }
            for bit in [1, 2, 4] {
                let qv = corners[i ^ bit];
                if (p.z - r) * (qv.z - r) < 0.0 {
                    pts.push(p + (qv - p) * ((r - p.z) / (qv.z - p.z)));
                }
            }
        }
        let mut rect = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in &pts {
            rect = [
                rect[0].min(p.x),
                rect[1].max(p.x),
                rect[2].min(p.y),
                rect[3].max(p.y),
            ];
        }
        rect = [rect[0] - r, rect[1] + r, rect[2] - r, rect[3] + r];
        // Coarse pass to find the patch, then a fine pass on its bounding box (+2 cells) in a
        // frame aligned with its long axis (thin strips when an edge is nearly parallel).
        let coarse = 40;
        let (_, _, hit, cov) = grid_overlap([1.0, 0.0], rect, coarse, w, &pose, &h, r);
        let (cx, cy) = (
            (rect[1] - rect[0]) / coarse as f64,
            (rect[3] - rect[2]) / coarse as f64,
        );
        let angle = 0.5 * (2.0 * cov[1]).atan2(cov[0] - cov[2]);
        let e1 = [angle.cos(), angle.sin()];
        let pad = 2.0 * cx.hypot(cy);
        // corners of the coarse hit box (+pad) and the deepest point, in the rotated frame
        let dp = o.deepest_point;
        let mut fine_rect = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for (x, y) in [
            (hit[0] - pad, hit[2] - pad),
            (hit[0] - pad, hit[3] + pad),
            (hit[1] + pad, hit[2] - pad),
            (hit[1] + pad, hit[3] + pad),
            (dp.x, dp.y),
        ] {
            let (s, t) = (x * e1[0] + y * e1[1], -x * e1[1] + y * e1[0]);
            fine_rect = [
                fine_rect[0].min(s),
                fine_rect[1].max(s),
                fine_rect[2].min(t),
                fine_rect[3].max(t),
            ];
        }
        let (volume, centroid, hit, _) = grid_overlap(e1, fine_rect, 120, w, &pose, &h, r);
        // Patch size: diameter of the patch (a near-parallel edge gives a long thin sliver).
        let patch = (hit[1] - hit[0]).hypot(hit[3] - hit[2]);
        assert!(
            rel(o.volume, volume) < 0.01,
            "w/r {frac}: {} vs brute {volume}",
            o.volume
        );
        let off = (o.centroid.coords - centroid).norm();
        assert!(
            off < 0.01 * patch,
            "w/r {frac}: centroid off by {off}, patch {patch}"
        );
    }
}

#[test]
fn sphere_sphere_lens_matches_closed_form() {
    let (ra, rb) = (0.01, 0.006);
    let ca = Point3::new(0.1, 0.2, 0.3);
    let dir = Vector3::new(1.0, -2.0, 0.5).normalize();
    for w in [1e-6, 1e-4, 3e-3] {
        let d = ra + rb - w;
        let cb = ca + dir * d;
        let o = sphere_sphere_overlap(ra, &ca, rb, &cb).unwrap();
        // Standard lens volume.
        let exact =
            PI * (ra + rb - d).powi(2) * (d * d + 2.0 * d * (ra + rb) - 3.0 * (ra - rb).powi(2))
                / (12.0 * d);
        assert!(rel(o.volume, exact) < 1e-9);
        assert!(rel(o.area, exact / w) < 1e-9);
        assert!((o.normal.into_inner() - dir).norm() < 1e-14);
    }
    // Equal spheres: lens symmetric about the midpoint.
    let cb = ca + dir * 0.019;
    let o = sphere_sphere_overlap(0.01, &ca, 0.01, &cb).unwrap();
    assert!(rel(o.volume, 2.0 * cap(0.01, 0.0005)) < 1e-12);
    assert!((o.centroid - (ca + dir * 0.0095)).norm() < 1e-15);
    assert!(sphere_sphere_overlap(ra, &ca, rb, &(ca + dir * 0.0161)).is_none());
}

#[test]
fn mass_properties_match_limits_and_thesis_cube() {
    // Sharp box: m (b² + c²) / 12 with full side lengths.
    let sharp = ConvexShape::rounded_box(Vector3::new(0.1, 0.2, 0.3), 0.0).unwrap();
    let (m, i) = sharp.mass_properties(1000.0).unwrap();
    assert!(rel(m, 1000.0 * 0.2 * 0.4 * 0.6) < 1e-14);
    assert!(rel(i.x, m * (0.4f64.powi(2) + 0.6f64.powi(2)) / 12.0) < 1e-13);
    // Fully rounded: a ball, 2/5 m r².
    let ball = ConvexShape::rounded_box(Vector3::repeat(0.05), 0.05).unwrap();
    let (m, i) = ball.mass_properties(2810.0).unwrap();
    assert!(rel(m, 2810.0 * 4.0 / 3.0 * PI * 0.05f64.powi(3)) < 1e-14);
    assert!(rel(i.z, 0.4 * m * 0.0025) < 1e-13);
    // Capsule-like check: half extents (0.05, r, r) with roundover r is a capsule along x.
    let r = 0.01;
    let capsule = ConvexShape::rounded_box(Vector3::new(0.05, r, r), r).unwrap();
    let (m, i) = capsule.mass_properties(1.0).unwrap();
    let l = 0.08; // cylinder length
    let mc = PI * r * r * l;
    let ms = 4.0 / 3.0 * PI * r.powi(3);
    assert!(rel(m, mc + ms) < 1e-14);
    assert!(rel(i.x, 0.5 * mc * r * r + 0.4 * ms * r * r) < 1e-13);
    // SPEC §2: the thesis 1 in 7075 cube weighs about 46 g.
    let (cube, _, _) = thesis_cube();
    let (m, _) = cube.mass_properties(2810.0).unwrap();
    assert!((m - 0.046).abs() < 0.01 * 0.046, "cube mass {m}");
}

#[test]
fn validation_names_the_field() {
    let e = ConvexShape::rounded_box(Vector3::new(0.1, -1.0, 0.1), 0.0).unwrap_err();
    assert!(e.to_string().contains("half_extents.y"));
    let e = ConvexShape::rounded_box(Vector3::repeat(0.1), 0.2).unwrap_err();
    assert!(matches!(e, GeometryError::RoundoverTooLarge { .. }));
    let e = ConvexShape::rounded_box(Vector3::repeat(0.1), f64::NAN).unwrap_err();
    assert!(e.to_string().contains("roundover"));
    assert!(ConvexShape::sphere(0.0)
        .unwrap_err()
        .to_string()
        .contains("radius"));
    assert!(HalfSpace::new(Vector3::zeros(), 0.0).is_err());
    let (cube, _, _) = thesis_cube();
    assert!(cube
        .mass_properties(-1.0)
        .unwrap_err()
        .to_string()
        .contains("density"));
}

#[test]
fn volume_is_continuous_and_monotone_in_depth() {
    // Sweeping the depth across every piece boundary of a generic orientation: volume must
    // grow, and dV/dw ≈ cross-section area (between the areas at w and w + dw).
    let (cube, a, r) = thesis_cube();
    let rot = UnitQuaternion::from_euler_angles(0.05, 0.02, 0.3);
    let outer = Vector3::repeat(a / 2.0);
    let mut last = 0.0;
    for k in 1..200 {
        let w = k as f64 * 0.02 * r;
        let o = shape_halfspace_overlap(&cube, &pose_at_depth(rot, outer, r, w), &floor()).unwrap();
        assert!(o.volume > last);
        last = o.volume;
    }
    // Whole cube submerged: the full volume and the centre.
    let deep = pose_at_depth(rot, outer, r, 2.0 * a);
    let o = shape_halfspace_overlap(&cube, &deep, &floor()).unwrap();
    assert!(rel(o.volume, cube.volume()) < 1e-12);
    assert!((o.centroid.coords - deep.translation.vector).norm() < 1e-12 * a);
}

/// Micro benchmark (run with `cargo test --release --lib geometry::tests::bench -- --ignored
/// --nocapture`): time per call for a tilted thesis cube.
#[test]
#[ignore]
fn bench_tilted_cube() {
    let (cube, a, r) = thesis_cube();
    let outer = Vector3::repeat(a / 2.0);
    let cases = [
        (
            "corner lowest",
            UnitQuaternion::from_euler_angles(0.3, 0.5, 0.2),
            0.5 * r,
        ),
        (
            "face tilted 2°",
            UnitQuaternion::from_euler_angles(0.035, 0.0, 0.0),
            0.5 * r,
        ),
        (
            "face tilted 0.1°x0.1°",
            UnitQuaternion::from_euler_angles(0.0017, 0.0017, 0.0),
            0.5 * r,
        ),
        ("resting flat", UnitQuaternion::identity(), 0.5 * r),
    ];
    for (name, rot, w) in cases {
        let pose = pose_at_depth(rot, outer, r, w);
        let n = 200_000;
        let t0 = std::time::Instant::now();
        let mut acc = 0.0;
        for k in 0..n {
            let p = Isometry3::from_parts(
                Translation3::new(0.0, 0.0, pose.translation.z - 1e-12 * k as f64),
                pose.rotation,
            );
            acc += shape_halfspace_overlap(&cube, &p, &floor()).map_or(0.0, |o| o.volume);
        }
        let dt = t0.elapsed().as_secs_f64() / n as f64;
        println!("{name}: {:.2} µs/call (checksum {acc:e})", dt * 1e6);
    }
}

#[test]
fn depth_query_matches_the_overlap_and_the_brute_force_depth() {
    let (cube, a, r) = thesis_cube();
    let outer = Vector3::repeat(a / 2.0);
    let ball = ConvexShape::Sphere { radius: 0.75 * a };
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    for i in 0..200 {
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ));
        // Depth set by brute force over the corners (pose_at_depth), from just touching to
        // deeper than the roundover; every 10th pose lifted clear of the floor.
        let w = r * 10f64.powf(rng.gen_range(-4.0..0.5));
        let mut pose = pose_at_depth(q, outer, r, w);
        if i % 10 == 0 {
            pose.translation.vector.z += 2.0 * w;
        }
        for shape in [&cube, &ball] {
            let depth = shape_halfspace_depth(shape, &pose, &floor());
            let overlap = shape_halfspace_overlap(shape, &pose, &floor());
            match (depth, overlap) {
                (Some((d, p)), Some(o)) => {
                    assert_eq!(d, o.depth);
                    assert_eq!(p, o.deepest_point);
                    // The deepest point lies at depth d below the floor.
                    assert!((p.z + d).abs() < 1e-15, "{} vs {d}", p.z);
                }
                (None, None) => assert!(i % 10 == 0 || shape == &ball),
                (d, o) => panic!("pose {i}: depth {d:?} but overlap {o:?}"),
            }
            if shape == &cube {
                let expected = if i % 10 == 0 { None } else { Some(w) };
                let got = depth.map(|(d, _)| d);
                match (expected, got) {
                    (Some(e), Some(g)) => assert!((g - e).abs() < 1e-15 + 1e-12 * e),
                    (None, None) => {}
                    _ => panic!("pose {i}: expected depth {expected:?}, got {got:?}"),
                }
            }
        }
    }
}
