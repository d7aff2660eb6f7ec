//! The exact face contact's closed forms: the monomial moments of a pressed polygon
//! ([`PolygonMoments`], docs/reference/models.md "Closed-form parts") against an independent fine
//! quadrature on random clipped polygons, and the stored energy and the dissipation of heads
//! that press and separate at once (where the clamp holds over a whole part, that part is
//! integrated in closed form) against the continuum by a brute-force midpoint rule.

use super::face_contact::{
    continuum_cells, evaluate, lip_contact, lip_plane, lowest_point_depth, table_6_2, HALF,
    ROUNDOVER,
};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use railwear::geometry::{FacePatch, PlacedFace, PolygonMoments};
use railwear::physics::impact::ImpactParams;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `∫_P f dA` over a convex polygon (vertices in order) by an independent rule: composite
/// Simpson in `u` on `panels` panels over the whole range (not split at the vertices: its
/// error is O(h²) at their kinks), and in `v` Simpson on the column `[lo, hi]` found by
/// intersecting the edges (exact for the cubic densities tested).
fn simpson_over(verts: &[[f64; 2]], f: &dyn Fn(f64, f64) -> f64, panels: usize) -> f64 {
    let (u_min, u_max) = verts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
            (a.0.min(p[0]), a.1.max(p[0]))
        });
    let column = |u: f64| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..verts.len() {
            let (p, q) = (verts[i], verts[(i + 1) % verts.len()]);
            let (a, b) = (p[0].min(q[0]), p[0].max(q[0]));
            if u < a || u > b || b == a {
                continue;
            }
            let v = p[1] + (q[1] - p[1]) * (u - p[0]) / (q[0] - p[0]);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if hi <= lo {
            return 0.0;
        }
        let mid = 0.5 * (lo + hi);
        (hi - lo) / 6.0 * (f(u, lo) + 4.0 * f(u, mid) + f(u, hi))
    };
    let h = (u_max - u_min) / panels as f64;
    let mut sum = column(u_min) + column(u_max);
    for i in 1..panels {
        let u = u_min + i as f64 * h;
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * column(u);
    }
    sum * h / 3.0
}

/// An affine function `c + g · (ξ − ξ₀)` as [`PolygonMoments::product`] takes it.
type Affine = (f64, [f64; 2]);
/// A density of `ξ = (u, v)`.
type Density<'a> = dyn Fn(f64, f64) -> f64 + 'a;

/// A shoe head's inner bottom face at a random tilt and depth against a bounded lip top,
/// split by a random line (where the law would change form): one of the parts.
fn random_part(rng: &mut ChaCha8Rng) -> Option<FacePatch> {
    let (plane, extent) = lip_plane();
    let face = PlacedFace::new(plane, Some(&extent), &Isometry3::identity());
    let rot = UnitQuaternion::from_euler_angles(
        rng.gen_range(-0.02..0.02),
        rng.gen_range(-3.2..3.2),
        rng.gen_range(-0.02..0.02),
    );
    let centre = Point3::new(
        rng.gen_range(-0.03..0.03),
        ROUNDOVER - rng.gen_range(-2e-4..4e-4),
        0.0,
    );
    let axis_u = rot * Vector3::x() * (HALF[0] - ROUNDOVER);
    let axis_v = rot * Vector3::z() * (HALF[2] - ROUNDOVER);
    let patch = FacePatch::new(centre, axis_u, axis_v, ROUNDOVER, &face)?;
    let g = Vector3::new(rng.gen_range(-1.0..1.0), 0.0, rng.gen_range(-1.0..1.0));
    let cut = rng.gen_range(-0.02..0.02);
    let line = patch.affine(|x| g.dot(&x.coords) - cut);
    let (above, below) = patch.split(&line);
    if rng.gen_bool(0.5) {
        above.or(below)
    } else {
        below.or(above)
    }
}

