//! Exact volume and first moment of an axis-aligned box below a plane.
//!
//! The box is clipped face by face (Sutherland–Hodgman on ≤ 8 vertices, fixed arrays). With
//! the reference origin `o` on the cutting plane, the cap face contributes nothing and
//! `V = Σ_f ∫ tetra(o, clipped face f)`; the tetrahedra from a fan triangulation also give the
//! first moment. `o` is the projection of the deepest box vertex onto the plane, which lies
//! inside the clipped solid for the shallow cuts of contact, so all tetrahedra have the same
//! sign and nothing cancels. A face exactly parallel to the plane is handled like any other:
//! kept whole, dropped whole, or (lying in the plane) contributing a zero-volume tetrahedron.

use nalgebra::Vector3;

const MAX_VERTS: usize = 8;

/// Volume (m³) and first moment about the local origin (m⁴) of
/// `{x ∈ box(centre, half) : n·x <= c}`; `n` must be a unit vector.
#[inline]
pub(crate) fn box_below_plane(
    centre: &Vector3<f64>,
    half: &Vector3<f64>,
    n: &Vector3<f64>,
    c: f64,
) -> (f64, Vector3<f64>) {
    let zero = (0.0, Vector3::zeros());
    if half.x <= 0.0 || half.y <= 0.0 || half.z <= 0.0 {
        return zero;
    }
    let u_centre = n.dot(centre) - c;
    let extent = n.x.abs() * half.x + n.y.abs() * half.y + n.z.abs() * half.z;
    if u_centre - extent >= 0.0 {
        return zero;
    }
    let full_volume = 8.0 * half.x * half.y * half.z;
    if u_centre + extent <= 0.0 {
        return (full_volume, centre * full_volume);
    }
    // Deepest vertex, then its projection onto the plane as the origin of the tetrahedra.
    let deep_offset = Vector3::new(
        -half.x.copysign(n.x),
        -half.y.copysign(n.y),
        -half.z.copysign(n.z),
    );
    let deep = centre + deep_offset;
    let origin = deep - n * (n.dot(&deep) - c);
    let q = centre - origin; // box centre relative to the origin
    let mut volume = 0.0;
    let mut moment = Vector3::zeros();
    for axis in 0..3 {
        let b = (axis + 1) % 3;
        let cc = (axis + 2) % 3;
        for sign in [1.0, -1.0] {
            let mut face_centre = q;
            face_centre[axis] += sign * half[axis];
            let mut eb = Vector3::zeros();
            eb[b] = half[b];
            let mut ec = Vector3::zeros();
            ec[cc] = half[cc] * sign; // flips orientation for the -axis face
            let mut verts = [Vector3::zeros(); MAX_VERTS];
            verts[0] = face_centre - eb - ec;
            verts[1] = face_centre + eb - ec;
            verts[2] = face_centre + eb + ec;
            verts[3] = face_centre - eb + ec;
            let (verts, count) = clip_below(&verts, 4, n);
            if count < 3 {
                continue;
            }
            let v0 = verts[0];
            for k in 1..count - 1 {
                let (v1, v2) = (verts[k], verts[k + 1]);
                let tet = v0.dot(&v1.cross(&v2)) / 6.0;
                volume += tet;
                moment += (v0 + v1 + v2) * (tet / 4.0);
            }
        }
    }
    (volume, moment + origin * volume)
}

/// Keeps the part of a planar polygon with `n·x <= 0`.
#[inline]
fn clip_below(
    verts: &[Vector3<f64>; MAX_VERTS],
    count: usize,
    n: &Vector3<f64>,
) -> ([Vector3<f64>; MAX_VERTS], usize) {
    let mut out = [Vector3::zeros(); MAX_VERTS];
    let mut m = 0;
    for k in 0..count {
        let p = verts[k];
        let q = verts[(k + 1) % count];
        let dp = n.dot(&p);
        let dq = n.dot(&q);
        if dp <= 0.0 && m < MAX_VERTS {
            out[m] = p;
            m += 1;
        }
        if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) && m < MAX_VERTS {
            out[m] = p + (q - p) * (dp / (dp - dq));
            m += 1;
        }
    }
    (out, m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_cube_and_corner_tetrahedron() {
        let c = Vector3::new(1.0, 2.0, 3.0);
        let h = Vector3::new(1.0, 1.0, 1.0);
        // plane through the centre, normal +z: lower half
        let (v, m) = box_below_plane(&c, &h, &Vector3::z(), 3.0);
        assert!((v - 4.0).abs() < 1e-13);
        let cen = m / v;
        assert!((cen - Vector3::new(1.0, 2.0, 2.5)).norm() < 1e-13);
        // corner cut: n = (1,1,1)/√3 through the point at distance t along each axis from the
        // lowest corner -> tetrahedron with legs t, volume t³/6, centroid corner + t/4.
        let n = Vector3::new(1.0, 1.0, 1.0).normalize();
        let corner = c - h;
        let t = 0.3;
        let off = n.dot(&(corner + Vector3::new(t, 0.0, 0.0)));
        let (v, m) = box_below_plane(&c, &h, &n, off);
        assert!((v - t * t * t / 6.0).abs() < 1e-15);
        assert!((m / v - (corner + Vector3::repeat(t / 4.0))).norm() < 1e-13);
    }
}
