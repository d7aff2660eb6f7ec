//! Closed-form monomial moments `∫_P (u − u₀)^a (v − v₀)^b dA` of a polygon `P` in a face's
//! material coordinates, `a + b <= 3` (docs/models.md "Exact face contact", "Closed-form
//! parts"): every density of the IMPACT law with `e = 2` on a part of a pressed face where
//! `w` and `ẇ` are affine (the stored energy `k w³/3`, the clamp's dissipation `k w² ẇ`, the
//! force `k w² + c ẇ` and its first moments) is a polynomial of degree at most 3 in `ξ`, so
//! its integral is a fixed combination of these ten numbers.
//!
//! Derivation (divergence theorem as a fan of signed triangles): `P` is the signed sum of the
//! triangles `(ξ₀, p_i, p_{i+1})` over its edges. On the triangle with apex at the origin
//! `x = s p + t q`, `(s, t)` on the unit simplex, `dA = (p × q) ds dt`, and
//! `∫ s^i t^j ds dt = i! j! / (i + j + 2)!`, so
//! `∫ u^a v^b = (p × q) Σ_{i<=a, j<=b} C(a,i) C(b,j) p_u^i q_u^(a−i) p_v^j q_v^(b−j)
//! (i+j)! (a+b−i−j)! / (a+b+2)!`. No division by an edge's length or a gradient: exact to
//! round-off for every polygon, however thin. Moments are taken about the first vertex (a
//! thin ramp far from `ξ = 0` keeps its digits).

/// The moments of one polygon about its reference point `origin` (the first vertex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolygonMoments {
    /// The reference point `ξ₀`.
    pub origin: [f64; 2],
    /// `m[a][b] = ∫ (u − u₀)^a (v − v₀)^b dA` for `a + b <= 3` (zero elsewhere), in `ξ` units.
    pub m: [[f64; 4]; 4],
}

/// `(i + j)! (n − i − j)! / (n + 2)!` for `n = a + b <= 3`, indexed `[n][i + j]`.
const SIMPLEX: [[f64; 4]; 4] = [
    [1.0 / 2.0, 0.0, 0.0, 0.0],
    [1.0 / 6.0, 1.0 / 6.0, 0.0, 0.0],
    [2.0 / 24.0, 1.0 / 24.0, 2.0 / 24.0, 0.0],
    [6.0 / 120.0, 2.0 / 120.0, 2.0 / 120.0, 6.0 / 120.0],
];
/// Binomial coefficients `C(n, k)`, `n <= 3`.
const BINOMIAL: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 2.0, 1.0, 0.0],
    [1.0, 3.0, 3.0, 1.0],
];

impl PolygonMoments {
    /// The moments of the polygon with vertices `verts` (in order, either orientation: the
    /// moments of a clockwise polygon are returned with the counter-clockwise sign, so the
    /// area `m[0][0]` is positive). Empty polygons give zeros.
    pub fn of(verts: &[[f64; 2]]) -> Self {
        let mut m = [[0.0; 4]; 4];
        let origin = verts.first().copied().unwrap_or([0.0; 2]);
        if verts.len() < 3 {
            return Self { origin, m };
        }
        for k in 1..verts.len() - 1 {
            let p = [verts[k][0] - origin[0], verts[k][1] - origin[1]];
            let q = [verts[k + 1][0] - origin[0], verts[k + 1][1] - origin[1]];
            let jac = p[0] * q[1] - p[1] * q[0];
            // Powers p^i, q^i of each coordinate, i <= 3.
            let pow = |x: f64| [1.0, x, x * x, x * x * x];
            let (pu, pv, qu, qv) = (pow(p[0]), pow(p[1]), pow(q[0]), pow(q[1]));
            for a in 0..4 {
                for b in 0..4 - a {
                    let n = a + b;
                    let mut sum = 0.0;
                    for i in 0..=a {
                        for j in 0..=b {
                            sum += BINOMIAL[a][i]
                                * BINOMIAL[b][j]
                                * pu[i]
                                * qu[a - i]
                                * pv[j]
                                * qv[b - j]
                                * SIMPLEX[n][i + j];
                        }
                    }
                    m[a][b] += jac * sum;
                }
            }
        }
        if m[0][0] < 0.0 {
            for row in &mut m {
                for x in row.iter_mut() {
                    *x = -*x;
                }
            }
        }
        Self { origin, m }
    }

    /// The area.
    pub fn area(&self) -> f64 {
        self.m[0][0]
    }

    /// `∫ Π_k L_k dA` for up to three affine functions `L_k(ξ) = c_k + g_k · (ξ − ξ₀)` given
    /// as `(c_k, g_k)` about [`PolygonMoments::origin`]: the product expanded into monomials.
    pub fn product(&self, factors: &[(f64, [f64; 2])]) -> f64 {
        // Coefficients of the product polynomial in (du, dv), degree <= 3.
        let mut poly = [[0.0; 4]; 4];
        poly[0][0] = 1.0;
        let mut degree = 0;
        for &(c, g) in factors.iter().take(3) {
            let mut next = [[0.0; 4]; 4];
            for a in 0..=degree {
                for b in 0..=degree - a {
                    let x = poly[a][b];
                    if x == 0.0 {
                        continue;
                    }
                    next[a][b] += x * c;
                    next[a + 1][b] += x * g[0];
                    next[a][b + 1] += x * g[1];
                }
            }
            poly = next;
            degree += 1;
        }
        let mut sum = 0.0;
        for a in 0..=degree {
            for b in 0..=degree - a {
                sum += poly[a][b] * self.m[a][b];
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_square_has_the_textbook_moments() {
        // Square [0, 1]²: ∫ u^a v^b = 1/((a+1)(b+1)).
        let m = PolygonMoments::of(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        for a in 0..4 {
            for b in 0..4 - a {
                let exact = 1.0 / ((a + 1) as f64 * (b + 1) as f64);
                assert!((m.m[a][b] - exact).abs() < 1e-15, "{a} {b}: {}", m.m[a][b]);
            }
        }
    }

    #[test]
    fn a_right_triangle_has_the_textbook_moments_in_either_orientation() {
        // Triangle (0,0), (1,0), (0,1): ∫ u^a v^b = a! b! / (a+b+2)!.
        let fact = |n: usize| (1..=n).product::<usize>() as f64;
        for verts in [
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
        ] {
            let m = PolygonMoments::of(&verts);
            for a in 0..4 {
                for b in 0..4 - a {
                    let exact = fact(a) * fact(b) / fact(a + b + 2);
                    assert!((m.m[a][b] - exact).abs() < 1e-15, "{a} {b}: {}", m.m[a][b]);
                }
            }
        }
    }
}