#[test]
fn closed_form_moments_equal_a_fine_quadrature_on_random_clipped_polygons() {
    // Every density the closed-form parts integrate (e = 2): the stored energy w³, the clamp's
    // dissipation w² ẇ, the elastic force w² and its first moments w² u, w² v, the damping
    // power ẇ², with ẇ a random affine rate. The reference (Simpson on 40 000 panels in u)
    // has an O(h²) error at the vertices' kinks of about 1e-9 of ∫|f|; the closed form must
    // agree within 1e-7 of ∫|f| + area · max|f| · 1e-9.
    let mut rng = ChaCha8Rng::seed_from_u64(2713);
    let mut tested = 0;
    let mut worst: f64 = 0.0;
    while tested < 120 {
        let Some(part) = random_part(&mut rng) else {
            continue;
        };
        tested += 1;
        let verts = part.vertices();
        let moments = PolygonMoments::of(verts);
        let depth = part.depth();
        let rate = {
            let g = Vector3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            let c = rng.gen_range(-1.0..1.0);
            part.affine(|x| c + g.dot(&x.coords) * 30.0)
        };
        let o = moments.origin;
        let (w, r) = (depth.about(o), rate.about(o));
        let u = (o[0], [1.0, 0.0]);
        let v = (o[1], [0.0, 1.0]);
        let cases: [(&[Affine], &Density<'_>); 7] = [
            (&[], &|_, _| 1.0),
            (&[w, w, w], &|a, b| depth.at([a, b]).powi(3)),
            (&[w, w, r], &|a, b| {
                depth.at([a, b]).powi(2) * rate.at([a, b])
            }),
            (&[w, w], &|a, b| depth.at([a, b]).powi(2)),
            (&[w, w, u], &|a, b| depth.at([a, b]).powi(2) * a),
            (&[w, w, v], &|a, b| depth.at([a, b]).powi(2) * b),
            (&[r, r], &|a, b| rate.at([a, b]).powi(2)),
        ];
        for (factors, f) in cases {
            let closed = moments.product(factors);
            let reference = simpson_over(verts, f, 40_000);
            let magnitude = simpson_over(verts, &|a, b| f(a, b).abs(), 40_000);
            let peak = verts
                .iter()
                .map(|p| f(p[0], p[1]).abs())
                .fold(0.0, f64::max);
            let bound = 1e-7 * magnitude + 1e-9 * moments.area() * peak;
            let error = (closed - reference).abs();
            worst = worst.max(error / (magnitude + 1e-300));
            assert!(
                error <= bound,
                "{closed:e} vs reference {reference:e} (bound {bound:e}) on {verts:?}"
            );
        }
    }
    eprintln!("worst |closed − reference| / ∫|f| = {worst:.2e}");
}

/// The continuum's stored energy (J) and the dissipation of the damping and the clamp
/// (W, the per-point law's `(f_n − k w^e) ẇ`) of the head at `pose` moving with `(v, ω)`
/// against the plane y = 0, by a midpoint rule of `m × m` cells per inner face (each a ball
/// of the roundover radius carrying `1/m²` of the face law); also the gross dissipation scale
/// `Σ (k w^e + c STEP |ẇ|) |ẇ|` (W) and the number of cells whose force the clamp zeroes at
/// depths past the damping ramp (where a whole part may be unloaded).
fn continuum_energy(
    impact: &ImpactParams,
    pose: &Isometry3<f64>,
    v: Vector3<f64>,
    omega: Vector3<f64>,
    m: usize,
) -> (f64, f64, f64, usize) {
    let (mut energy, mut dissipation, mut gross, mut unloaded) = (0.0, 0.0, 0.0, 0);
    continuum_cells(pose, v, omega, m, &mut |c| {
        let f = impact.force(c.w, c.wdot);
        energy += c.share * impact.potential(c.w);
        dissipation += c.share * (f - impact.elastic_force(c.w)) * c.wdot;
        gross += c.share * impact.force(c.w, c.wdot.abs()) * c.wdot.abs();
        if f == 0.0 && c.w >= impact.full_damping_depth {
            unloaded += 1;
        }
    });
    (energy, dissipation, gross, unloaded)
}

#[test]
fn pressed_and_separating_heads_store_and_dissipate_what_the_continuum_does() {
    // Energy test of the closed-form parts: heads pressed up to 0.2 mm into a plane while they
    // close, separate, or both (turning), so the clamp holds over whole parts of the core. The
    // stored energy must equal the continuum's within 1e-4 (its density k w³/3 is smooth, and
    // the exact contact integrates it exactly), and the dissipation within 2e-3 of the gross
    // dissipation scale (the bound of the force test at impact states); it is never negative
    // (passivity). Reference: 600² and 1200² midpoint cells per face, extrapolated.
    let contact = lip_contact(false, false);
    let impact = table_6_2();
    let mut rng = ChaCha8Rng::seed_from_u64(5171);
    let mut with_unloaded = 0;
    for _ in 0..8 {
        let rot = UnitQuaternion::from_euler_angles(
            rng.gen_range(-0.01..0.01),
            rng.gen_range(-0.5..0.5),
            rng.gen_range(-0.004..0.004),
        );
        let pose = Isometry3::from_parts(
            Translation3::new(
                0.0,
                lowest_point_depth(&rot) - rng.gen_range(5e-5..2e-4),
                0.0,
            ),
            rot,
        );
        let v = Vector3::new(0.0, rng.gen_range(-0.01..0.01), 0.0);
        let omega = Vector3::new(rng.gen_range(-2.0..2.0), 0.0, rng.gen_range(-2.0..2.0));
        let (energy, _, _, tracks) = evaluate(&contact, &pose, v, omega);
        let dissipation: f64 = tracks.iter().map(|t| t.damping_power).sum();
        let (e1, d1, _, _) = continuum_energy(&impact, &pose, v, omega, 600);
        let (e2, d2, gross, unloaded) = continuum_energy(&impact, &pose, v, omega, 1200);
        let (e_ref, d_ref) = ((4.0 * e2 - e1) / 3.0, (4.0 * d2 - d1) / 3.0);
        if unloaded > 0 {
            with_unloaded += 1;
        }
        eprintln!(
            "energy {energy:.6e} vs {e_ref:.6e} ({:.1e}); dissipation {dissipation:.6e} vs \
             {d_ref:.6e} ({:.1e} of gross {gross:.3e}); {unloaded} unloaded cells",
            (energy - e_ref).abs() / e_ref,
            (dissipation - d_ref).abs() / gross
        );
        assert!(
            (energy - e_ref).abs() <= 1e-4 * e_ref,
            "{energy} vs {e_ref}"
        );
        assert!(
            (dissipation - d_ref).abs() <= 2e-3 * gross,
            "{dissipation} vs {d_ref}"
        );
        assert!(dissipation >= 0.0, "{dissipation}");
    }
    assert!(
        with_unloaded >= 3,
        "states must unload part of the core: {with_unloaded}"
    );
}
