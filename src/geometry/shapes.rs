//! Convex contact shapes, the half-space they press into, validation and mass properties.

use nalgebra::{Unit, Vector3};
use std::f64::consts::PI;
use thiserror::Error;

/// Invalid geometry input; each variant names the field and the rule it broke.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GeometryError {
    /// A length or density had to be a finite number > 0.
    #[error("{field} must be a finite number > 0 (got {value})")]
    NotPositive {
        /// Field name as the user wrote it.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// The roundover had to be finite and >= 0.
    #[error("roundover must be a finite number >= 0 (got {value})")]
    NegativeRoundover {
        /// Offending value, m.
        value: f64,
    },
    /// The roundover cannot exceed the smallest outer half extent.
    #[error("roundover ({roundover} m) must be <= the smallest half extent ({min_half_extent} m)")]
    RoundoverTooLarge {
        /// Roundover radius, m.
        roundover: f64,
        /// Smallest outer half extent, m.
        min_half_extent: f64,
    },
    /// A value had to be finite.
    #[error("{field} must be a finite number (got {value})")]
    NotFinite {
        /// Field name as the user wrote it.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// A half-space normal had to be finite and non-zero.
    #[error("normal must be a finite non-zero vector (got {value:?})")]
    BadNormal {
        /// Offending vector.
        value: [f64; 3],
    },
}

/// A convex body piece, described in its own frame (centred at the origin, box axes along x,
/// y, z). Thesis 5.1: the 1 in cube with a 0.02 in roundover; shoes are built from pieces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConvexShape {
    /// Ball of `radius` m centred at the frame origin.
    Sphere {
        /// Radius, m.
        radius: f64,
    },
    /// Box with rounded edges and corners: inner box of half extents `half_extents - roundover`
    /// Minkowski-summed with a ball of radius `roundover`.
    RoundedBox {
        /// OUTER half extents including the roundover, m (thesis cube: 0.5 in each).
        half_extents: Vector3<f64>,
        /// Edge and corner roundover radius, m (thesis 5.1: 0.02 in). 0 gives a sharp box.
        roundover: f64,
    },
}

fn positive(field: &'static str, value: f64) -> Result<f64, GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(GeometryError::NotPositive { field, value })
    }
}

impl ConvexShape {
    /// A validated sphere (`radius` in m, finite and > 0).
    pub fn sphere(radius: f64) -> Result<Self, GeometryError> {
        Ok(Self::Sphere {
            radius: positive("radius", radius)?,
        })
    }

    /// A validated rounded box: outer `half_extents` (m) finite and > 0, `roundover` (m)
    /// finite, >= 0 and <= the smallest half extent.
    pub fn rounded_box(half_extents: Vector3<f64>, roundover: f64) -> Result<Self, GeometryError> {
        positive("half_extents.x", half_extents.x)?;
        positive("half_extents.y", half_extents.y)?;
        positive("half_extents.z", half_extents.z)?;
        if !(roundover.is_finite() && roundover >= 0.0) {
            return Err(GeometryError::NegativeRoundover { value: roundover });
        }
        let min_half_extent = half_extents.min();
        if roundover > min_half_extent {
            return Err(GeometryError::RoundoverTooLarge {
                roundover,
                min_half_extent,
            });
        }
        Ok(Self::RoundedBox {
            half_extents,
            roundover,
        })
    }

