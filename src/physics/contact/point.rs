//! One contact point's IMPACT force and Coulomb friction (the per-material-point law of
//! docs/reference/models.md "Contact formulation"), and a track's sums over its points: shared by the
//! contact-point lattice and the exactly integrated face contact, whose quadrature nodes are
//! points of the same law ([`super::face`]).

use super::{PointLoad, TrackLinearization, TrackMoments};
use crate::geometry::{FacePatch, Line};
use crate::physics::body::BodyFrame;
use crate::physics::friction::FrictionParams;
use nalgebra::{Matrix3, Point3, Vector3};

/// Where one (piece, face) pair's point evaluations go.
pub(super) struct PointOutputs<'s, 'p> {
    /// Index of the contact in the system.
    pub(super) index: u32,
    /// Track index within the contact.
    pub(super) track: u32,
    /// Receives each loaded point's force derivatives.
    pub(super) linearizations: Option<&'s mut Vec<TrackLinearization>>,
    /// Or sums them into one block per track (the exact face contact's nodes).
    pub(super) moments: Option<&'s mut TrackMoments>,
    /// Receives each loaded point's load.
    pub(super) points: Option<&'s mut (dyn FnMut(&PointLoad) + 'p)>,
    /// The contact's stored elastic energy, J: each point adds its own (in the points' order,
    /// so the sum is the lattice's bit for bit).
    pub(super) energy: &'s mut f64,
    /// The track's sums.
    pub(super) sum: TrackSum,
    /// The tangent projector `I − n nᵀ` of the last normal `n` the friction's derivatives
    /// used ([`PointOutputs::tangent`]).
    pub(super) tangent: (Vector3<f64>, Matrix3<f64>),
    /// While set, the points take no friction of their own and sum their normal loads here
    /// instead ([`super::FrictionRule::PerPart`]).
    pub(super) lump: Option<Lump>,
    /// While [`PointOutputs::lump`] is set and derivatives are taken, each point's
    /// derivatives wait here for the part's friction direction ([`super::Contact::end_lump`]).
    pub(super) lump_nodes: &'s mut Vec<TrackLinearization>,
    /// Which nodes' derivatives are taken ([`super::JacobianScope`]).
    pub(super) scope: super::JacobianScope,
}

/// The normal loads of a part's points, for its friction at their load centre
/// ([`super::FrictionRule::PerPart`]): `Σ f_n`, `Σ f_n p`, `Σ f_n n` and `Σ f_n c` (the balls'
/// centres).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Lump {
    pub(super) normal_force: f64,
    pub(super) moment: Vector3<f64>,
    pub(super) normal: Vector3<f64>,
    pub(super) centre: Vector3<f64>,
}

impl PointOutputs<'_, '_> {
    /// The value of [`PointOutputs::tangent`] before any point: no normal equals it.
    pub(super) const NO_TANGENT: (Vector3<f64>, Matrix3<f64>) = (
        Vector3::new(f64::NAN, f64::NAN, f64::NAN),
        Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    );

    /// True when the points' derivatives are taken (into moments or a list).
    #[inline]
    pub(super) fn linearizing(&self) -> bool {
        self.linearizations.is_some() || self.moments.is_some()
    }

    /// Outputs that take only the points' derivatives, into this track's linearizations or
    /// moments: their force, energy, powers and sums go to `energy` and a discarded sum, and
    /// they take no lump (per-node friction). For a Newton matrix taken on other nodes than
    /// the force ([`super::JacobianScope::NewtonMatrix`]).
    pub(super) fn derivatives_only<'a>(
        &'a mut self,
        energy: &'a mut f64,
        lump_nodes: &'a mut Vec<TrackLinearization>,
    ) -> PointOutputs<'a, 'a> {
        PointOutputs {
            index: self.index,
            track: self.track,
            linearizations: self.linearizations.as_deref_mut(),
            moments: self.moments.as_deref_mut(),
            points: None,
            energy,
            sum: TrackSum::default(),
            tangent: self.tangent,
            lump: None,
            lump_nodes,
            scope: self.scope,
        }
    }

    /// Hands one point's derivatives to the track's moments when they are summed, else to
    /// the list of linearizations.
    #[inline]
    pub(super) fn push_linearization(&mut self, lin: &TrackLinearization) {
        if let Some(sum) = self.moments.as_deref_mut() {
            sum.add(lin);
        } else if let Some(all) = self.linearizations.as_deref_mut() {
            all.push(*lin);
        }
    }

    /// `I − n nᵀ` for the normal `n`, computed again only when `n` differs from the last
    /// one's (the points of a face's polygon share the plane's normal). Equal normals give the
    /// same matrix bit for bit: an entry `δ_ij − n_i n_j` does not depend on the sign of a
    /// zero product.
    #[inline]
    fn tangent(&mut self, normal: &Vector3<f64>) -> Matrix3<f64> {
        if self.tangent.0 != *normal {
            self.tangent = (*normal, Matrix3::identity() - normal * normal.transpose());
        }
        self.tangent.1
    }
}

