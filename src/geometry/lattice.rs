//! The contact points of a convex piece: material points on its surface, each a small ball,
//! whose stiffness shares resolve a face contact over the face (SPEC §2 "Passivity",
//! docs/reference/models.md "Contact formulation").
//!
//! A rounded box is its inner box ⊕ ball(roundover). Its contact points are the surface nodes
//! of an `n × n × n` lattice on the inner box, each a ball of the roundover radius, so a ball
//! touches a plane exactly where the rounded surface does. Each node carries the weight
//! `β = 2 f(i) f(j) f(k) / (n − 1)²` with `f = 1/2` at the first and last node of an axis and 1
//! between: on every face of the box the weights of the face's nodes are the trapezoid rule
//! for that face normalised to its area, so they sum to exactly 1 on each face, and a node
//! shared by two or three faces (an edge or a corner) has the same weight seen from each of
//! them. A face pressed uniformly by `w` therefore carries `Σ β k w^e = k w^e`, the thesis'
//! IMPACT law (eq. 2.1) for the whole face, whatever the face's size; an edge carries
//! `1/(2(n−1))` of that stiffness, a corner `1/(4(n−1)²)`. The same number of nodes on every
//! axis is what makes the shared weights agree (a box of unequal sides gets a finer spacing
//! along its short axes).
//!
//! A sphere is one point: its centre, with its radius and weight 1, which is the thesis' point
//! law exactly (Table 2.2 anchors).
//!
//! Order: nodes that mirror each other through the piece's z = 0 plane are adjacent, so sums
//! over a configuration symmetric about that plane cancel pair by pair, exactly (a planar
//! motion stays planar to the last bit).

use super::shapes::ConvexShape;
use nalgebra::Point3;

/// Nodes per box edge used by the reference models (25 per face, 98 per box).
pub const DEFAULT_POINTS_PER_EDGE: usize = 5;

/// Smallest and largest accepted nodes per edge (a case's `contact_points_per_edge`).
pub const POINTS_PER_EDGE_RANGE: (usize, usize) = (2, 33);

/// Largest lattice [`contact_points`] builds: beyond a case's range, for convergence studies
/// against the exact face contact (issue 27; 129 points per edge is about 99 000 points per box).
pub const STUDY_POINTS_PER_EDGE_MAX: usize = 129;

/// One contact point of a piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Centre of the point's ball in the piece's frame, m.
    pub local: Point3<f64>,
    /// Ball radius, m (the roundover; 0 for a sharp box; the radius for a sphere).
    pub radius: f64,
    /// Share of the contact's stiffness and damping, dimensionless (sums to 1 over any face).
    pub weight: f64,
}

/// The contact points of `shape` with `points_per_edge` nodes per box edge (clamped to
/// 2..=[`STUDY_POINTS_PER_EDGE_MAX`]; a case's setting is validated against
/// [`POINTS_PER_EDGE_RANGE`]; ignored for a sphere).
///
/// The weights assume an inner box with all half extents > 0 (a roundover smaller than every
/// outer half extent); for a box collapsed along an axis the two coincident faces both count.
pub fn contact_points(shape: &ConvexShape, points_per_edge: usize) -> Vec<ContactPoint> {
    match *shape {
        ConvexShape::Sphere { radius } => vec![ContactPoint {
            local: Point3::origin(),
            radius,
            weight: 1.0,
        }],
        ConvexShape::RoundedBox {
            half_extents,
            roundover,
        } => {
            let n = points_per_edge.clamp(POINTS_PER_EDGE_RANGE.0, STUDY_POINTS_PER_EDGE_MAX);
            let last = n - 1;
            let inner = half_extents.map(|h| (h - roundover).max(0.0));
            // Node coordinate as an exact fraction of the half extent: t(last − i) = −t(i).
            let frac = |i: usize| (2.0 * i as f64 - last as f64) / last as f64;
            let end = |i: usize| if i == 0 || i == last { 0.5 } else { 1.0 };
            let scale = 2.0 / (last * last) as f64;
            let mut out = Vec::with_capacity(n * n * n - n.saturating_sub(2).pow(3));
            let mut push = |i: usize, j: usize, k: usize| {
                let on_surface = [i, j, k].iter().any(|&m| m == 0 || m == last);
                if on_surface {
                    out.push(ContactPoint {
                        local: Point3::new(inner.x * frac(i), inner.y * frac(j), inner.z * frac(k)),
                        radius: roundover,
                        weight: scale * end(i) * end(j) * end(k),
                    });
                }
            };
            for i in 0..n {
                for j in 0..n {
                    // k and its mirror last − k, adjacent; the middle node alone.
                    for k in 0..n.div_ceil(2) {
                        push(i, j, k);
                        if last - k != k {
                            push(i, j, last - k);
                        }
                    }
                }
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn cube(n: usize) -> Vec<ContactPoint> {
        let shape = ConvexShape::rounded_box(Vector3::new(0.03, 0.01, 0.02), 5e-4).expect("box");
        contact_points(&shape, n)
    }

    #[test]
    fn every_face_sums_to_one_and_nodes_are_the_surface_of_the_lattice() {
        for n in [2, 3, 5, 8] {
            let pts = cube(n);
            assert_eq!(pts.len(), n * n * n - (n - 2).pow(3), "n = {n}");
            let inner = Vector3::new(0.03 - 5e-4, 0.01 - 5e-4, 0.02 - 5e-4);
            for axis in 0..3 {
                for side in [-1.0, 1.0] {
                    let sum: f64 = pts
                        .iter()
                        .filter(|p| p.local[axis] == side * inner[axis])
                        .map(|p| p.weight)
                        .sum();
                    assert!(
                        (sum - 1.0).abs() < 1e-14,
                        "n {n} axis {axis} side {side}: {sum}"
                    );
                }
            }
            assert!(pts.iter().all(|p| p.radius == 5e-4));
        }
    }

    #[test]
    fn mirror_nodes_through_z_are_adjacent() {
        let pts = cube(5);
        let mut i = 0;
        while i < pts.len() {
            let p = pts[i].local;
            if p.z == 0.0 {
                i += 1;
                continue;
            }
            let q = pts[i + 1].local;
            assert_eq!((q.x, q.y, q.z), (p.x, p.y, -p.z), "node {i}");
            assert_eq!(pts[i].weight, pts[i + 1].weight);
            i += 2;
        }
    }

    #[test]
    fn a_sphere_is_its_centre() {
        let pts = contact_points(&ConvexShape::Sphere { radius: 0.05 }, 5);
        assert_eq!(pts.len(), 1);
        assert_eq!(pts[0].radius, 0.05);
        assert_eq!(pts[0].weight, 1.0);
    }
}