    /// Largest distance of a point of the piece from its frame origin, m.
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Self::Sphere { radius } => radius,
            Self::RoundedBox {
                half_extents,
                roundover,
            } => (half_extents - Vector3::repeat(roundover)).norm() + roundover,
        }
    }

    /// Volume, m³ (exact, Steiner formula for the rounded box).
    pub fn volume(&self) -> f64 {
        match *self {
            Self::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
            Self::RoundedBox {
                half_extents,
                roundover: r,
            } => {
                let h = half_extents - Vector3::repeat(r);
                8.0 * h.x * h.y * h.z
                    + 8.0 * r * (h.x * h.y + h.y * h.z + h.z * h.x)
                    + 2.0 * PI * r * r * (h.x + h.y + h.z)
                    + 4.0 / 3.0 * PI * r.powi(3)
            }
        }
    }

    /// Mass (kg) and principal moments of inertia about the centre (kg·m², along the shape
    /// axes) for a uniform `density` (kg/m³, e.g. 7075-T73: 2810).
    ///
    /// Exact for both shapes: the rounded box is summed over its Steiner pieces (inner box,
    /// 6 face slabs, 12 quarter cylinders, 8 ball octants) with the parallel-axis terms written
    /// out, so there is no approximation.
    pub fn mass_properties(&self, density: f64) -> Result<(f64, Vector3<f64>), GeometryError> {
        let rho = positive("density", density)?;
        match *self {
            Self::Sphere { radius } => {
                let mass = rho * self.volume();
                Ok((mass, Vector3::repeat(0.4 * mass * radius * radius)))
            }
            Self::RoundedBox {
                half_extents,
                roundover: r,
            } => {
                let h = half_extents - Vector3::repeat(r);
                // s[i] = ∫ x_i² dV over the whole shape.
                let mut s = Vector3::zeros();
                for i in 0..3 {
                    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                    let (hi, hj, hk) = (h[i], h[j], h[k]);
                    // inner box
                    let mut si = 8.0 * hj * hk * hi.powi(3) / 3.0;
                    // two slabs normal to i: x_i ∈ [h_i, h_i + r]
                    si += 2.0 * 4.0 * hj * hk * ((hi + r).powi(3) - hi.powi(3)) / 3.0;
                    // four slabs normal to j and k: x_i spans [-h_i, h_i]
                    si += 2.0 * (2.0 * hk * r + 2.0 * hj * r) * 2.0 * hi.powi(3) / 3.0;
                    // edges along i: x_i is the along-edge coordinate
                    si += 4.0 * (PI * r * r / 4.0) * 2.0 * hi.powi(3) / 3.0;
                    // edges along j and k: x_i is transverse; quarter disk ∫ν = r³/3,
                    // ∫ν² = π r⁴ / 16
                    let quarter = hi * hi * PI * r * r / 4.0
                        + 2.0 * hi * r.powi(3) / 3.0
                        + PI * r.powi(4) / 16.0;
                    si += 4.0 * (2.0 * hj + 2.0 * hk) * quarter;
                    // vertices: ball octant ∫ν = π r⁴/16, ∫ν² = π r⁵/30
                    si += 8.0
                        * (hi * hi * PI * r.powi(3) / 6.0
                            + 2.0 * hi * PI * r.powi(4) / 16.0
                            + PI * r.powi(5) / 30.0);
                    s[i] = si;
                }
                let mass = rho * self.volume();
                let inertia = Vector3::new(s.y + s.z, s.z + s.x, s.x + s.y) * rho;
                Ok((mass, inertia))
            }
        }
    }
}

/// A solid half-space `{x : normal·x <= offset}` (world frame), e.g. a tube wall or rail face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// Unit normal pointing out of the solid into free space.
    pub normal: Unit<Vector3<f64>>,
    /// Plane offset along the normal, m: the surface is `normal·x = offset`.
    pub offset: f64,
}

impl HalfSpace {
    /// Validated half-space from any finite non-zero `normal` (normalised here) and `offset` m.
    pub fn new(normal: Vector3<f64>, offset: f64) -> Result<Self, GeometryError> {
        let norm = normal.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(GeometryError::BadNormal {
                value: [normal.x, normal.y, normal.z],
            });
        }
        if !offset.is_finite() {
            return Err(GeometryError::NotFinite {
                field: "offset",
                value: offset,
            });
        }
        Ok(Self {
            normal: Unit::new_unchecked(normal / norm),
            offset,
        })
    }
}