impl super::Contact {
    /// The IMPACT force and friction of one ball of `radius` centred at `centre` (world, a
    /// material point of body a) carrying the share `beta` of the face law, at signed
    /// distance `distance` (m) from the face's solid whose outward unit normal there is
    /// `normal`: nothing when `w = radius − distance <= 0`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn evaluate_point(
        &self,
        fa: &BodyFrame,
        fb: &BodyFrame,
        centre: &Point3<f64>,
        radius: f64,
        beta: f64,
        distance: f64,
        normal: &Vector3<f64>,
        out: &mut PointOutputs<'_, '_>,
    ) {
        let normal = *normal;
        let w = radius - distance;
        if w <= 0.0 {
            return;
        }
        let p = centre - normal * radius;
        let v_rel = fa.point_velocity(&p) - fb.point_velocity(&p);
        let wdot = -v_rel.dot(&normal);
        // The force's parts once (each STEP evaluated once per point): the same numbers as
        // `ImpactParams::force`, `elastic_force` and `force_gradient`. When the derivatives
        // are taken, each STEP's value and slope come from one `sincos`.
        let linearizing = out.linearizing();
        let (spring, damping, damping_slope) = if linearizing {
            self.impact.force_parts_with_slope(w)
        } else {
            let (spring, damping) = self.impact.force_parts(w);
            (spring, damping, 0.0)
        };
        let fn_mag = beta * (spring + damping * wdot).max(0.0);
        let elastic = beta * spring;
        let slip = v_rel - normal * v_rel.dot(&normal);
        let speed = slip.norm();
        let mut ft = 0.0;
        let mut mu = None;
        let mut force = normal * fn_mag;
        let lumped = if let Some(lump) = out.lump.as_mut() {
            if fn_mag > 0.0 {
                lump.normal_force += fn_mag;
                lump.moment += p.coords * fn_mag;
                lump.normal += normal * fn_mag;
                lump.centre += centre.coords * fn_mag;
            }
            true
        } else {
            false
        };
        // Lumped, the part's friction comes at its end (`Contact::end_lump`).
        if let (false, Some(fr)) = (lumped, &self.friction) {
            if speed > 0.0 && fn_mag > 0.0 {
                let m = if linearizing {
                    let both = fr.coefficient_with_derivative(speed);
                    mu = Some(both);
                    both.0
                } else {
                    fr.coefficient(speed)
                };
                ft = m * fn_mag;
                force -= slip * (ft / speed);
            }
        }
        if fn_mag > 0.0 && linearizing {
            let (dfn_dw, dfn_dwdot) =
                self.impact
                    .unclamped_gradient_with_slope(w, wdot, damping, damping_slope);
            let (dforce_dfn, dforce_dslip) = if lumped {
                // The part's `−μ_c ŝ_c` joins `∂F/∂f_n` when the part ends.
                (normal, Matrix3::zeros())
            } else {
                let tangent = match self.friction {
                    Some(_) => out.tangent(&normal),
                    None => Matrix3::zeros(),
                };
                friction_derivatives(self.friction.as_ref(), &normal, &tangent, &slip, fn_mag, mu)
            };
            let lin = TrackLinearization {
                body_a: self.body_a,
                body_b: self.body_b,
                deepest_point: p,
                point: p,
                centre: *centre,
                force,
                normal,
                dfn_dw: beta * dfn_dw,
                dfn_dwdot: beta * dfn_dwdot,
                dforce_dfn,
                dforce_dslip,
            };
            if lumped {
                out.lump_nodes.push(lin);
            } else {
                out.push_linearization(&lin);
            }
        }
        *out.energy += beta * self.impact.potential(w);
        if let Some(sink) = out.points.as_deref_mut() {
            if fn_mag > 0.0 {
                sink(&PointLoad {
                    contact: out.index,
                    track: out.track,
                    normal_force: fn_mag,
                    weight: beta,
                    slip_speed: speed,
                });
            }
        }
        out.sum.add(&PointForce {
            point: p,
            force,
            normal,
            normal_force: fn_mag,
            penetration: w,
            penetration_rate: wdot,
            slip,
            speed,
            friction_force: ft,
            damping_power: (fn_mag - elastic) * wdot,
            lever_a: p.coords - fa.position,
            lever_b: p.coords - fb.position,
        });
    }
}

/// One contact point's force and rates (an input of [`TrackSum::add`]).
pub(super) struct PointForce {
    pub(super) point: Point3<f64>,
    pub(super) force: Vector3<f64>,
    pub(super) normal: Vector3<f64>,
    pub(super) normal_force: f64,
    pub(super) penetration: f64,
    pub(super) penetration_rate: f64,
    pub(super) slip: Vector3<f64>,
    pub(super) speed: f64,
    pub(super) friction_force: f64,
    pub(super) damping_power: f64,
    pub(super) lever_a: Vector3<f64>,
    pub(super) lever_b: Vector3<f64>,
}

/// A track's sums over its contact points. Points arrive in mirror pairs
/// ([`crate::geometry::lattice`]), so in a configuration symmetric about a piece's mid-plane
/// the out-of-plane sums cancel pair by pair, exactly.
#[derive(Default)]
pub(super) struct TrackSum {
    pub(super) touching: bool,
    pub(super) force: Vector3<f64>,
    pub(super) torque_a: Vector3<f64>,
    pub(super) torque_b: Vector3<f64>,
    pub(super) normal_force: f64,
    pub(super) weighted_slip: Vector3<f64>,
    pub(super) weighted_speed: f64,
    pub(super) weighted_point: Vector3<f64>,
    pub(super) friction_force: f64,
    pub(super) damping_power: f64,
    pub(super) friction_power: f64,
    pub(super) penetration: f64,
    pub(super) penetration_rate: f64,
    pub(super) deepest_point: Point3<f64>,
    pub(super) normal: Vector3<f64>,
}

impl TrackSum {
    /// A part of the track whose points all penetrate with their force clamped to zero
    /// (`face.rs`, closed form): it dissipates `damping_power` (W) and carries no force.
    pub(super) fn add_unloaded(&mut self, damping_power: f64) {
        self.touching = true;
        self.damping_power += damping_power;
    }

    #[inline]
    pub(super) fn add(&mut self, p: &PointForce) {
        self.touching = true;
        self.force += p.force;
        self.torque_a += p.lever_a.cross(&p.force);
        self.torque_b += p.lever_b.cross(&p.force);
        self.normal_force += p.normal_force;
        self.weighted_slip += p.slip * p.normal_force;
        self.weighted_speed += p.speed * p.normal_force;
        self.weighted_point += p.point.coords * p.normal_force;
        self.friction_force += p.friction_force;
        self.damping_power += p.damping_power;
        self.friction_power += p.friction_force * p.speed;
        if p.penetration > self.penetration {
            self.penetration = p.penetration;
            self.penetration_rate = p.penetration_rate;
            self.deepest_point = p.point;
            self.normal = p.normal;
        }
    }
}

/// `(∂F/∂f_n, ∂F/∂s)` of the contact force `F = n f_n − μ(|s|) f_n ŝ` at normal force `fn_mag`
/// and slip `slip` (tangential; `mu` = (μ(|s|), μ'(|s|)) when already known): `∂F/∂f_n = n − μ ŝ` and
/// `∂F/∂s = −f_n (μ' ŝŝᵀ + μ/|s| (P − ŝŝᵀ))` with `P = I − nnᵀ`; at zero slip the limit
/// `μ/|s| → μ'(0)` is used. `tangent` is `P = I − nnᵀ` (read only with friction).
pub(super) fn friction_derivatives(
    friction: Option<&FrictionParams>,
    normal: &Vector3<f64>,
    tangent: &Matrix3<f64>,
    slip: &Vector3<f64>,
    fn_mag: f64,
    mu: Option<(f64, f64)>,
) -> (Vector3<f64>, Matrix3<f64>) {
    let Some(fr) = friction else {
        return (*normal, Matrix3::zeros());
    };
    let speed = slip.norm();
    if speed > 0.0 {
        // One division for the direction and `μ/|s|`.
        let inv_speed = 1.0 / speed;
        let dir = slip * inv_speed;
        let along = dir * dir.transpose();
        let (mu, dmu) = mu.unwrap_or_else(|| fr.coefficient_with_derivative(speed));
        (
            normal - dir * mu,
            -(along * dmu + (tangent - along) * (mu * inv_speed)) * fn_mag,
        )
    } else {
        (
            *normal,
            -tangent * (fr.coefficient_derivative(0.0) * fn_mag),
        )
    }
}

/// The penetration rate `ẇ = −n·v_rel` of the balls of `radius` on `patch` (affine in its `ξ`:
/// a rigid relative motion).
pub(super) fn penetration_rate(
    patch: &FacePatch,
    fa: &BodyFrame,
    fb: &BodyFrame,
    radius: f64,
    normal: &Vector3<f64>,
) -> Line {
    patch.affine(|x| {
        let p = x - normal * radius;
        -(fa.point_velocity(&p) - fb.point_velocity(&p)).dot(normal)
    })
}
